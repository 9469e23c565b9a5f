// Parametrisation of the simulated robot cell: the arm, cameras and AprilTag markers (the
// cell model's, cellmodel/include/arflex_cellmodel/{arm,layout}.h), the seeded error set that
// makes the TRUE arm differ from the NOMINAL one, joint compliance and scripted disturbances. Both MJCF models are generated from one CellConfig
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

#include "arflex_cellmodel/arm.h"
#include "arflex_cellmodel/layout.h"

namespace arflex {
namespace sim {

// The arm and the cell layout are the cell model's (cellmodel/, no MuJoCo); the simulator
// uses them under their old names.
using cellmodel::ArmParams;
using cellmodel::DefaultArm;
using cellmodel::JointVector;
using cellmodel::kNumJoints;
using cellmodel::LinkParams;
using cellmodel::Vec3;

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

using cellmodel::CameraSpec;
using cellmodel::TagSpec;

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
