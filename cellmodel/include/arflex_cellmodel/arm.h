// The robot of the showcase cell as the controllers know it: the NOMINAL arm's geometry,
// masses and limits (one parametrisation; the simulator builds both its MJCF models from it,
// simulator/include/arflex_sim/mjcf.h). No MuJoCo, only the C++ standard library.
//
// Units: metres, kilograms, radians, seconds, newtons, newton-metres.
// Frames: world z up; the arm base sits at the world origin. At q = 0 the upper arm points
// up (+z) and the forearm and the flange point forward (+x).
#ifndef ARFLEX_CELLMODEL_ARM_H_
#define ARFLEX_CELLMODEL_ARM_H_

#include <array>
#include <string>

namespace arflex {
namespace cellmodel {

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

}  // namespace cellmodel
}  // namespace arflex

#endif  // ARFLEX_CELLMODEL_ARM_H_
