// test_cell_input.cc - test_cell: cell.invalid_input (invalid input values) and cell.bad_program
// (a bad program file) (the harness: cell_rig.h).
#include "cell_rig.h"

namespace celltest {

// Validated data (docs/safety.md): joint_state and tool values that fail their checks (NaN,
// Inf, a non-unit tool quaternion) are not used and are counted as update errors; the output
// keeps what the valid values gave; a valid value afterwards is used again.
void CaseInvalidInput() {
  static struct arflex_host script, traj;
  int r = MakeScript(&script, {{"joint_state", kJsT}, {"tool", kToolT}});
  CHECK(r == 0, "script: %d", r);
  r = Make(&traj, "trajectory", "trajectory", kMs);
  CHECK(r == 0, "create/spawn trajectory: %d", r);
  CHECK(arflex_host_set_param(&traj, "run", 0, nullptr, kCall) == 0, "run=0");  // idle: the output stays put
  Reader rd, tid;
  CHECK(rd.Open(&traj, "joint_ref", &kRefT) == 0 && tid.Open(&traj, "tool_id", &kSampleT) == 0, "open outputs");
  struct arflex_port* js_out = arflex_host_output(&script, "joint_state");
  struct arflex_port* tool_out = arflex_host_output(&script, "tool");
  CHECK(arflex_host_bind(&traj, "joint_state", arflex_host_output_name(&script, "joint_state"), kCall) == 0,
        "bind joint_state");
  CHECK(arflex_host_start(&traj, kCall) == 0, "start");
  const double nan = std::nan(""), inf = HUGE_VAL;
  uint64_t js_seq = 0;
  auto write_js = [&](const Q& q, int bad_field) {  // bad_field: 0 none, 1 q NaN, 2 qd Inf, 3 tau NaN
    struct arflex_joint_state js;
    memset(&js, 0, sizeof(js));
    js.t_ns = (int64_t)Now();
    js.seq = ++js_seq;
    for (int j = 0; j < 6; ++j) js.q[j] = q[j];
    if (bad_field == 1) js.q[1] = nan;
    if (bad_field == 2) js.qd[3] = inf;
    if (bad_field == 3) js.tau[5] = nan;
    arflex_state_write(js_out, &js, sizeof(js));
  };
  auto errors = [&] {
    struct arflex_stats st;
    return arflex_ctl_stats_read(traj.ctl, &st) == 0 ? st.update_errors : 0;
  };
  auto wait_errors = [&](uint64_t above) {
    const uint64_t dl = Now() + kWait;
    while (errors() <= above && Now() < dl) sched_yield();
    return errors() > above;
  };
  Q robot;
  robot << -0.2, 0.4, 0.3, 0.1, 0.8, -0.1;
  // 1. Invalid measurements before the first valid one: counted, no reference written (the
  //    program waits for a measured arm to start from).
  for (int bad = 1; bad <= 3; ++bad) {
    const uint64_t e0 = errors();
    write_js(robot, bad);
    CHECK(wait_errors(e0), "invalid joint state %d was not counted", bad);
  }
  CHECK(rd.Head() == 0, "a reference was written before a valid measurement");
  // 2. The first valid one: the output starts at the arm.
  write_js(robot, 0);
  Q out = Q::Zero();
  uint64_t seq = 0;
  auto latest = [&]() {
    struct arflex_joint_ref ref;
    bool any = false;
    while (rd.Read(&ref, &seq) == 1) {
      for (int j = 0; j < 6; ++j) out[j] = ref.q[j];
      any = true;
    }
    return any;
  };
  {
    const uint64_t dl = Now() + kWait;
    while (!latest() && Now() < dl) sched_yield();
  }
  CHECK(seq != 0 && (out - robot).cwiseAbs().maxCoeff() < 1e-12, "the output did not start at the arm");
  // 3. An arm measured 80 mrad away at rest for 1.5 s, every value invalid (tau NaN): not used,
  //    the idle output stays (a valid arm that far for 1 s would pull the output to it).
  Q away = robot;
  away[0] += 0.08;
  const uint64_t e1 = errors();
  {
    const uint64_t end = Now() + 1500 * kMs;
    while (Now() < end) {
      write_js(away, 3);
      latest();
      sched_yield();
    }
  }
  CHECK(errors() > e1 + 100, "invalid joint states were not counted (%llu)", (unsigned long long)(errors() - e1));
  latest();
  CHECK((out - robot).cwiseAbs().maxCoeff() < 1e-12, "the output moved on invalid joint states (%g rad)",
        (out - robot).cwiseAbs().maxCoeff());
  // 4. The same pose valid: used again, the output comes to the arm after kAwayNs (1 s).
  {
    const uint64_t dl = Now() + kWait;
    bool there = false;
    while (!there && Now() < dl) {
      write_js(away, 0);
      if (latest()) there = (out - away).cwiseAbs().maxCoeff() < 1e-12;
      sched_yield();
    }
    CHECK(there, "a valid measurement after invalid ones was not used");
  }
  // 5. The tool: a valid one is used (tool_id 7); NaN TCP, a non-unit quaternion or an unknown
  //    status are counted and the last valid tool stays in use; a valid one afterwards is used.
  auto tool = [&](uint32_t id, int bad) {  // bad: 0 none, 1 tcp NaN, 2 quaternion not unit, 3 status
    static uint64_t tseq = 0;
    struct arflex_tool_state t;
    memset(&t, 0, sizeof(t));
    t.t_ns = (int64_t)Now();
    t.seq = ++tseq;
    t.tool_id = id;
    t.status = bad == 3 ? 99 : ARFLEX_TOOL_STATE_STATUS_READY;
    t.tcp_p[2] = bad == 1 ? nan : 0.1;
    t.tcp_quat[0] = bad == 2 ? 0.5 : 1.0;
    t.mass = 1;
    arflex_state_write(tool_out, &t, sizeof(t));
  };
  auto tool_id_is = [&](double want) {
    struct arflex_sample v;
    uint64_t s2;
    const uint64_t dl = Now() + kWait;
    while (Now() < dl) {
      if (tid.Read(&v, &s2) == 1 && v.value == want) return true;
      sched_yield();
    }
    return false;
  };
  tool(7, 0);
  CHECK(arflex_host_bind(&traj, "tool", arflex_host_output_name(&script, "tool"), kCall) == 0, "bind tool");
  CHECK(tool_id_is(7), "the valid tool 7 was not taken");
  for (int bad = 1; bad <= 3; ++bad) {
    const uint64_t e0 = errors();
    tool(9, bad);
    CHECK(wait_errors(e0), "invalid tool state %d was not counted", bad);
    // 200 values of tool_id after the error: all still 7.
    struct arflex_sample v;
    uint64_t s2 = 0, first = 0;
    bool all7 = true;
    const uint64_t dl = Now() + kWait;
    while (Now() < dl) {
      if (tid.Read(&v, &s2) != 1) {
        sched_yield();
        continue;
      }
      if (first == 0) first = s2;
      all7 = all7 && v.value == 7.0;
      if (s2 > first + 200) break;
    }
    CHECK(s2 > first + 200 && all7, "tool_id left 7 on invalid tool state %d", bad);
  }
  tool(9, 0);
  CHECK(tool_id_is(9), "a valid tool after invalid ones was not used");
  printf("invalid_input: %llu invalid values counted as update errors\n", (unsigned long long)errors());
  CHECK(arflex_host_stop(&traj, kCall) == 0, "stop");
}

// A bad program file fails the RT half's start (exit code 4, message names file:line);
// START with a program number that has no file is refused with -ENOENT; nothing is left.
void CaseBadProgram() {
  static struct arflex_host bad, good;
  const std::string dir = MakeDataDir();
  CHECK(!dir.empty(), "mkdtemp");
  std::string env = "ARFLEX_DATA_DIR=" + dir;
  char* envp[] = {const_cast<char*>(env.c_str()), nullptr};
  bool ok = WriteText(arflex::cellkin::ProgramPath(dir, 2),
                      "arflex-program 1\nptp 0 0 0 0 0 0\nptp 0 0 0 0 0 7\n");
  int r = ok ? Make(&bad, "bad", "trajectory", kMs, envp)
             : -EIO;
  RemoveDir(dir);
  CHECK(r == -ECHILD, "a bad program file was accepted (%d)", r);
  const int st = arflex_host_exit_status(&bad);
  CHECK(WIFEXITED(st) && WEXITSTATUS(st) == ARFLEX_EXIT_CONFIGURE, "exit status 0x%x", st);
  // No data dir: only program 0; START of program 5 is refused, program 0 starts.
  r = Make(&good, "good", "trajectory", kMs);
  CHECK(r == 0, "spawn: %d", r);
  CHECK(SetI(&good, "program", 5) == 0, "set program 5");
  r = arflex_host_start(&good, kCall);
  CHECK(r == -ENOENT, "START of a missing program: %d", r);
  CHECK(SetI(&good, "program", 0) == 0 && arflex_host_start(&good, kCall) == 0, "program 0");
  CHECK(arflex_host_stop(&good, kCall) == 0, "stop");
}

}  // namespace celltest
