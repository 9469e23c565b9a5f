// test_cell_sim - CTest cell.sim.conventions: the nominal model the cell's components use
// (cellkin) against the simulated TRUE cell (arflex_sim, MuJoCo): the gravity torques the
// force-guard subtracts match the drive torques at rest, the tool weight matches the wrist
// sensor, and a scripted push is recovered in magnitude and direction by ContactForceWorld
// (the formula force-guard and teach use). Built only with the simulator.
#include <cmath>
#include <cstdio>
#include <string>

#include "arflex_sim/cell.h"
#include "cellkin.h"

using arflex::cellkin::Model;
using arflex::cellkin::Q;

int main() {
  int failures = 0;
#define CHECK(c, ...)                                                \
  do {                                                               \
    if (!(c)) {                                                      \
      fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #c);   \
      fprintf(stderr, __VA_ARGS__);                                  \
      fputc('\n', stderr);                                           \
      ++failures;                                                    \
    }                                                                \
  } while (0)
  Model m;
  const arflex::sim::JointVector q0 = {0.1, 0.2, 0.5, 0.1, 0.6, 0.2};
  arflex::sim::CellConfig cfg = arflex::sim::DefaultCellConfig();
  arflex::sim::PushSpec push;
  push.start = 2.0;
  push.duration = 2.0;
  push.force = {0, 250, -150};
  cfg.pushes.push_back(push);
  std::string err;
  auto cell = arflex::sim::Cell::Create(cfg, q0, &err);
  if (!cell) {
    fprintf(stderr, "FAIL: cannot create the simulated cell: %s\n", err.c_str());
    return 1;
  }
  cell->SetJointReference(q0);
  cell->Step(1500);  // settle (1.5 s)
  auto js = cell->ReadJointState();
  Q q, tau;
  for (int j = 0; j < 6; ++j) {
    q[j] = js.q[j];
    tau[j] = js.tau[j];
  }
  const Q ext = tau - m.GravityTorque(q, 0);
  printf("at rest: |tau - nominal gravity| max %.1f N m (joint torques up to %.0f N m)\n",
         ext.cwiseAbs().maxCoeff(), tau.cwiseAbs().maxCoeff());
  CHECK(ext.cwiseAbs().maxCoeff() < 100, "external torque at rest %.1f N m",
        ext.cwiseAbs().maxCoeff());
  auto w = cell->ReadWrench();
  const Eigen::Vector3d f(w.force[0], w.force[1], w.force[2]);
  const Eigen::Vector3d c0 = m.ContactForceWorld(q, f, 0);
  printf("at rest: contact force %.2f N (tool weight %.1f N)\n", c0.norm(),
         m.arm().tool_mass * 9.81);
  CHECK(c0.norm() < 5, "contact force at rest %.2f N", c0.norm());
  cell->Step(1500);  // 1 s into the push
  js = cell->ReadJointState();
  for (int j = 0; j < 6; ++j) {
    q[j] = js.q[j];
    tau[j] = js.tau[j];
  }
  w = cell->ReadWrench();
  const Eigen::Vector3d fp(w.force[0], w.force[1], w.force[2]);
  const Eigen::Vector3d c1 = m.ContactForceWorld(q, fp, 0);
  const Eigen::Vector3d want(push.force[0], push.force[1], push.force[2]);
  printf("push (0, 250, -150) N: recovered (%.1f, %.1f, %.1f) N; external torque max %.0f N m\n",
         c1.x(), c1.y(), c1.z(), (tau - m.GravityTorque(q, 0)).cwiseAbs().maxCoeff());
  CHECK((c1 - want).norm() < 0.05 * want.norm(), "recovered push off by %.1f N",
        (c1 - want).norm());
  CHECK((tau - m.GravityTorque(q, 0)).cwiseAbs().maxCoeff() > 200,
        "the push does not show in the joint torques");
  if (failures) return 1;
  printf("ok conventions\n");
  return 0;
}
