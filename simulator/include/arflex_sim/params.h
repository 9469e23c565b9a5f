// Parametrisation of the simulated robot cell: arm geometry and dynamics, the seeded error
// set that makes the TRUE arm differ from the NOMINAL one, joint compliance, cameras, AprilTag
// markers and scripted disturbances. Both MJCF models are generated from one CellConfig
// (see mjcf.h), so the true and nominal models cannot drift apart by hand editing.
//
// Units: metres, kilograms, radians, seconds, newtons, newton-metres.
// Frames: world z up; the arm base sits at the world origin. At q = 0 the upper arm points
// up (+z) and the forearm and the flange point forward (+x).
#ifndef ARFLEX_SIM_PARAMS_H_
#define ARFLEX_SIM_PARAMS_H_

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace arflex {
namespace sim {

inline constexpr int kNumJoints = 6;
using JointVector = std::array<double, kNumJoints>;
using Vec3 = std::array<double, 3>;

// One link of the serial chain. Body i (i = 0..5) carries joint i+1; `offset` is the origin
// of body i in the frame of its parent (body i-1, or the world for i = 0) at q = 0; `axis`
// is the joint axis in body i's frame. Inertial data is about the link's centre of mass,
// with principal axes aligned to the body frame.
struct LinkParams {
  std::string name;
  Vec3 offset;
  Vec3 axis;
  double mass;
  Vec3 com;           // centre of mass in the body frame
  Vec3 inertia;       // principal moments of inertia at the com (kg m^2)
  double lower, upper;  // joint limits (rad)
  double armature;    // reflected rotor inertia of the drive (kg m^2)
  double damping;     // viscous friction at the motor (N m s/rad)
  double max_torque;  // drive torque limit (N m)
  // Series compliance between gear and link (0 = rigid). Modelled in the TRUE model as a
  // passive hinge on the same axis as the joint with this stiffness (N m/rad).
  double stiffness;
  double compliance_damping;  // damping of the passive hinge (N m s/rad)
  // Geometry used for rendering and contacts: a capsule from `geom_from` to `geom_to`
  // (body frame) with radius `geom_radius`.
  Vec3 geom_from, geom_to;
  double geom_radius;
};

// The arm: six links, the tool centre point in the flange (body 5) frame and the tool mass.
struct ArmParams {
  std::array<LinkParams, kNumJoints> links;
  Vec3 tcp_offset;       // TCP position in the flange frame (orientation = flange frame)
  double tool_mass;      // gripper/tool rigidly mounted on the flange (kg)
  Vec3 tool_com;         // tool com in the flange frame
  Vec3 payload_com;      // where the payload sits, in the flange frame
  double base_height;    // height of the fixed pedestal geometry (visual only)
};

// KR 210 R2700-class arm (2.7 m wrist-centre reach, 210 kg payload); dimensions follow the
// published geometry of that class, masses and inertias are plausible estimates.
ArmParams DefaultArm();

// Bounds of the error distributions. Each error is drawn from a normal distribution with the
// given standard deviation, truncated (redrawn) at `clip_sigma` standard deviations.
struct ErrorModel {
  double length_sigma = 0.35e-3;     // per axis, per link offset and the TCP offset (m)
  double joint_offset_sigma = 0.015 * 3.14159265358979323846 / 180.0;  // per joint (rad)
  double clip_sigma = 2.5;
};

// The drawn errors. `offset_error[i]` is added to link i's `offset`; index 6 is the TCP
// offset. `joint_offset[i]` is added to joint i's angle: the true link turns by
// q_i + joint_offset[i] when the servo reads q_i.
struct ErrorSet {
  uint64_t seed = 0;
  std::array<Vec3, kNumJoints + 1> offset_error{};
  JointVector joint_offset{};
};

// Draws an error set with a documented, portable generator (splitmix64 + Box-Muller;
// identical on every platform and standard library).
ErrorSet DrawErrorSet(uint64_t seed, const ErrorModel& model);

// Returns `arm` with `errors` applied to the geometry (the joint offsets are not geometry;
// the MJCF generator applies them as a rotation of the body about its joint axis).
ArmParams ApplyGeometryErrors(const ArmParams& arm, const ErrorSet& errors);

// A fixed camera. The pose is given as position and a point it looks at with an up hint;
// intrinsics are MuJoCo's: vertical field of view, square pixels, principal point at the
// image centre.
struct CameraSpec {
  std::string name;
  Vec3 pos;
  Vec3 look_at;
  Vec3 up = {0, 0, 1};
  double fovy_deg = 45.0;
};

// An AprilTag tag36h11 marker rendered as a textured square. `size` is the edge of the
// black border square (AprilTag's "tag size"); the rendered square is 10/8 of that because
// of the white quiet zone. `body` is "world" or one of the arm bodies ("link6", ...). The
// tag faces the +z axis of its frame, given as position and a rotation (quaternion w x y z)
// in the body frame.
struct TagSpec {
  int id;
  double size;
  std::string body;
  Vec3 pos;
  std::array<double, 4> quat = {1, 0, 0, 0};
};

// An obstacle box (a mocap body: it can be moved at run time). Placed far away when
// disabled.
struct ObstacleSpec {
  bool enabled = false;
  Vec3 pos = {1.8, 0.0, 1.0};
  Vec3 half_size = {0.1, 0.1, 0.1};
};

// A push on the tool: `force` (world frame, N) applied at the TCP from `start` for
// `duration` seconds of simulated time.
struct PushSpec {
  double start = 0.0;
  double duration = 0.0;
  Vec3 force = {0, 0, 0};
};

// A hand guiding the arm: from `start` for `duration` seconds a target point moves linearly
// from `from` to `to` (world), and the hand pulls the TCP towards it with a spring-damper
// force F = stiffness * (target - tcp) - damping * v_tcp, saturated at `max_force`.
struct HandGuideSpec {
  bool enabled = false;
  double start = 0.0;
  double duration = 0.0;
  Vec3 from = {0, 0, 0};
  Vec3 to = {0, 0, 0};
  double stiffness = 2000.0;  // N/m
  double damping = 200.0;     // N s/m
  double max_force = 150.0;   // N
};

struct ServoGains {
  JointVector kp = {2.0e6, 4.0e6, 2.0e6, 1.5e5, 1.5e5, 5.0e4};   // N m/rad
  JointVector kd = {6.0e4, 1.2e5, 5.0e4, 2.0e3, 2.0e3, 5.0e2};   // N m s/rad
};

struct CellConfig {
  ArmParams arm = DefaultArm();
  uint64_t error_seed = 1;
  ErrorModel error_model;
  bool compliance = true;           // include the series compliance in the TRUE model
  double payload_mass = 0.0;        // actual payload (kg); can be changed at run time
  double nominal_payload_mass = 0.0;  // what the controller is told (gravity compensation)
  double timestep = 0.001;          // physics step == controller period (s)
  ServoGains gains;
  bool gravity_compensation = true;
  std::vector<CameraSpec> cameras;
  std::vector<TagSpec> tags;
  ObstacleSpec obstacle;
  std::vector<PushSpec> pushes;
  HandGuideSpec hand;
  int max_render_width = 1280;      // offscreen buffer size baked into the model
  int max_render_height = 1024;
};

// The showcase cell: the arm, four cameras around the work area, tags near the tool and on a
// fixed reference board.
CellConfig DefaultCellConfig();

}  // namespace sim
}  // namespace arflex

#endif  // ARFLEX_SIM_PARAMS_H_
