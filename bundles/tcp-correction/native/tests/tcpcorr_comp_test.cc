// tcpcorr.comp.*: the tcp-correction RT half under the rt-core host API. The test plays the
// rest of the cell: a "feeder" instance whose reference and tcp_pose segments it writes, and
// the plant: the measured TCP is the nominal TCP of the corrected output, shifted by a fixed
// error (what the true arm does differently from the nominal model).
//
//   tcpcorr_comp_test <case> <tcp-correction exe> <contract>   cases: converge, hold, invalid, switch,
//   adopt, convert
//
// The corrector's ports, parameters (max_rate, max_sigma, track_tol, orientation, ... with
// their defaults), period and safe mode come from the bundle's contract
// (arflex_host_load_contract, docs/DECISIONS.md D32/D34); the rate-limit check uses the
// contract's max_rate. The harness's own choices: SCHED_OTHER, no mlock or cpu_dma_latency, no
// heartbeat watchdog. The feeder plays the motion source, vision and the robot: it is the
// test's own provider, not a component, and its segments are declared here.
// Every case ends by checking that no /dev/shm or /dev/mqueue object of its runtime id and no
// child process is left. Waits are on conditions with deadlines; nothing asserts on timing.
//
// The harness (the Rig, CHECK, the leak check) is tcpcorr_comp_rig.h/.cc; after the common part
// below (converge) the cases are in tcpcorr_comp_held.cc (invalid, hold) and
// tcpcorr_comp_handover.cc (switch, adopt) and tcpcorr_comp_convert.cc (convert).
#include <unistd.h>

#include "tcpcorr_comp_rig.h"

namespace tcpcorr_comp {
namespace {

void RunCase(const std::string& name, const char* exe) {
  Rig rig;
  double err = 0;
  CHECK(rig.Create(exe) == 0, "create/spawn/bind/start");
  err = rig.Converge(2e-6);
  CHECK(err < 2e-6, "TCP error %.3f um after the loop (from %.3f um)", 1e6 * err, 1e6 * kPlantError.norm());
  // The `error` output: the first measurement saw the whole plant error (no correction yet);
  // one more measurement of the converged arm shows it below 0.01 mm; `correction` is non-zero.
  CHECK(std::abs(rig.first_error_mm - 1e3 * kPlantError.norm()) < 1e-6, "first error output %.6f mm, expected %.6f",
        rig.first_error_mm, 1e3 * kPlantError.norm());
  rig.Watch(100 * kMs, true, true, Eigen::Vector3d::Zero());
  CHECK(rig.last_error_mm >= 0 && rig.last_error_mm < 0.01, "error output %.6f mm after converging", rig.last_error_mm);
  CHECK(rig.last_size_mrad > 0.01, "correction output %.6f mrad after converging", rig.last_size_mrad);
  if (name == "invalid") CaseInvalid(rig);
  if (name == "switch") CaseSwitch(rig);
  if (name == "adopt") CaseAdopt(rig, exe);
  if (name == "convert") CaseConvert(rig, exe);
  if (name == "hold") CaseHold(rig);
  if (failures) return;  // a check of the case failed: it ended there
  CHECK(rig.max_jump_excess < 1e-12, "output jumped %.3g rad beyond the rate limit", rig.max_jump_excess);
  CHECK(arflex_host_shutdown(&rig.corr, 5 * kSec) == 0, "SHUTDOWN");
  CHECK(arflex_host_wait_exit(&rig.corr, 10 * kSec) == 0, "exit");
}

}  // namespace
}  // namespace tcpcorr_comp

using namespace tcpcorr_comp;

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr,
                 "usage: tcpcorr_comp_test <converge|hold|invalid|switch|adopt|convert> <tcp-correction exe> <contract>\n");
    return 2;
  }
  contract_xml = argv[3];
  std::snprintf(rid, sizeof(rid), "tcc%d", static_cast<int>(getpid()));
  const std::string name = argv[1];
  if (name != "converge" && name != "hold" && name != "invalid" && name != "switch" && name != "adopt" &&
      name != "convert") {
    std::fprintf(stderr, "tcpcorr_comp_test: unknown case '%s'\n", argv[1]);
    return 2;
  }
  RunCase(name, argv[2]);
  if (Leaked()) ++failures;
  std::printf("tcpcorr.comp.%s: %s\n", name.c_str(), failures ? "FAIL" : "ok");
  return failures ? 1 : 0;
}
