// test_cell_stop_away.cc - cell.stop_away: after a protective stop whose causes are gone, the
// trajectory that waits for the fresh command moves its held output to an arm at rest more
// than 50 mrad from it (pushed there during the stop), after 1 s, and starts no motion; the
// fresh command then resumes it. Without it sim-robot (which after a stop takes only a
// reference at rest within ref_acquire_tol of the arm) and the operator (who gives the fresh
// command once the arm has taken a reference) wait for each other for ever (CellE2EIT, once).
#include "cell_rig.h"

namespace celltest {

void CaseStopAway() {
  static struct arflex_host script, traj;
  const std::string dir = MakeDataDir();
  CHECK(!dir.empty(), "mkdtemp");
  bool ok = WriteText(arflex::cellkin::ProgramPath(dir, 1),
                      "arflex-program 1\nstart 0 0 0 0 0 0\nptp 0.6 0 0 0 0 0 speed 0.3\n"
                      "ptp 0.6 0.4 0 0 0 0 speed 0.3\n");
  std::string env = "ARFLEX_DATA_DIR=" + dir;
  char* envp[] = {const_cast<char*>(env.c_str()), nullptr};
  int r = ok ? MakeScript(&script, {{"joint_state", kJsT}, {"safety", kST}}) : -EIO;
  CHECK(r == 0, "script: %d", r);
  r = Make(&traj, "trajectory", "trajectory", kMs, envp);
  RemoveDir(dir);
  CHECK(r == 0, "create/spawn trajectory: %d", r);
  CHECK(arflex_host_set_param(&traj, "safety_max_age_ms", arflex_f64_bits(1000), nullptr, kCall) == 0,
        "safety_max_age_ms");
  struct arflex_port* js_out = arflex_host_output(&script, "joint_state");
  struct arflex_port* sf_out = arflex_host_output(&script, "safety");
  uint64_t js_seq = 0, sf_seq = 0;
  auto write_js = [&](const Q& q) { WriteJointState(js_out, q, &js_seq); };
  auto write_safety = [&](bool stop) {
    struct arflex_safety_state s;
    memset(&s, 0, sizeof(s));
    s.t_ns = (int64_t)Now();
    s.seq = ++sf_seq;
    s.mode = stop ? ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP : ARFLEX_SAFETY_STATE_MODE_NORMAL;
    s.flags = stop ? ARFLEX_SAFETY_STATE_FLAG_FORCE_LIMIT | ARFLEX_SAFETY_STATE_FLAG_RESET_REQUIRED : 0;
    s.power_scale = stop ? 0.1 : 1.0;
    s.force_limit = 150;
    arflex_state_write(sf_out, &s, sizeof(s));
  };
  write_js(Q::Zero());
  write_safety(false);
  CHECK(arflex_host_bind(&traj, "joint_state", arflex_host_output_name(&script, "joint_state"), kCall) == 0 &&
            arflex_host_bind(&traj, "safety", arflex_host_output_name(&script, "safety"), kCall) == 0,
        "bind joint_state and safety");
  CHECK(SetI(&traj, "program", 1) == 0 && arflex_host_start(&traj, kCall) == 0, "start program 1");
  Reader rd;
  CHECK(rd.Open(&traj, "joint_ref", &kRefT) == 0, "open joint_ref");
  auto hold = [&] { return arflex_ctl_hold(traj.ctl) & 0xffu; };

  // 1. The arm follows the program into its first motion; the guard stops it there; the arm
  //    follows the stop ramp and comes to rest with the output.
  struct arflex_joint_ref ref;
  uint64_t seq = 0;
  Q q = Q::Zero(), held = Q::Zero();
  int phase = 0;
  uint64_t still = 0, t_stop = 0;
  uint64_t deadline = Now() + kWait;
  while (Now() < deadline && phase < 2) {
    if (rd.Read(&ref, &seq) != 1) {
      sched_yield();
      continue;
    }
    Q now;
    for (int j = 0; j < 6; ++j) now[j] = ref.q[j];
    write_js(now);  // the robot follows
    if (phase == 0) {
      write_safety(false);
      if (now[0] > 0.2) {
        phase = 1;
        t_stop = Now();
      }
    } else {
      write_safety(true);
      still = (now - q).cwiseAbs().maxCoeff() == 0 ? still + 1 : 0;
      if (still > 100) phase = 2;
    }
    q = now;
  }
  CHECK(phase == 2, "the output did not come to rest after the stop (phase %d)", phase);
  CHECK(q[0] > 0.2 && q[0] < 0.6, "stopped at q1 %.3f, in the first motion", q[0]);
  held = q;
  printf("stop_away: stopped in the first motion at q1 %.4f, %.0f ms after the stop\n", q[0],
         (Now() - t_stop) * 1e-6);

  // 2. Pushed during the stop: the arm at rest 80 mrad away for 1.5 s while the stop holds.
  //    The output stays where it stopped (the stop holds on purpose).
  Q arm = held;
  arm[1] += 0.08;
  deadline = Now() + 1500 * kMs;
  while (Now() < deadline) {
    if (rd.Read(&ref, &seq) != 1) {
      sched_yield();
      continue;
    }
    write_js(arm);
    write_safety(true);
    for (int j = 0; j < 6; ++j) q[j] = ref.q[j];
    CHECK((q - held).cwiseAbs().maxCoeff() == 0, "the output moved during the stop (seq %llu)",
          (unsigned long long)seq);
  }

  // 3. The stop's causes are gone (the guard's reset): the output waits for the fresh command
  //    and, the arm being at rest 80 mrad away, moves to it after 1 s; no motion starts.
  const uint64_t t_reset = Now();
  uint64_t t_left = 0, t_moved = 0, rest_after = 0;
  deadline = t_reset + 5 * kSec;
  while (Now() < deadline && rest_after < 500) {
    if (rd.Read(&ref, &seq) != 1) {
      sched_yield();
      continue;
    }
    write_js(arm);
    write_safety(false);
    for (int j = 0; j < 6; ++j) q[j] = ref.q[j];
    if (!t_moved) {
      // on its way (at most the limiter's steps) only joint 2 moves, from the stop's pose to the arm
      Q off = q - held;
      off[1] = 0;
      CHECK(off.cwiseAbs().maxCoeff() < 1e-12 && q[1] >= held[1] - 1e-12 && q[1] <= arm[1] + 1e-12,
            "the output left the stop's pose for somewhere else than the arm (q1 %.4f q2 %.4f)", q[0], q[1]);
      if (!t_left && (q - held).cwiseAbs().maxCoeff() > 0) t_left = Now();
      if ((q - arm).cwiseAbs().maxCoeff() < 1e-12) t_moved = Now();
    } else {
      CHECK((q - arm).cwiseAbs().maxCoeff() < 1e-12, "motion started without the fresh command (q1 %.4f q2 %.4f)",
            q[0], q[1]);
      ++rest_after;
    }
  }
  CHECK(t_moved, "the held output did not move to the arm at rest 80 mrad away after the reset: the robot "
        "that takes only a reference near the arm and the operator would wait for each other");
  CHECK(t_left - t_reset >= 990 * kMs, "the output left %.0f ms after the reset, before 1 s", (t_left - t_reset) * 1e-6);
  CHECK(rest_after >= 500, "only %llu outputs at the arm", (unsigned long long)rest_after);
  CHECK(hold() == ARFLEX_HOLD_AWAIT_COMMAND, "hold word 0x%x while the fresh command is awaited", hold());
  printf("stop_away: the held output left for the arm 80 mrad away %.0f ms after the reset and reached it "
         "%.0f ms after; no motion for 500 cycles after\n", (t_left - t_reset) * 1e-6, (t_moved - t_left) * 1e-6);

  // 4. The fresh command: the program plays again, from the arm.
  CHECK(arflex_host_set_param(&traj, "run", 1, nullptr, kCall) == 0, "run=1 (the fresh command)");
  bool resumed = false;
  deadline = Now() + kWait;
  while (!resumed && Now() < deadline) {
    if (rd.Read(&ref, &seq) != 1) {
      sched_yield();
      continue;
    }
    Q now;
    for (int j = 0; j < 6; ++j) now[j] = ref.q[j];
    write_js(now);
    write_safety(false);
    resumed = (now - arm).cwiseAbs().maxCoeff() > 1e-3;
  }
  CHECK(resumed, "the fresh command did not resume the program");
  CHECK(hold() == 0, "hold word 0x%x after the command", hold());
}

}  // namespace celltest
