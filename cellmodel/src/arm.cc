#include "arflex_cellmodel/arm.h"

namespace arflex {
namespace cellmodel {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// Inertia of a solid cylinder of `mass`, `length` along axis `along` (0=x, 1=y, 2=z),
// radius `radius`, about its centre.
Vec3 RodInertia(double mass, double length, double radius, int along) {
  const double axial = 0.5 * mass * radius * radius;
  const double transverse = mass * (3.0 * radius * radius + length * length) / 12.0;
  Vec3 inertia = {transverse, transverse, transverse};
  inertia[along] = axial;
  return inertia;
}

}  // namespace

ArmParams DefaultArm() {
  ArmParams arm;
  // Joint 1: vertical axis through the base.
  LinkParams& l1 = arm.links[0];
  l1.name = "link1";
  l1.offset = {0.0, 0.0, 0.0};
  l1.axis = {0, 0, 1};
  l1.mass = 300.0;
  l1.com = {0.10, 0.0, 0.40};
  l1.inertia = {45.0, 50.0, 30.0};
  l1.lower = -185 * kDeg;
  l1.upper = 185 * kDeg;
  l1.armature = 80.0;
  l1.damping = 200.0;
  l1.max_torque = 15000.0;
  l1.stiffness = 0.0;
  l1.compliance_damping = 0.0;
  l1.geom_from = {0.0, 0.0, 0.15};
  l1.geom_to = {0.35, 0.0, 0.675};
  l1.geom_radius = 0.22;
  // Joint 2: shoulder, 350 mm forward and 675 mm above joint 1; upper arm 1150 mm along +z.
  LinkParams& l2 = arm.links[1];
  l2.name = "link2";
  l2.offset = {0.35, 0.0, 0.675};
  l2.axis = {0, 1, 0};
  l2.mass = 180.0;
  l2.com = {0.0, 0.0, 0.50};
  l2.inertia = RodInertia(180.0, 1.15, 0.15, 2);
  l2.lower = -60 * kDeg;
  l2.upper = 80 * kDeg;
  l2.armature = 100.0;
  l2.damping = 200.0;
  l2.max_torque = 25000.0;
  l2.stiffness = 2.0e7;
  l2.compliance_damping = 2.0e4;
  l2.geom_from = {0.0, 0.0, 0.0};
  l2.geom_to = {0.0, 0.0, 1.15};
  l2.geom_radius = 0.15;
  // Joint 3: elbow at the end of the upper arm; forearm axis 41 mm above the elbow.
  LinkParams& l3 = arm.links[2];
  l3.name = "link3";
  l3.offset = {0.0, 0.0, 1.15};
  l3.axis = {0, 1, 0};
  l3.mass = 150.0;
  l3.com = {0.05, 0.0, 0.041};
  l3.inertia = {4.0, 9.0, 9.0};
  l3.lower = -110 * kDeg;
  l3.upper = 155 * kDeg;
  l3.armature = 60.0;
  l3.damping = 150.0;
  l3.max_torque = 15000.0;
  l3.stiffness = 1.2e7;
  l3.compliance_damping = 1.0e4;
  l3.geom_from = {-0.30, 0.0, 0.041};
  l3.geom_to = {0.45, 0.0, 0.041};
  l3.geom_radius = 0.16;
  // Joint 4: forearm roll, 500 mm along the forearm.
  LinkParams& l4 = arm.links[3];
  l4.name = "link4";
  l4.offset = {0.50, 0.0, 0.041};
  l4.axis = {1, 0, 0};
  l4.mass = 60.0;
  l4.com = {0.35, 0.0, 0.0};
  l4.inertia = RodInertia(60.0, 0.70, 0.12, 0);
  l4.lower = -350 * kDeg;
  l4.upper = 350 * kDeg;
  l4.armature = 10.0;
  l4.damping = 20.0;
  l4.max_torque = 3000.0;
  l4.stiffness = 0.0;
  l4.compliance_damping = 0.0;
  l4.geom_from = {0.0, 0.0, 0.0};
  l4.geom_to = {0.60, 0.0, 0.0};
  l4.geom_radius = 0.12;
  // Joint 5: wrist bend at the end of the 1200 mm forearm.
  LinkParams& l5 = arm.links[4];
  l5.name = "link5";
  l5.offset = {0.70, 0.0, 0.0};
  l5.axis = {0, 1, 0};
  l5.mass = 25.0;
  l5.com = {0.08, 0.0, 0.0};
  l5.inertia = {0.15, 0.20, 0.20};
  l5.lower = -125 * kDeg;
  l5.upper = 125 * kDeg;
  l5.armature = 8.0;
  l5.damping = 15.0;
  l5.max_torque = 3000.0;
  l5.stiffness = 5.0e5;
  l5.compliance_damping = 300.0;
  l5.geom_from = {-0.02, 0.0, 0.0};
  l5.geom_to = {0.13, 0.0, 0.0};
  l5.geom_radius = 0.10;
  // Joint 6: flange roll; the body origin is the flange face, 215 mm from the wrist centre.
  LinkParams& l6 = arm.links[5];
  l6.name = "link6";
  l6.offset = {0.215, 0.0, 0.0};
  l6.axis = {1, 0, 0};
  l6.mass = 5.0;
  l6.com = {-0.02, 0.0, 0.0};
  l6.inertia = {0.02, 0.015, 0.015};
  l6.lower = -350 * kDeg;
  l6.upper = 350 * kDeg;
  l6.armature = 3.0;
  l6.damping = 5.0;
  l6.max_torque = 1500.0;
  l6.stiffness = 0.0;
  l6.compliance_damping = 0.0;
  l6.geom_from = {-0.05, 0.0, 0.0};
  l6.geom_to = {-0.005, 0.0, 0.0};
  l6.geom_radius = 0.08;

  arm.tcp_offset = {0.30, 0.0, 0.0};
  arm.tool_mass = 25.0;
  arm.tool_com = {0.12, 0.0, 0.0};
  arm.payload_com = {0.24, 0.0, 0.0};
  arm.base_height = 0.15;
  return arm;
}

}  // namespace cellmodel
}  // namespace arflex
