// arflex-cellmodel - the cell model on the command line.
//   arflex-cellmodel fk q1 q2 q3 q4 q5 q6   nominal TCP pose at the joint angles (rad):
//                                          "x y z qw qx qy qz" (m, world; unit quaternion)
//   arflex-cellmodel chain                 the nominal chain, one line per joint
//                                          ("joint i axis x|y|z offset ox oy oz") and "tcp tx ty tz"
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "arflex_cellmodel/arm.h"
#include "arflex_cellmodel/kinematics.h"

namespace cm = arflex::cellmodel;

static int Usage() {
  fprintf(stderr, "usage: arflex-cellmodel fk q1 q2 q3 q4 q5 q6 | arflex-cellmodel chain\n");
  return 2;
}

int main(int argc, char** argv) {
  const cm::ArmParams arm = cm::DefaultArm();
  if (argc == 2 && strcmp(argv[1], "chain") == 0) {
    for (int i = 0; i < cm::kNumJoints; ++i) {
      const cm::LinkParams& l = arm.links[i];
      const char axis = l.axis[0] != 0 ? 'x' : l.axis[1] != 0 ? 'y' : 'z';
      printf("joint %d axis %c offset %.17g %.17g %.17g\n", i + 1, axis, l.offset[0], l.offset[1],
             l.offset[2]);
    }
    printf("tcp %.17g %.17g %.17g\n", arm.tcp_offset[0], arm.tcp_offset[1], arm.tcp_offset[2]);
    return 0;
  }
  if (argc != 2 + cm::kNumJoints || strcmp(argv[1], "fk") != 0) return Usage();
  cm::JointVector q;
  for (int i = 0; i < cm::kNumJoints; ++i) {
    char* end = nullptr;
    q[i] = strtod(argv[2 + i], &end);
    if (end == argv[2 + i] || *end != '\0') return Usage();
  }
  const Eigen::Isometry3d t = cm::NominalKinematics(arm).Tcp(q);
  const Eigen::Quaterniond r(t.linear());
  printf("%.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", t.translation().x(), t.translation().y(),
         t.translation().z(), r.w(), r.x(), r.y(), r.z());
  return 0;
}
