// test_cell_trajectory.cc - test_cell: cell.trajectory, cell.program_switch, cell.late_robot
// (the harness: cell_rig.h).
#include "cell_rig.h"

namespace celltest {

void CaseTrajectory() {
  static struct arflex_host traj;
  const std::string dir = MakeDataDir();
  CHECK(!dir.empty(), "mkdtemp");
  const char* prog =
      "arflex-program 1\nstart 0 0 0 0 0 0\n"
      "ptp 0.5 0.3 0.6 -0.4 0.8 0.3\n"
      "ptp -0.4 0.1 0.9 0.5 -0.6 -0.2 speed 0.5\n"
      "ptp 0 0.2 0.5 0 0.6 0\n";
  const double target[3][6] = {{0.5, 0.3, 0.6, -0.4, 0.8, 0.3},
                               {-0.4, 0.1, 0.9, 0.5, -0.6, -0.2},
                               {0, 0.2, 0.5, 0, 0.6, 0}};
  bool ok = WriteText(arflex::cellkin::ProgramPath(dir, 1), prog);
  std::string env = "ARFLEX_DATA_DIR=" + dir;
  char* envp[] = {const_cast<char*>(env.c_str()), nullptr};
  int r = ok ? Make(&traj, "trajectory", "trajectory", kMs, envp)
             : -EIO;
  RemoveDir(dir);  // loaded at configure: the process does not need the file any more
  CHECK(r == 0, "create/spawn trajectory: %d", r);
  CHECK(SetI(&traj, "program", 1) == 0, "set program");
  Reader rd;
  CHECK(rd.Open(&traj, "joint_ref", &kRefT) == 0, "open joint_ref");
  CHECK(arflex_host_start(&traj, kCall) == 0, "start");

  const double deg = M_PI / 180;
  const double vmax[6] = {123 * deg, 115 * deg, 112 * deg, 179 * deg, 172 * deg, 219 * deg};
  std::vector<Sample> s;
  s.reserve(200000);
  bool paused_checked = false;
  double near[3] = {1e9, 1e9, 1e9};
  uint64_t pause_at = 0, stable = 0;
  const uint64_t deadline = Now() + kWait;
  while (Now() < deadline) {
    struct arflex_joint_ref ref;
    uint64_t seq;
    if (rd.Read(&ref, &seq) != 1) {
      sched_yield();
      continue;
    }
    Sample x{seq, Q::Zero()};
    for (int j = 0; j < 6; ++j) x.q[j] = ref.q[j];
    for (int k = 0; k < 3; ++k) {
      double d = 0;
      for (int j = 0; j < 6; ++j) d = std::max(d, std::fabs(x.q[j] - target[k][j]));
      near[k] = std::min(near[k], d);
    }
    const bool same = !s.empty() && (s.back().q - x.q).norm() == 0;
    s.push_back(x);
    // Pause in the middle of the second motion, check the hold, resume.
    if (!paused_checked && near[0] < 1e-4 && pause_at == 0 && x.q[0] < 0.1 && x.q[0] > -0.3) {
      CHECK(arflex_host_set_param(&traj, "run", 0, nullptr, kCall) == 0, "run=0");
      pause_at = seq;
    }
    if (pause_at && !paused_checked) {
      stable = same ? stable + 1 : 0;
      if (stable >= 300) {  // 300 consecutive reads without motion while paused
        paused_checked = true;
        CHECK(arflex_host_set_param(&traj, "run", 1, nullptr, kCall) == 0, "run=1");
      }
    }
    if (near[2] < 1e-9 && paused_checked) {
      // at the last target; finished when it stays there
      if (same && ++stable > 50) break;
    }
  }
  CHECK(paused_checked, "the pause was never observed (pause_at %llu)", (unsigned long long)pause_at);
  for (int k = 0; k < 3; ++k) CHECK(near[k] < 1e-4, "target %d missed by %g rad", k + 1, near[k]);
  // Never jumps: on every pair of consecutive cycles, |dq_j| <= vmax_j * dt.
  uint64_t pairs = 0;
  double worst = 0;
  for (size_t i = 1; i < s.size(); ++i) {
    if (s[i].seq != s[i - 1].seq + 1) continue;
    ++pairs;
    for (int j = 0; j < 6; ++j)
      worst = std::max(worst, std::fabs(s[i].q[j] - s[i - 1].q[j]) / (vmax[j] * 1e-3));
  }
  printf("trajectory: %zu samples, %llu consecutive pairs, max |dq| per cycle %.3f of vmax*dt\n",
         s.size(), (unsigned long long)pairs, worst);
  CHECK(pairs > 200, "only %llu consecutive cycle pairs observed", (unsigned long long)pairs);
  CHECK(worst <= 1.0 + 1e-9, "a joint moved %.4f x vmax*dt in one cycle", worst);
  CHECK(arflex_host_stop(&traj, kCall) == 0, "stop");
}

// A program selected while running is taken at the next standstill: the running joint motion
// of program 1 ends on its target, then program 2 plays from there; program 1's second
// motion never starts. Every consecutive pair of cycles within the speed limits.
void CaseProgramSwitch() {
  static struct arflex_host traj;
  const std::string dir = MakeDataDir();
  CHECK(!dir.empty(), "mkdtemp");
  bool ok = WriteText(arflex::cellkin::ProgramPath(dir, 1),
                      "arflex-program 1\nstart 0 0 0 0 0 0\nptp 0.3 0 0 0 0 0 speed 0.3\n"
                      "ptp 0.6 0 0 0 0 0 speed 0.3\n") &&
            WriteText(arflex::cellkin::ProgramPath(dir, 2),
                      "arflex-program 1\nptp 0.3 0.3 0 0 0 0 speed 0.3\n");
  std::string env = "ARFLEX_DATA_DIR=" + dir;
  char* envp[] = {const_cast<char*>(env.c_str()), nullptr};
  int r = ok ? Make(&traj, "trajectory", "trajectory", kMs, envp)
             : -EIO;
  RemoveDir(dir);
  CHECK(r == 0, "create/spawn trajectory: %d", r);
  CHECK(SetI(&traj, "program", 1) == 0 && arflex_host_start(&traj, kCall) == 0, "start program 1");
  Reader rd;
  CHECK(rd.Open(&traj, "joint_ref", &kRefT) == 0, "open joint_ref");
  bool switched = false;
  double max_q0 = 0, q0_at_q1 = -1;
  uint64_t stable = 0;
  Q last = Q::Zero();
  const uint64_t deadline = Now() + kWait;
  while (Now() < deadline) {
    struct arflex_joint_ref ref;
    uint64_t seq;
    if (rd.Read(&ref, &seq) != 1) {
      sched_yield();
      continue;
    }
    Q q;
    for (int j = 0; j < 6; ++j) q[j] = ref.q[j];
    max_q0 = std::max(max_q0, q[0]);
    if (!switched && q[0] > 0.05) {  // in the middle of program 1's first motion
      CHECK(SetI(&traj, "program", 2) == 0, "set program 2 while running");
      switched = true;
    }
    if (q0_at_q1 < 0 && q[1] > 1e-6) q0_at_q1 = q[0];  // program 2 began
    stable = (q - last).norm() == 0 ? stable + 1 : 0;
    last = q;
    if (std::fabs(q[1] - 0.3) < 1e-12 && stable > 50) break;
  }
  printf("program_switch: program 2 began at q1 = %.9f (program 1's first target 0.3), q1 max %.9f\n",
         q0_at_q1, max_q0);
  CHECK(switched, "program 1 never moved");
  CHECK(std::fabs(last[1] - 0.3) < 1e-12, "program 2 did not reach its target (q2 = %g)", last[1]);
  CHECK(std::fabs(q0_at_q1 - 0.3) < 1e-9, "program 2 began before program 1's motion ended (q1 = %g)",
        q0_at_q1);
  CHECK(max_q0 <= 0.3 + 1e-9, "program 1's second motion started (q1 reached %g)", max_q0);
  CHECK(arflex_host_stop(&traj, kCall) == 0, "stop");
}

// A robot that appears while the trajectory plays (joint_state bound late, as when the
// trajectory is installed first), somewhere else than the output: the program starts over from
// the measured pose (no reference pulling the arm across), at rest, within the limits, and
// plays to its end. Bound again to a robot that followed the output (the same robot rewired):
// the program goes on where it was.
void CaseLateRobot() {
  static struct arflex_host script, traj;
  const std::string dir = MakeDataDir();
  CHECK(!dir.empty(), "mkdtemp");
  bool ok = WriteText(arflex::cellkin::ProgramPath(dir, 1),
                      "arflex-program 1\nstart 0 0 0 0 0 0\nptp 0.5 0 0 0 0 0 speed 0.3\n"
                      "ptp 0.5 0.3 0 0 0 0 speed 0.3\n") &&
            WriteText(arflex::cellkin::ProgramPath(dir, 2),
                      "arflex-program 1\nptp 0.5 0 0 0 0 0 speed 0.3\nptp 0.5 0.3 0 0 0 0 speed 0.3\n");
  std::string env = "ARFLEX_DATA_DIR=" + dir;
  char* envp[] = {const_cast<char*>(env.c_str()), nullptr};
  int r = ok ? MakeScript(&script, {{"joint_state", kJsT}}) : -EIO;
  CHECK(r == 0, "script: %d", r);
  r = Make(&traj, "trajectory", "trajectory", kMs, envp);
  RemoveDir(dir);
  CHECK(r == 0, "create/spawn trajectory: %d", r);
  CHECK(SetI(&traj, "program", 1) == 0 && arflex_host_start(&traj, kCall) == 0, "start program 1");
  Reader rd;
  CHECK(rd.Open(&traj, "joint_ref", &kRefT) == 0, "open joint_ref");
  const double deg = M_PI / 180;
  const double vmax[6] = {123 * deg, 115 * deg, 112 * deg, 179 * deg, 172 * deg, 219 * deg};
  struct arflex_port* js_out = arflex_host_output(&script, "joint_state");
  uint64_t js_seq = 0;
  auto write_js = [&](const Q& q) { WriteJointState(js_out, q, &js_seq); };
  Q robot;
  robot << -0.2, 0.4, 0.3, 0.1, 0.8, -0.1;  // where the late robot's arm is
  Q q = Q::Zero(), last = Q::Zero();
  uint64_t seq = 0, last_seq = 0, stable = 0;
  int phase = 0;  // 0 unbound, 1 bound far (restart expected), 2 rebound while following
  double jump = -1, worst = 0, q2_min_after_rebind = 1e9, q1_min_phase1 = 1e9;
  const uint64_t deadline = Now() + kWait;
  while (Now() < deadline) {
    struct arflex_joint_ref ref;
    if (rd.Read(&ref, &seq) != 1) {
      sched_yield();
      continue;
    }
    for (int j = 0; j < 6; ++j) q[j] = ref.q[j];
    const bool consecutive = last_seq && seq == last_seq + 1;
    if (phase == 0 && q[0] > 0.1) {  // in the middle of the first motion: the robot appears
      write_js(robot);
      CHECK(arflex_host_bind(&traj, "joint_state", arflex_host_output_name(&script, "joint_state"), kCall) == 0,
            "bind joint_state");
      phase = 1;
    } else if (phase == 1) {
      if (jump < 0) {
        if ((q - robot).cwiseAbs().maxCoeff() < 1e-3) jump = (q - last).cwiseAbs().maxCoeff();  // restarted
      } else {
        q1_min_phase1 = std::min(q1_min_phase1, q[0]);
        for (int j = 0; consecutive && j < 6; ++j) worst = std::max(worst, std::fabs(q[j] - last[j]) / (vmax[j] * 1e-3));
        write_js(q);  // the robot follows from now on
        if (std::fabs(q[0] - 0.5) < 1e-12 && q[1] > 0.05) {  // in the second motion: the same robot rewired
          CHECK(arflex_host_bind(&traj, "joint_state", arflex_host_output_name(&script, "joint_state"), kCall) == 0,
                "bind joint_state again");
          phase = 2;
        }
      }
    } else if (phase == 2) {
      write_js(q);
      for (int j = 0; consecutive && j < 6; ++j) worst = std::max(worst, std::fabs(q[j] - last[j]) / (vmax[j] * 1e-3));
      q2_min_after_rebind = std::min(q2_min_after_rebind, q[1]);
      stable = (q - last).norm() == 0 ? stable + 1 : 0;
      if (std::fabs(q[1] - 0.3) < 1e-12 && stable > 50) break;
    }
    last = q;
    last_seq = seq;
  }
  printf("late_robot: output jumped %.3f rad to the arm when it appeared; then max |dq| per cycle %.3f of vmax*dt; "
         "q2 after the rewiring >= %.4f\n", jump, worst, q2_min_after_rebind);
  CHECK(phase == 2, "phase %d reached (the program did not restart from the arm and play on)", phase);
  CHECK(jump > 0.1, "the output did not start over at the robot's pose (step %g)", jump);
  CHECK(q1_min_phase1 >= robot[0] - 1e-9, "the restarted program went below the arm's q1 (%g)", q1_min_phase1);
  CHECK(worst <= 1.0 + 1e-9, "a joint moved %.4f x vmax*dt in one cycle after the restart", worst);
  CHECK(q2_min_after_rebind > 0.05 - 1e-3, "the program restarted when the following robot was rewired (q2 %g)",
        q2_min_after_rebind);
  CHECK(std::fabs(last[1] - 0.3) < 1e-12 && std::fabs(last[0] - 0.5) < 1e-12, "did not end on the last target");
  // The program has ended. An arm that stays 30 mrad away (inside the 50 mrad tolerance: a
  // corrected arm sits up to 20 mrad off) for 1.5 s leaves the output where it is; one that
  // stays 80 mrad away (its robot does not follow) for 1 s gets the output moved to it.
  auto hold_arm = [&](const Q& arm, uint64_t ns, Q* out) {
    const uint64_t end = Now() + ns;
    while (Now() < end) {
      write_js(arm);
      struct arflex_joint_ref ref;
      if (rd.Read(&ref, &seq) == 1)
        for (int j = 0; j < 6; ++j) (*out)[j] = ref.q[j];
      sched_yield();
    }
  };
  Q end_pose = last, out = last, arm = last;
  arm[0] += 0.03;
  hold_arm(arm, 1500 * kMs, &out);
  CHECK((out - end_pose).cwiseAbs().maxCoeff() == 0, "the output moved to an arm 30 mrad away");
  arm[0] = end_pose[0] + 0.08;
  const uint64_t t_away = Now();
  bool moved = false;
  while (!moved && Now() < t_away + 5 * kSec) {
    hold_arm(arm, 10 * kMs, &out);
    moved = (out - arm).cwiseAbs().maxCoeff() < 1e-12;
  }
  printf("late_robot: an arm 80 mrad from the ended program's output got it after %.2f s\n", (Now() - t_away) * 1e-9);
  CHECK(moved, "the idle output did not move to an arm 80 mrad away");
  CHECK(Now() - t_away >= 990 * kMs, "the output moved before the arm had been away for 1 s");
  // Program 2 playing in a loop while the arm stays where it is, at rest (its robot refuses the
  // reference):
  // once the output has been more than 50 mrad away for 1 s, the program starts over from its
  // first motion at the arm; then it plays on from there.
  const Q held = arm;
  CHECK(SetI(&traj, "loop", 1) == 0 && SetI(&traj, "program", 2) == 0, "program 2 in a loop");
  uint64_t t_left = 0, t_back = 0;
  bool played_on = false;
  const uint64_t t_end = Now() + 10 * kSec;
  while (!played_on && Now() < t_end) {
    write_js(held);
    struct arflex_joint_ref ref;
    if (rd.Read(&ref, &seq) != 1) {
      sched_yield();
      continue;
    }
    for (int j = 0; j < 6; ++j) out[j] = ref.q[j];
    const double d = (out - held).cwiseAbs().maxCoeff();
    if (t_left == 0 && d > 0.05) t_left = Now();
    // Back at the arm: within 1 mrad (the restarted program's first cycle already moves it a
    // little); the program's own path stays 80 mrad from the held arm on joint 1.
    if (t_left != 0 && t_back == 0 && d < 1e-3) t_back = Now();
    if (t_back != 0 && d > 0.01) played_on = true;
  }
  printf("late_robot: a looping program whose arm stays put left it and started over at the arm %.2f s later\n",
         t_back ? (t_back - t_left) * 1e-9 : -1.0);
  CHECK(t_left != 0, "the looping program never moved away from the arm");
  CHECK(t_back != 0, "the playing program did not start over at an arm that stays away");
  CHECK(t_back - t_left >= 990 * kMs, "started over before the arm had been away for 1 s");
  CHECK(played_on, "the program did not play on from the arm");
  CHECK(arflex_host_stop(&traj, kCall) == 0, "stop");
}

}  // namespace celltest
