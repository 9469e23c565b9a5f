// test_cell - CTest cell.*: the cell's RT halves as processes under the rt-core host API,
// wired as the DRCR would wire them; the test itself plays the robot and the sensors through
// "script" instances whose output segments it writes.
//   test_cell <trajectory|program_switch|late_robot|stop_away|invalid_input|bad_program|force_guard|teach_replay|tools> <bin dir> <bundles dir>
// Each component (trajectory, force-guard, teach, tool-gripper, tool-spindle) is created from
// its bundle's contract, <bundles dir>/<name>/src/main/resources/OSGI-INF/arflex/<name>.xml
// (arflex_host_load_contract, docs/DECISIONS.md D32/D34): its ports, parameters with their
// defaults and bounds, safe mode, movesHardware and executable; no port or parameter of a
// component is declared here. The harness's own choices: a 1 ms period for every component
// but the guard (20 ms, so that the test sees each of its outputs), deadline = period,
// SCHED_OTHER, no mlock or cpu_dma_latency, no heartbeat watchdog, and in the tools case a
// tool safety freshness of 1000 ms where the contracts say 20 ms (the test's guard writes only
// while the test polls; checked against the contract's bounds). The scripts play the robot,
// the sensors, a guard and a command source: they are the test's own providers, not
// components, and their segments are declared here.
// Every case uses its own runtime id and ends by checking that no /dev/shm/arflex.<rid>.*,
// no queue and no child process is left. Waits are conditions with deadlines (counted in the
// components' cycles where the brief is about cycles); nothing asserts on timing.
//
// The harness (instances, CHECK, readers, the leak check) is cell_rig.h/.cc; the cases are in
// test_cell_<topic>.cc: trajectory (trajectory, program_switch, late_robot), state_transfer,
// force_guard, teach (teach_replay), tools, input (invalid_input, bad_program).
#include "cell_rig.h"

using namespace celltest;

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: %s <trajectory|program_switch|late_robot|stop_away|invalid_input|bad_program|force_guard|force_guard_state|teach_replay|teach_state|teach_sweep|tools> <bin dir> <bundles dir>\n", argv[0]);
    return 2;
  }
  bindir = argv[2];
  bundlesdir = argv[3];
  snprintf(rid, sizeof(rid), "cell-%d", (int)getpid());
  const std::string c = argv[1];
  if (c == "trajectory") CaseTrajectory();
  else if (c == "force_guard") CaseForceGuard();
  else if (c == "force_guard_state") CaseForceGuardState();
  else if (c == "teach_replay") CaseTeachReplay();
  else if (c == "teach_state") CaseTeachState();
  else if (c == "teach_sweep") CaseTeachSweep();
  else if (c == "tools") CaseTools();
  else if (c == "bad_program") CaseBadProgram();
  else if (c == "program_switch") CaseProgramSwitch();
  else if (c == "state_transfer") CaseStateTransfer();
  else if (c == "late_robot") CaseLateRobot();
  else if (c == "stop_away") CaseStopAway();
  else if (c == "invalid_input") CaseInvalidInput();
  else {
    fprintf(stderr, "unknown case '%s'\n", argv[1]);
    return 2;
  }
  DestroyAll();
  if (Leaked()) ++failures;
  if (failures) return 1;
  printf("ok %s\n", argv[1]);
  return 0;
}
