// test_cell_force_guard.cc - test_cell: cell.force_guard (the harness: cell_rig.h).
#include "cell_rig.h"

namespace celltest {

// Waits for the next guard output; returns false at the deadline.
bool NextSafety(Reader* rd, struct arflex_safety_state* s, uint64_t* seq, uint64_t deadline) {
  while (Now() < deadline) {
    if (rd->Read(s, seq) == 1) return true;
    sched_yield();
  }
  return false;
}

// Scripts a push and checks that the guard's first PROTECTIVE_STOP output is at most two
// outputs after the guard's output counter observed right after the push was written (one
// output may come from a cycle that had read its inputs just before the write: that is the
// "same cycle" allowance; the next one must have seen it). Repeats when the reader missed
// outputs and so cannot decide. Returns the cycles from the push to the stop, or -1.
int PushAndCount(struct arflex_host* script, Reader* rd, const Model& m, const Q& q,
                 const Q& extra_tau, const Eigen::Vector3d& push, uint64_t* wseq) {
  struct arflex_safety_state s;
  uint64_t seq;
  WriteRobot(script, m, q, extra_tau, push, wseq);
  const uint64_t h0 = rd->Head();
  uint64_t last = 0;
  bool gap = false;
  while (NextSafety(rd, &s, &seq, Now() + 5 * kSec)) {
    if (last && seq != last + 1 && seq <= h0 + 2) gap = true;
    last = seq;
    if (s.mode == ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP) {
      if (seq <= h0 + 2) return (int)(seq - h0);
      return gap ? -2 : -1;
    }
    if (seq > h0 + 2 && !gap) return -1;
  }
  return -1;
}

void CaseForceGuard() {
  static struct arflex_host script, guard, traj;
  Model m;
  uint64_t wseq = 0;
  int r = MakeScript(&script, {{"joint_state", kJsT}, {"wrench", kWT}});
  CHECK(r == 0, "script: %d", r);
  // A slower guard period (20 ms) lets the test see each of its outputs.
  r = Make(&guard, "guard", "force-guard", 20 * kMs);
  CHECK(r == 0, "guard: %d", r);
  r = Make(&traj, "trajectory", "trajectory", kMs);
  CHECK(r == 0, "trajectory: %d", r);
  CHECK(SetI(&traj, "loop", 1) == 0, "loop");
  // the guard writes every 20 ms here: fresh means younger than 100 ms
  CHECK(arflex_host_set_param(&traj, "safety_max_age_ms", arflex_f64_bits(100), nullptr, kCall) == 0,
        "safety_max_age_ms");
  Q q;
  q << 0.1, 0.2, 0.5, 0.1, 0.6, 0.2;
  WriteRobot(&script, m, q, Q::Zero(), Eigen::Vector3d::Zero(), &wseq);
  CHECK(arflex_host_bind(&guard, "joint_state", arflex_host_output_name(&script, "joint_state"), kCall) == 0, "bind js");
  CHECK(arflex_host_bind(&guard, "wrench", arflex_host_output_name(&script, "wrench"), kCall) == 0, "bind wrench");
  CHECK(arflex_host_bind(&traj, "safety", arflex_host_output_name(&guard, "safety"), kCall) == 0, "bind safety");
  Reader rd, tr;
  CHECK(rd.Open(&guard, "safety", &kST) == 0 && tr.Open(&traj, "joint_ref", &kRefT) == 0, "readers");
  CHECK(arflex_host_start(&guard, kCall) == 0 && arflex_host_start(&traj, kCall) == 0, "start");

  struct arflex_safety_state s;
  uint64_t seq;
  // Rest with a 100 N push (below the 150 N limit): NORMAL for 10 outputs.
  WriteRobot(&script, m, q, Q::Zero(), Eigen::Vector3d(0, 100, 0), &wseq);
  for (int i = 0; i < 10; ++i) {
    CHECK(NextSafety(&rd, &s, &seq, Now() + 5 * kSec), "no guard output");
    if (i < 2) continue;  // outputs of cycles before the write
    CHECK(s.mode == ARFLEX_SAFETY_STATE_MODE_NORMAL, "mode %u at rest (force %.1f N)", s.mode, s.force_norm);
    CHECK(std::fabs(s.force_norm - 100) < 1e-6, "contact force %.6f N, expected 100", s.force_norm);
  }
  // The trajectory moves while NORMAL.
  struct arflex_joint_ref ref0, ref1;
  uint64_t tseq;
  const uint64_t dl = Now() + kWait;
  while (tr.Read(&ref0, &tseq) != 1 && Now() < dl) sched_yield();
  bool moved = false;
  while (!moved && Now() < dl) {
    if (tr.Read(&ref1, &tseq) == 1) moved = std::fabs(ref1.q[1] - ref0.q[1]) > 1e-3;
  }
  CHECK(moved, "trajectory does not move in NORMAL mode");

  // 1. A 300 N push: protective stop in the same or the next cycle.
  int cycles = -2;
  for (int attempt = 0; attempt < 5 && cycles == -2; ++attempt) {
    cycles = PushAndCount(&script, &rd, m, q, Q::Zero(), Eigen::Vector3d(300, 0, 0), &wseq);
    if (cycles == -2) {  // undecidable (missed outputs): reset and try again
      WriteRobot(&script, m, q, Q::Zero(), Eigen::Vector3d::Zero(), &wseq);
      CHECK(arflex_host_reset(&guard, kCall) == 0, "reset for retry");
      do {
        CHECK(NextSafety(&rd, &s, &seq, Now() + 5 * kSec), "no output");
      } while (s.mode != ARFLEX_SAFETY_STATE_MODE_NORMAL);
    }
  }
  CHECK(cycles >= 1 && cycles <= 2, "protective stop %d outputs after the push (want 1..2)", cycles);
  printf("force-guard: push -> protective stop in output +%d of the guard's cycle counter\n", cycles);
  // 2. Stays stopped after the push is gone, with the reasons and the power fraction.
  WriteRobot(&script, m, q, Q::Zero(), Eigen::Vector3d::Zero(), &wseq);
  for (int i = 0; i < 15; ++i) {
    CHECK(NextSafety(&rd, &s, &seq, Now() + 5 * kSec), "no output");
    CHECK(s.mode == ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP, "left safe mode without reset");
    CHECK((s.flags & ARFLEX_SAFETY_STATE_FLAG_FORCE_LIMIT) && (s.flags & ARFLEX_SAFETY_STATE_FLAG_RESET_REQUIRED),
          "flags 0x%x", s.flags);
    CHECK(std::fabs(s.power_scale - 0.1) < 1e-12, "power %g", s.power_scale);
  }
  // 3. The trajectory stopped: after its stop time its reference no longer changes, over
  //    500 of its own cycles.
  {
    uint64_t first = 0, still = 0;
    const uint64_t d2 = Now() + kWait;
    struct arflex_joint_ref a, b;
    bool have = false;
    while (Now() < d2 && still < 500) {
      if (tr.Read(&b, &tseq) != 1) continue;
      if (!first) first = tseq;
      if (tseq < first + 400) continue;  // 0.4 s: the stop ramp (stop_time 0.3 s) is over
      if (have && memcmp(a.q, b.q, sizeof(a.q)) != 0) {
        CHECK(false, "trajectory moved during the protective stop (seq %llu)", (unsigned long long)tseq);
      }
      if (!have) {
        a = b;
        have = true;
        still = tseq;
      }
      if (tseq - still >= 500) break;
    }
    CHECK(have, "no trajectory output during the stop");
  }
  // 4. Operator reset by the parameter edge: NORMAL again.
  CHECK(arflex_host_set_param(&guard, "reset", 1, nullptr, kCall) == 0, "reset=1");
  bool normal = false;
  for (int i = 0; i < 20 && !normal; ++i) {
    CHECK(NextSafety(&rd, &s, &seq, Now() + 5 * kSec), "no output");
    normal = s.mode == ARFLEX_SAFETY_STATE_MODE_NORMAL;
  }
  CHECK(normal, "reset parameter edge did not leave safe mode");
  CHECK(arflex_host_set_param(&guard, "reset", 0, nullptr, kCall) == 0, "reset=0");
  // 4b. The reset permits, it does not start (SAFETY.md 2): the trajectory waits for a fresh
  //     command, with its hold word saying so; a `run` written after the reset resumes it.
  {
    struct arflex_joint_ref a, b;
    bool have = false;
    uint64_t since = 0;
    const uint64_t d3 = Now() + kWait;
    while (Now() < d3) {
      if (tr.Read(&b, &tseq) != 1) continue;
      if (!have) {
        a = b;
        have = true;
        since = tseq;
      }
      CHECK(memcmp(a.q, b.q, sizeof(a.q)) == 0, "the trajectory moved after the reset without a command");
      if (tseq - since >= 500) break;
    }
    CHECK(have && tseq - since >= 500, "no trajectory output after the reset");
    CHECK(((arflex_ctl_hold(traj.ctl) & 0xffu) == ARFLEX_HOLD_AWAIT_COMMAND), "hold word 0x%x",
          arflex_ctl_hold(traj.ctl));
    CHECK(arflex_host_set_param(&traj, "run", 1, nullptr, kCall) == 0, "run=1 (the fresh command)");
    bool resumed = false;
    const uint64_t d4 = Now() + kWait;
    while (!resumed && Now() < d4)
      if (tr.Read(&b, &tseq) == 1) resumed = memcmp(a.q, b.q, sizeof(a.q)) != 0;
    CHECK(resumed, "the fresh command did not resume the motion");
    CHECK(arflex_ctl_hold(traj.ctl) == 0, "hold word 0x%x after the command", arflex_ctl_hold(traj.ctl));
  }
  // 5. An external joint torque (4 kN m on joint 2) trips it too; the RESET command clears it.
  cycles = PushAndCount(&script, &rd, m, q, (Q() << 0, 4000, 0, 0, 0, 0).finished(),
                        Eigen::Vector3d::Zero(), &wseq);
  CHECK(cycles >= 1 && cycles <= 2, "torque trip %d outputs after (want 1..2)", cycles);
  WriteRobot(&script, m, q, Q::Zero(), Eigen::Vector3d::Zero(), &wseq);
  for (int i = 0; i < 5; ++i) {
    CHECK(NextSafety(&rd, &s, &seq, Now() + 5 * kSec), "no output");
    CHECK(s.mode == ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP, "left safe mode without reset");
  }
  CHECK(arflex_host_reset(&guard, kCall) == 0, "RESET command");
  normal = false;
  for (int i = 0; i < 20 && !normal; ++i) {
    CHECK(NextSafety(&rd, &s, &seq, Now() + 5 * kSec), "no output");
    normal = s.mode == ARFLEX_SAFETY_STATE_MODE_NORMAL;
  }
  CHECK(normal, "RESET command did not leave safe mode");
  CHECK(arflex_host_stop(&traj, kCall) == 0 && arflex_host_stop(&guard, kCall) == 0, "stop");
}

}  // namespace celltest
