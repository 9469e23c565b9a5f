// cell_rig.h - the harness of test_cell (CTest cell.*, see test_cell.cc): the run's runtime id,
// the component and script instances it made, CHECK, and the helpers every case uses. The
// cases live by topic in test_cell_*.cc.
#ifndef ARFLEX_CELL_RIG_H
#define ARFLEX_CELL_RIG_H

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <sched.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <map>
#include <vector>

#include "arflex/host.h"
#include "arflex/host_contract.h"
#include "arflex_types/joint_ref.h"
#include "arflex_types/force_guard_state.h"
#include "arflex_types/tcp_correction_state.h"
#include "arflex_types/tcp_correction_state2.h"
#include "arflex_types/trajectory_state.h"
#include "arflex_types/teach_state.h"
#include "arflex_types/joint_state.h"
#include "arflex_types/safety_state.h"
#include "arflex_types/sample.h"
#include "arflex_types/tool_state.h"
#include "arflex_types/wrench.h"
#include "cellkin.h"

namespace celltest {

using arflex::cellkin::Model;
using arflex::cellkin::Q;

constexpr uint64_t kSec = 1000000000ull, kMs = 1000000ull;
constexpr uint64_t kCall = 2 * kSec, kWait = 30 * kSec;

inline char rid[ARFLEX_ID_MAX + 1];
inline std::string bindir, bundlesdir;
inline int failures;
inline std::vector<struct arflex_host*> hosts;

#define CHECK(c, ...)                                                      \
  do {                                                                     \
    if (!(c)) {                                                            \
      fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #c);         \
      fprintf(stderr, __VA_ARGS__);                                        \
      fputc('\n', stderr);                                                 \
      ++failures;                                                          \
      return;                                                              \
    }                                                                      \
  } while (0)

inline const struct arflex_port_type kRefT = {ARFLEX_TYPE_JOINT_REF_NAME, 1, 0, sizeof(arflex_joint_ref)};
inline const struct arflex_port_type kJsT = {ARFLEX_TYPE_JOINT_STATE_NAME, 1, 0, sizeof(arflex_joint_state)};
inline const struct arflex_port_type kWT = {ARFLEX_TYPE_WRENCH_NAME, 1, 0, sizeof(arflex_wrench)};
inline const struct arflex_port_type kST = {ARFLEX_TYPE_SAFETY_STATE_NAME, 1, 0, sizeof(arflex_safety_state)};
inline const struct arflex_port_type kToolT = {ARFLEX_TYPE_TOOL_STATE_NAME, 1, 0, sizeof(arflex_tool_state)};
inline const struct arflex_port_type kSampleT = {ARFLEX_TYPE_SAMPLE_NAME, 1, 0, sizeof(arflex_sample)};

struct arflex_ctl_config Config(uint64_t period);

struct Out {
  const char* port;
  struct arflex_port_type type;
};

// A script instance: the test's own provider, with the state outputs `outs` it writes itself.
int MakeScript(struct arflex_host* h, const std::vector<Out>& outs);

// A parameter default the harness chooses itself instead of the contract's.
struct Default {
  const char* name;
  double value;
};

// Creates instance `inst` of the component `comp` from its bundle's contract, with the
// harness's period and flags and the defaults `defs` (double parameters, within the
// contract's bounds); spawns the contract's executable from bindir and waits for READY.
int Make(struct arflex_host* h, const char* inst, const char* comp, uint64_t period,
         char* const* envp = nullptr, const std::vector<Default>& defs = {});

void DestroyAll();

// rt-core's test kit (arflex_testkit): /dev/shm and /dev/mqueue objects of rid, children.
bool Leaked();

// A reader of an output port with its own handle.
struct Reader {
  struct arflex_port port;
  bool open = false;
  int Open(struct arflex_host* h, const char* p, const struct arflex_port_type* t) {
    const char* name = arflex_host_output_name(h, p);
    if (!name) return -ENOENT;
    int r = arflex_port_open(&port, name, false, false, ARFLEX_PORT_STATE, t);
    open = r == 0;
    return r;
  }
  template <typename T>
  int Read(T* v, uint64_t* seq) { return arflex_state_read(&port, v, sizeof(*v), seq); }
  uint64_t Head() const { return __atomic_load_n(&port.hdr->head, __ATOMIC_ACQUIRE); }
  ~Reader() {
    if (open) arflex_port_close(&port);
  }
};

uint64_t Now();
// Writes an arm at rest at q (qd, tau 0) to a script's joint_state output, stamped now, with
// the next sequence number of *seq.
void WriteJointState(struct arflex_port* out, const Q& q, uint64_t* seq);
int SetI(struct arflex_host* h, const char* n, int64_t v);
std::string MakeDataDir();
void RemoveDir(const std::string& d);
bool WriteText(const std::string& path, const char* text);

struct Sample {
  uint64_t seq;
  Q q;
};

// Writes a resting robot at q (torques = nominal gravity) plus extra joint torque, and a
// wrench = tool weight + extra contact force (world frame, what a push adds): the script's
// joint_state and wrench (force_guard, teach_replay).
void WriteRobot(struct arflex_host* script, const Model& m, const Q& q, const Q& extra_tau,
                const Eigen::Vector3d& push_world, uint64_t* seq);

// The cases (test_cell <case> ...), one file a topic.
void CaseTrajectory();      // test_cell_trajectory.cc
void CaseProgramSwitch();   // test_cell_trajectory.cc
void CaseLateRobot();       // test_cell_trajectory.cc
void CaseStopAway();        // test_cell_stop_away.cc
void CaseStateTransfer();   // test_cell_state_transfer.cc
void CaseForceGuard();      // test_cell_force_guard.cc
void CaseForceGuardState(); // test_cell_force_guard_state.cc (D52)
void CaseTeachState();      // test_cell_teach_state.cc (D57)
void CaseTeachSweep();      // test_cell_teach_sweep.cc (D63)
void CaseTeachReplay();     // test_cell_teach.cc
void CaseTools();           // test_cell_tools.cc
void CaseInvalidInput();    // test_cell_input.cc
void CaseBadProgram();      // test_cell_input.cc

}  // namespace celltest

#endif  // ARFLEX_CELL_RIG_H
