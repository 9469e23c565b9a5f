// tcpcorr_comp_rig.h - the harness of tcpcorr_comp_test (tcpcorr.comp.*, see tcpcorr_comp_test.cc):
// the run's runtime id and the contract's figures, CHECK, and the Rig: the feeder the test
// writes, the corrector under test and the plant. The cases live by topic in tcpcorr_comp_*.cc.
#ifndef ARFLEX_TCPCORR_COMP_RIG_H
#define ARFLEX_TCPCORR_COMP_RIG_H

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

extern "C" {
#include "arflex/host.h"
#include "arflex/host_contract.h"
}
#include "arflex_cellmodel/kinematics.h"
#include "arflex_types/joint_ref.h"
#include "arflex_types/joint_state.h"
#include "arflex_types/pose.h"
#include "arflex_types/sample.h"
#include "arflex_types/tcp_correction_state.h"
#include "arflex_types/tcp_correction_state2.h"

namespace tcpcorr_comp {

constexpr uint64_t kSec = 1000000000ull;
constexpr uint64_t kMs = 1000000ull;
inline double max_rate;            // rad/s: the contract's default of max_rate
inline double period_s;            // s: the contract's period
inline const char* contract_xml;

inline char rid[ARFLEX_ID_MAX + 1];
inline int failures = 0;

// A failed check is counted and ends the case (the Rig's destructor cleans up).
#define CHECK(cond, ...)                                                   \
  do {                                                                     \
    if (!(cond)) {                                                         \
      std::fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond); \
      std::fprintf(stderr, __VA_ARGS__);                                   \
      std::fputc('\n', stderr);                                            \
      ++failures;                                                          \
      return;                                                              \
    }                                                                      \
  } while (0)

arflex_ctl_config Config();

// rt-core's test kit (arflex_testkit): /dev/shm and /dev/mqueue objects of rid, children.
bool Leaked();

inline const arflex::cellmodel::JointVector kRef = {0.2, 0.5, 0.3, 0.1, 0.8, -0.2};
inline const Eigen::Vector3d kPlantError(1.2e-3, -0.8e-3, 0.6e-3);  // true arm vs nominal, at the TCP

struct Rig {
  arflex_host_contract c{};
  arflex_host feeder{}, corr{}, feeder2{};
  bool feeder2_made = false;
  arflex_port out{}, err_out{}, size_out{};
  bool out_open = false, err_open = false, size_open = false;
  double first_error_mm = -1;  // the first value of the `error` output
  double last_error_mm = -1;   // the newest one
  double last_size_mrad = -1;  // the newest `correction` value
  double meas_var = 0;         // position variance the plant's measurements report (m^2)
  arflex::cellmodel::NominalKinematics kin{arflex::cellmodel::DefaultArm()};
  arflex_joint_ref last{};
  uint64_t pose_seq = 0;
  double max_jump_excess = 0;  // largest step beyond max_rate * period * cycles

  int Create(const char* exe);
  ~Rig();
  // Another half of tcp-correction (`inst`) bound to the feeder's reference and tcp_pose, with
  // its corrected output open in `o`: READY, not started. `state`, when given, is the type of
  // its state block instead of the contract's (a half whose contract declares an older one).
  int Second(arflex_host* h, const char* inst, const char* exe, arflex_port* o,
             const arflex_port_type* state = nullptr);
  // Creates feeder2, a second motion source, with one reference: kRef with `dq0` added to
  // joint 0.
  int MakeFeeder2(double dq0);
  // Reads the newest output; checks that it never jumps. Returns true on a new value.
  bool Read();
  // The plant: the measurement of the corrected output (nominal TCP + the plant's error).
  void Measure(bool valid, const Eigen::Vector3d& extra);
  // Writes a measurement of the last output (as Measure) made malformed: 1 position NaN,
  // 2 quaternion not unit, 3 a negative variance, 4 validity flag 2, 5 orientation Inf.
  void MeasureMalformed(int how, const Eigen::Vector3d& extra);
  // Reads until `n` new outputs in a row equal the one before them: the correction has come
  // to rest (it slews at max_rate towards its target). False when it has not within 20 s.
  bool Settle(int n);
  uint64_t Errors();
  bool WaitErrors(uint64_t above);
  // Runs the loop (a measurement every 20 ms of wall time) until the true TCP error is
  // below `tol` or the deadline passes. Returns the final error (m).
  double Converge(double tol);
  // Reads outputs for `ns` of wall time (to watch a hold or a ramp), measuring with `valid`.
  void Watch(uint64_t ns, bool measure, bool valid, const Eigen::Vector3d& extra);

 private:
  // A measurement of the last output: its nominal TCP + the plant's error + `extra`, numbered;
  // no variance, not yet valid.
  arflex_pose Pose(const Eigen::Vector3d& extra);
};

// The cases after the common part (converge) of RunCase, one file a topic.
void CaseInvalid(Rig& rig);                 // tcpcorr_comp_held.cc
void CaseHold(Rig& rig);                    // tcpcorr_comp_held.cc
void CaseSwitch(Rig& rig);                  // tcpcorr_comp_handover.cc
void CaseAdopt(Rig& rig, const char* exe);  // tcpcorr_comp_handover.cc
void CaseConvert(Rig& rig, const char* exe);  // tcpcorr_comp_convert.cc

}  // namespace tcpcorr_comp

#endif  // ARFLEX_TCPCORR_COMP_RIG_H
