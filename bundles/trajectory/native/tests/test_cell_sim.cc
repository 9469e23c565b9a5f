// test_cell_sim - CTest cell.sim.conventions: the nominal model the cell's components use
// (cellkin) against the simulated TRUE cell (arflex_sim, MuJoCo): the gravity torques the
// force-guard subtracts match the drive torques at rest, the tool weight matches the wrist
// sensor, and a scripted push is recovered in magnitude and direction by ContactForceWorld
// (the formula force-guard and teach use). Built only with the simulator.
#include <algorithm>
#include <algorithm>
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

  // A moving arm that brakes (Cell::Stop) with nothing touching it, seen as force-guard sees
  // it (ContactMonitor, every `every`-th simulation step): the static model (gravity only)
  // takes the arm's own inertia for an external load; with the inverse dynamics and the
  // allowance for the gears' ringing the default limits (3000 N m, 150 N) hold with margin.
  // Then the same motion with a 400 N push at constant speed: it is still seen.
  const double kTorqueLimit = 3000, kForceLimit = 150;
  for (int every : {1, 3}) {
    for (bool pushed : {false, true}) {
      arflex::sim::CellConfig c2 = arflex::sim::DefaultCellConfig();
      if (pushed) {
        arflex::sim::PushSpec p2;
        p2.start = 1.0;  // during the ramp (0.5 .. 1.2 s), before the stop
        p2.duration = 0.1;
        p2.force = {0, 0, -400};
        c2.pushes.push_back(p2);
      }
      auto arm = arflex::sim::Cell::Create(c2, q0, &err);
      CHECK(arm != nullptr, "second cell: %s", err.c_str());
      if (!arm) return 1;
      arm->Step(500);
      arflex::cellkin::ContactMonitor mon(&m);
      arflex::sim::JointVector ref = q0;
      const double speed[6] = {0.25, 0.5, 0.6, 1.0, 1.0, 1.5};  // rad/s: near the drives' limits
      double stat_t = 0, stat_f = 0, worst_t = -1e9, worst_f = -1e9;
      const double dt = arm->timestep();
      for (int k = 0; k < 1000; ++k) {
        if (k < 700) {  // a ramp, then the stop
          for (int j = 0; j < 6; ++j) ref[j] += speed[j] * dt;
          arm->SetJointReference(ref);
        } else if (k == 700) {
          arm->Stop();
        }
        arm->Step(1);
        if (k % every) continue;
        const auto s = arm->ReadJointState();
        Q qq, qd, tq;
        for (int j = 0; j < 6; ++j) {
          qq[j] = s.q[j];
          qd[j] = s.dq[j];
          tq[j] = s.tau[j];
        }
        mon.Update(static_cast<int64_t>(arm->time() * 1e9), qq, qd, tq, 0);
        if (k < 400) continue;  // the ramp's start: the servo catches up
        const auto wr = arm->ReadWrench();
        const Eigen::Vector3d fs(wr.force[0], wr.force[1], wr.force[2]);
        stat_t = std::max(stat_t, (tq - m.GravityTorque(qq, 0)).cwiseAbs().maxCoeff());
        stat_f = std::max(stat_f, m.ContactForceWorld(qq, fs, 0).norm());
        worst_t = std::max(worst_t, (mon.external_torque().cwiseAbs() - mon.torque_allowance()).maxCoeff());
        worst_f = std::max(worst_f, mon.ContactForce(fs, 0).norm() - mon.force_allowance());
      }
      printf("ramp and stop%s, sampled every %d step(s): static model %.0f N m / %.0f N; "
             "monitor beyond its allowance %.0f N m / %.0f N (limits %.0f / %.0f)\n",
             pushed ? " with a 400 N push" : "", every, stat_t, stat_f, worst_t, worst_f,
             kTorqueLimit, kForceLimit);
      if (!pushed) {
        CHECK(stat_t > kTorqueLimit && stat_f > kForceLimit,
              "the stop no longer loads the static model (%.0f N m, %.0f N): the case tests nothing",
              stat_t, stat_f);
        CHECK(worst_t < 0.5 * kTorqueLimit, "braking alone reads %.0f N m external", worst_t);
        CHECK(worst_f < 0.5 * kForceLimit, "braking alone reads %.0f N contact", worst_f);
      } else {
        CHECK(worst_f > kForceLimit, "a 400 N push at speed reads only %.0f N", worst_f);
      }
    }
  }
  if (failures) return 1;
  printf("ok conventions\n");
  return 0;
}
