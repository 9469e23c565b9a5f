// test_cell_tools.cc - test_cell: cell.tools (the harness: cell_rig.h).
#include "cell_rig.h"

namespace celltest {

// One tool provider after the other behind the same consumer code: the same port type, the
// consumer's reader opens either; each follows the command from the same command segment,
// with its safety input bound to a guard the script plays (NORMAL, written while waiting:
// a tool holds without a fresh guard; bundles/tool-gripper/native/tests/test_tools.c).
void CaseTools() {
  static struct arflex_host script, grip, spin, traj;
  int r = MakeScript(&script, {{"command", kSampleT}, {"safety", kST}});
  CHECK(r == 0, "script: %d", r);
  struct arflex_safety_state guard;
  memset(&guard, 0, sizeof(guard));
  guard.mode = ARFLEX_SAFETY_STATE_MODE_NORMAL;
  guard.power_scale = 1;
  uint64_t guard_at = 0;
  auto speak = [&] {  // a fresh guard value every 5 ms at most
    if (Now() - guard_at < 5 * kMs) return;
    guard_at = Now();
    guard.t_ns = (int64_t)guard_at;
    ++guard.seq;
    arflex_state_write(arflex_host_output(&script, "safety"), &guard, sizeof(guard));
  };
  speak();
  // The consumer the cell has: trajectory's tool input, bound to each tool in turn (the
  // DRCR's rebinding); its tool_id output tells which tool lin motions are planned for.
  r = Make(&traj, "trajectory", "trajectory", kMs);
  CHECK(r == 0 && arflex_host_start(&traj, kCall) == 0, "trajectory: %d", r);
  Reader tid;
  CHECK(tid.Open(&traj, "tool_id", &kSampleT) == 0, "open tool_id");
  struct arflex_sample cmd;
  memset(&cmd, 0, sizeof(cmd));
  cmd.seq = 1;
  cmd.value = 0.4;
  CHECK(arflex_state_write(arflex_host_output(&script, "command"), &cmd, sizeof(cmd)) == 0, "cmd");
  struct arflex_host* tools[2] = {&grip, &spin};
  const char* exes[2] = {"tool-gripper", "tool-spindle"};
  const uint32_t ids[2] = {1, 2};
  for (int i = 0; i < 2; ++i) {
    r = Make(tools[i], exes[i] + 5, exes[i], kMs, nullptr, {{"safety_max_age_ms", 1000}});
    CHECK(r == 0, "%s: %d", exes[i], r);
    CHECK(arflex_host_bind(tools[i], "command", arflex_host_output_name(&script, "command"), kCall) == 0, "bind");
    speak();
    CHECK(arflex_host_bind(tools[i], "safety", arflex_host_output_name(&script, "safety"), kCall) == 0,
          "bind safety");
    CHECK(arflex_host_start(tools[i], kCall) == 0, "start");
    Reader rd;  // the consumer: expects arflex.ToolState 1.0 from whoever provides `tool`
    CHECK(rd.Open(tools[i], "tool", &kToolT) == 0, "%s: consumer cannot open its tool port", exes[i]);
    struct arflex_tool_state s;
    uint64_t seq;
    bool ready = false;
    const uint64_t dl = Now() + kWait;
    while (!ready && Now() < dl) {
      speak();
      if (rd.Read(&s, &seq) != 1) {
        sched_yield();
        continue;
      }
      ready = s.status == ARFLEX_TOOL_STATE_STATUS_READY && std::fabs(s.command - 0.4) < 1e-12;
    }
    CHECK(ready, "%s never reached the commanded level", exes[i]);
    CHECK(s.tool_id == ids[i] && s.mass > 0 && s.tcp_quat[0] == 1.0, "%s state", exes[i]);
    printf("%s: tool_id %u, level %.2f, mass %.1f kg\n", exes[i], s.tool_id, s.command, s.mass);
    CHECK(arflex_host_bind(&traj, "tool", arflex_host_output_name(tools[i], "tool"), kCall) == 0,
          "bind trajectory.tool to %s", exes[i]);
    // trajectory reports the mounted tool's id, then 0 (the flange) once it is unbound
    for (const uint32_t want : {ids[i], 0u}) {
      struct arflex_sample v;
      bool seen = false;
      const uint64_t d2 = Now() + kWait;
      while (!seen && Now() < d2) {
        if (tid.Read(&v, &seq) == 1 && v.value == (double)want) seen = true;
        else sched_yield();
      }
      CHECK(seen, "trajectory's tool_id never showed %u with %s", want, exes[i]);
      if (want != 0) CHECK(arflex_host_unbind(&traj, "tool", kCall) == 0, "unbind");
    }
    CHECK(arflex_host_shutdown(tools[i], kCall) == 0 && arflex_host_wait_exit(tools[i], 5 * kSec) == 0,
          "shutdown %s", exes[i]);
  }
}

}  // namespace celltest
