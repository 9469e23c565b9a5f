// tcpcorr_comp_held.cc - tcpcorr.comp.invalid and tcpcorr.comp.hold: what the corrector does not
// use (malformed, invalid or uncertain values, a robot that does not follow) holds its output
// (the harness: tcpcorr_comp_rig.h).
#include "tcpcorr_comp_rig.h"

namespace tcpcorr_comp {

void CaseInvalid(Rig& rig) {
  // Validated data (docs/safety.md, README "Invalid input"): values that fail their checks
  // are not used and are counted (update_errors); the output stays where the valid ones put it.
  rig.Watch(200 * kMs, false, true, Eigen::Vector3d::Zero());  // let the ramp finish
  const arflex_joint_ref before = rig.last;
  const Eigen::Vector3d far(0.01, 0, 0);  // 10 mm: a valid measurement this far moves the output
  // 1. tcp_pose: malformed measurements claiming validity, 10 mm off: held, each kind counted.
  for (int how = 1; how <= 5; ++how) {
    const uint64_t e0 = rig.Errors();
    rig.MeasureMalformed(how, far);
    CHECK(rig.WaitErrors(e0), "malformed measurement %d was not counted", how);
    const uint64_t end = arflex_sys_now_ns() + 100 * kMs;
    uint64_t last_measure = 0;
    while (arflex_sys_now_ns() < end) {
      rig.Read();
      if (arflex_sys_now_ns() - last_measure > 20 * kMs) {
        rig.MeasureMalformed(how, far);
        last_measure = arflex_sys_now_ns();
      }
    }
    for (int i = 0; i < 6; ++i)
      CHECK(rig.last.q[i] == before.q[i], "joint %d moved on malformed measurement %d", i, how);
  }
  // 2. reference: NaN on one joint. The output holds its last value (no NaN passed on, the
  //    correction frozen even under valid measurements 10 mm off), counted; the hold word
  //    names the reference input as invalid.
  {
    arflex_joint_ref bad;
    std::memset(&bad, 0, sizeof(bad));
    bad.t_ns = 2;
    bad.seq = 2;
    for (int i = 0; i < 6; ++i) bad.q[i] = kRef[i];
    bad.q[2] = std::nan("");
    const uint64_t e0 = rig.Errors();
    arflex_state_write(arflex_host_output(&rig.feeder, "reference"), &bad, sizeof(bad));
    CHECK(rig.WaitErrors(e0), "the NaN reference was not counted");
    const uint32_t hold = arflex_ctl_hold(rig.corr.ctl);
    CHECK((hold & 0xffu) == ARFLEX_HOLD_REFERENCE && ((hold >> 8) & 0xffu) == ARFLEX_HOLD_REF_INVALID &&
              ((hold >> 16) & 0xffu) == 0u,
          "hold word 0x%x", hold);
    const uint64_t seq0 = rig.last.seq;
    rig.Watch(300 * kMs, true, true, far);
    CHECK(rig.last.seq > seq0 + 50, "the output is not written while the reference is invalid");
    for (int i = 0; i < 6; ++i)
      CHECK(rig.last.q[i] == before.q[i], "joint %d moved from %.12f to %.12f on an invalid reference", i,
            before.q[i], rig.last.q[i]);
    // Inf too.
    bad.seq = 3;
    bad.q[2] = kRef[2];
    bad.q[5] = -HUGE_VAL;
    const uint64_t e1 = rig.Errors();
    arflex_state_write(arflex_host_output(&rig.feeder, "reference"), &bad, sizeof(bad));
    CHECK(rig.WaitErrors(e1), "the Inf reference was not counted");
    rig.Watch(100 * kMs, false, true, far);
    for (int i = 0; i < 6; ++i) CHECK(rig.last.q[i] == before.q[i], "joint %d moved on an Inf reference", i);
    // A valid reference again: the hold clears and the output follows it (+ the correction).
    arflex_joint_ref good = bad;
    good.seq = 4;
    for (int i = 0; i < 6; ++i) good.q[i] = kRef[i] + (i == 0 ? 1e-3 : 0.0);
    const double excess = rig.max_jump_excess;  // the reference's own 1 mrad step is passed on as is
    arflex_state_write(arflex_host_output(&rig.feeder, "reference"), &good, sizeof(good));
    const uint64_t deadline = arflex_sys_now_ns() + 20 * kSec;
    bool moved = false;
    while (!moved && arflex_sys_now_ns() < deadline) {
      if (rig.Read()) moved = std::abs(rig.last.q[0] - before.q[0] - 1e-3) < 1e-4;
    }
    rig.max_jump_excess = excess;
    CHECK(moved, "a valid reference after invalid ones was not followed");
    CHECK((arflex_ctl_hold(rig.corr.ctl) & 0xffu) == ARFLEX_HOLD_NONE, "hold word 0x%x after a valid reference",
          arflex_ctl_hold(rig.corr.ctl));
  }
  // 3. joint_state: bound, the robot where the output is, but its values NaN: the robot's
  //    position is unknown, valid measurements 10 mm off are held (counted); a valid joint
  //    state at the output lets them in again and the output moves.
  {
    rig.Watch(200 * kMs, false, true, Eigen::Vector3d::Zero());
    // the correction may still be slewing towards what case 2 measured: at rest first
    CHECK(rig.Settle(50), "the output did not come to rest");
    const arflex_joint_ref held = rig.last;
    arflex_joint_state js;
    std::memset(&js, 0, sizeof(js));
    js.seq = 1;
    for (int i = 0; i < 6; ++i) js.q[i] = held.q[i];
    js.tau[1] = std::nan("");
    arflex_state_write(arflex_host_output(&rig.feeder, "joint_state"), &js, sizeof(js));
    const uint64_t e0 = rig.Errors();
    CHECK(arflex_host_bind(&rig.corr, "joint_state", arflex_host_output_name(&rig.feeder, "joint_state"), 2 * kSec) == 0,
          "BIND joint_state");
    CHECK(rig.WaitErrors(e0), "the NaN joint state was not counted");
    rig.Watch(300 * kMs, true, true, far);
    for (int i = 0; i < 6; ++i)
      CHECK(rig.last.q[i] == held.q[i], "joint %d moved while the robot's joint state was invalid", i);
    js.seq = 2;
    js.tau[1] = 0;
    arflex_state_write(arflex_host_output(&rig.feeder, "joint_state"), &js, sizeof(js));
    const uint64_t deadline = arflex_sys_now_ns() + 20 * kSec;
    uint64_t last_measure = 0;
    bool moved = false;
    while (!moved && arflex_sys_now_ns() < deadline) {
      if (rig.Read()) moved = rig.last.q[0] != held.q[0] || rig.last.q[1] != held.q[1];
      if (arflex_sys_now_ns() - last_measure > 20 * kMs) {
        rig.Measure(true, far);
        last_measure = arflex_sys_now_ns();
      }
    }
    CHECK(moved, "measurements were still held after a valid joint state");
  }
  printf("invalid: %llu invalid values counted as update errors\n", (unsigned long long)rig.Errors());
}

void CaseHold(Rig& rig) {
  // Vision drops out: invalid measurements far off are held, the output does not move.
  const arflex_joint_ref before = rig.last;
  rig.Watch(300 * kMs, true, false, Eigen::Vector3d(0.01, 0, 0));
  for (int i = 0; i < 6; ++i) {
    CHECK(rig.last.q[i] == before.q[i], "joint %d moved from %.12f to %.12f while vision was out", i,
          before.q[i], rig.last.q[i]);
  }
  // Valid but uncertain measurements (1 mm standard deviation > max_sigma 0.2 mm) are held too.
  rig.meas_var = 1e-6;
  rig.Watch(300 * kMs, true, true, Eigen::Vector3d(0.01, 0, 0));
  rig.meas_var = 0;
  for (int i = 0; i < 6; ++i) {
    CHECK(rig.last.q[i] == before.q[i], "joint %d moved from %.12f to %.12f on uncertain measurements", i,
          before.q[i], rig.last.q[i]);
  }
  // Tracking interlock: the robot's joints bound and 10 mrad away from the output (a robot
  // holding in safe mode): valid, certain measurements 10 mm off are held too.
  {
    arflex_joint_state js;
    std::memset(&js, 0, sizeof(js));
    js.seq = 1;
    for (int i = 0; i < 6; ++i) js.q[i] = before.q[i] + 0.01;
    arflex_state_write(arflex_host_output(&rig.feeder, "joint_state"), &js, sizeof(js));
    CHECK(arflex_host_bind(&rig.corr, "joint_state", arflex_host_output_name(&rig.feeder, "joint_state"), 2 * kSec) == 0,
          "BIND joint_state");
    rig.Watch(300 * kMs, true, true, Eigen::Vector3d(0.01, 0, 0));
    for (int i = 0; i < 6; ++i) {
      CHECK(rig.last.q[i] == before.q[i], "joint %d moved from %.12f to %.12f while the robot did not follow", i,
            before.q[i], rig.last.q[i]);
    }
  }
  // Disabled: the correction ramps out at max_rate, to exactly the reference.
  CHECK(arflex_host_set_param(&rig.corr, "enable", 0, nullptr, 2 * kSec) == 0, "SET_PARAM enable");
  {
    const uint64_t deadline = arflex_sys_now_ns() + 20 * kSec;
    bool at_ref = false;
    while (!at_ref && arflex_sys_now_ns() < deadline) {
      if (!rig.Read()) continue;
      at_ref = true;
      for (int i = 0; i < 6; ++i) at_ref = at_ref && rig.last.q[i] == kRef[i];
    }
    CHECK(at_ref, "the output did not return to the reference");
  }
}

}  // namespace tcpcorr_comp
