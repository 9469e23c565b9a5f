// test_cell - CTest cell.*: the cell's RT halves as processes under the rt-core host API,
// wired as the DRCR would wire them; the test itself plays the robot and the sensors through
// "script" instances whose output segments it writes.
//   test_cell <trajectory|program_switch|late_robot|invalid_input|bad_program|force_guard|teach_replay|tools> <bin dir> <bundles dir>
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
#include "arflex_types/tcp_correction_state.h"
#include "arflex_types/trajectory_state.h"
#include "arflex_types/joint_state.h"
#include "arflex_types/safety_state.h"
#include "arflex_types/sample.h"
#include "arflex_types/tool_state.h"
#include "arflex_types/wrench.h"
#include "cellkin.h"
#include "helper.h" /* rt-core test kit: leak checks */

using arflex::cellkin::Model;
using arflex::cellkin::Q;

namespace {

constexpr uint64_t kSec = 1000000000ull, kMs = 1000000ull;
constexpr uint64_t kCall = 2 * kSec, kWait = 30 * kSec;

char rid[ARFLEX_ID_MAX + 1];
std::string bindir, bundlesdir;
int failures;
std::vector<struct arflex_host*> hosts;

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

const struct arflex_port_type kRefT = {ARFLEX_TYPE_JOINT_REF_NAME, 1, 0, sizeof(arflex_joint_ref)};
const struct arflex_port_type kJsT = {ARFLEX_TYPE_JOINT_STATE_NAME, 1, 0, sizeof(arflex_joint_state)};
const struct arflex_port_type kWT = {ARFLEX_TYPE_WRENCH_NAME, 1, 0, sizeof(arflex_wrench)};
const struct arflex_port_type kST = {ARFLEX_TYPE_SAFETY_STATE_NAME, 1, 0, sizeof(arflex_safety_state)};
const struct arflex_port_type kToolT = {ARFLEX_TYPE_TOOL_STATE_NAME, 1, 0, sizeof(arflex_tool_state)};
const struct arflex_port_type kSampleT = {ARFLEX_TYPE_SAMPLE_NAME, 1, 0, sizeof(arflex_sample)};

struct arflex_ctl_config Config(uint64_t period) {
  struct arflex_ctl_config c;
  memset(&c, 0, sizeof(c));
  c.period_ns = period;
  c.cfg_flags = ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
  return c;
}

struct Out {
  const char* port;
  struct arflex_port_type type;
};

// A script instance: the test's own provider, with the state outputs `outs` it writes itself.
int MakeScript(struct arflex_host* h, const std::vector<Out>& outs) {
  struct arflex_host_output o[8];
  memset(h, 0, sizeof(*h));
  for (size_t i = 0; i < outs.size(); ++i) {
    o[i].port = outs[i].port;
    o[i].spec = {ARFLEX_PORT_STATE, outs[i].type, 1, ARFLEX_OVERFLOW_NONE};
  }
  struct arflex_host_opts opts;
  memset(&opts, 0, sizeof(opts));
  opts.runtime = rid;
  opts.instance = "script";
  opts.config = Config(kMs);
  opts.outputs = o;
  opts.noutputs = (unsigned)outs.size();
  int r = arflex_host_create(h, &opts);
  if (r == 0) hosts.push_back(h);
  return r;
}

// A parameter default the harness chooses itself instead of the contract's.
struct Default {
  const char* name;
  double value;
};

// Creates instance `inst` of the component `comp` from its bundle's contract, with the
// harness's period and flags and the defaults `defs` (double parameters, within the
// contract's bounds); spawns the contract's executable from bindir and waits for READY.
int Make(struct arflex_host* h, const char* inst, const char* comp, uint64_t period,
         char* const* envp = nullptr, const std::vector<Default>& defs = {}) {
  static const struct arflex_host_type types[] = {
      ARFLEX_HOST_TYPE(JOINT_REF),    ARFLEX_HOST_TYPE(JOINT_STATE), ARFLEX_HOST_TYPE(WRENCH),
      ARFLEX_HOST_TYPE(SAFETY_STATE), ARFLEX_HOST_TYPE(TOOL_STATE),  ARFLEX_HOST_TYPE(SAMPLE),
      ARFLEX_HOST_TYPE(TRAJECTORY_STATE), ARFLEX_HOST_TYPE(TCP_CORRECTION_STATE)};
  static struct arflex_host_contract c;  // read again for each instance
  const std::string xml = bundlesdir + "/" + comp + "/src/main/resources/OSGI-INF/arflex/" + comp + ".xml";
  char err[512];
  memset(h, 0, sizeof(*h));
  int r = arflex_host_load_contract(&c, xml.c_str(), types, sizeof(types) / sizeof(types[0]), err, sizeof(err));
  if (r < 0) {
    fprintf(stderr, "%s\n", err);
    return r;
  }
  for (const Default& d : defs) {
    struct arflex_param_slot* s = nullptr;
    for (unsigned i = 0; i < c.nparams; ++i)
      if (strcmp(c.params[i].name, d.name) == 0) s = &c.params[i];
    if (!s || s->type != ARFLEX_PARAM_DOUBLE || d.value < arflex_bits_f64(s->min_bits) ||
        d.value > arflex_bits_f64(s->max_bits)) {
      fprintf(stderr, "%s: no double parameter %s admitting %g\n", xml.c_str(), d.name, d.value);
      return -EINVAL;
    }
    s->default_bits = arflex_f64_bits(d.value);
  }
  struct arflex_host_opts opts;
  arflex_host_contract_opts(&c, rid, inst, &opts);
  opts.config.period_ns = period;
  opts.config.deadline_ns = period;
  opts.config.priority = 0;
  opts.config.hb_timeout_ns = 0;
  opts.config.cfg_flags |= ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
  r = arflex_host_create(h, &opts);
  if (r < 0) return r;
  hosts.push_back(h);
  const std::string path = bindir + "/" + c.executable;
  if ((r = arflex_host_spawn(h, path.c_str(), nullptr, envp)) < 0) return r;
  return arflex_host_wait_state(h, ARFLEX_STATE_READY, 10 * kSec);
}

void DestroyAll() {
  for (auto* h : hosts) {
    if (h->pid > 0 && !h->reaped && arflex_host_shutdown(h, kCall) == 0)
      arflex_host_wait_exit(h, 5 * kSec);
    arflex_host_destroy(h);
  }
  hosts.clear();
}

// rt-core's test kit (arflex_testkit): /dev/shm and /dev/mqueue objects of rid, children.
bool Leaked() {
  bool any = th_leftovers(rid) > 0;
  if (!th_no_children()) {
    fprintf(stderr, "leak: a child process is left\n");
    any = true;
  }
  return any;
}

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

uint64_t Now() { return arflex_sys_now_ns(); }

int SetI(struct arflex_host* h, const char* n, int64_t v) {
  return arflex_host_set_param(h, n, (uint64_t)v, nullptr, kCall);
}

std::string MakeDataDir() {
  char dir[] = "/tmp/arflex-cell-XXXXXX";
  if (!mkdtemp(dir)) return "";
  return dir;
}

void RemoveDir(const std::string& d) {
  if (d.empty()) return;
  if (DIR* dd = opendir(d.c_str())) {
    while (struct dirent* e = readdir(dd)) {
      if (e->d_name[0] == '.') continue;
      unlink((d + "/" + e->d_name).c_str());
    }
    closedir(dd);
  }
  rmdir(d.c_str());
}

bool WriteText(const std::string& path, const char* text) {
  FILE* f = fopen(path.c_str(), "w");
  if (!f) return false;
  fputs(text, f);
  return fclose(f) == 0;
}

struct Sample {
  uint64_t seq;
  Q q;
};

// ---- trajectory ----------------------------------------------------------------------------

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

// State transfer (docs/DECISIONS.md D41): a second trajectory half told the first one's state
// segment (ADOPT) before its START plays on from there cycle for cycle: every reference both
// halves wrote under the same seq is the same, while the program moves. Without the ADOPT a
// fresh half starts its program over (the jump the transfer avoids); a state block of another
// type refuses the START.
void CaseStateTransfer() {
  static struct arflex_host a, b, fresh, wrong, other;
  const std::string dir = MakeDataDir();
  CHECK(!dir.empty(), "mkdtemp");
  const char* prog =
      "arflex-program 1\nstart 0 0 0 0 0 0\n"
      "ptp 0.5 0.3 0.6 -0.4 0.8 0.3 speed 0.2\n"
      "lin 2.0 0.3 1.2 0.70710678 0 0.70710678 0 speed 0.1\n"
      "ptp 0 0.2 0.5 0 0.6 0 speed 0.2\n";
  bool ok = WriteText(arflex::cellkin::ProgramPath(dir, 1), prog);
  std::string env = "ARFLEX_DATA_DIR=" + dir;
  char* envp[] = {const_cast<char*>(env.c_str()), nullptr};
  int r = ok ? Make(&a, "trajectory", "trajectory", kMs, envp) : -EIO;
  if (r == 0) r = Make(&b, "1-trajectory", "trajectory", kMs, envp);
  if (r == 0) r = Make(&fresh, "2-trajectory", "trajectory", kMs, envp);
  if (r == 0) r = Make(&wrong, "3-trajectory", "trajectory", kMs, envp);
  RemoveDir(dir);
  CHECK(r == 0, "create/spawn the trajectory halves: %d", r);
  CHECK(arflex_host_state(&a) != nullptr, "the contract's state block has a segment");
  for (struct arflex_host* h : {&a, &b, &fresh, &wrong}) CHECK(SetI(h, "program", 1) == 0, "program 1");
  Reader ra, rb, rf;
  CHECK(ra.Open(&a, "joint_ref", &kRefT) == 0 && rb.Open(&b, "joint_ref", &kRefT) == 0 &&
            rf.Open(&fresh, "joint_ref", &kRefT) == 0, "open joint_ref");
  CHECK(arflex_host_start(&a, kCall) == 0, "start a");
  // well into the program: the first motion under way
  std::map<uint64_t, Q> qa;
  struct arflex_joint_ref ref;
  uint64_t seq;
  uint64_t deadline = Now() + kWait;
  while (Now() < deadline && qa.size() < 1500) {
    if (ra.Read(&ref, &seq) == 1) {
      Q q;
      for (int j = 0; j < 6; ++j) q[j] = ref.q[j];
      qa[ref.seq] = q;
    } else {
      sched_yield();
    }
  }
  CHECK(qa.size() >= 1500, "a wrote %zu references", qa.size());
  CHECK((qa.rbegin()->second - qa.begin()->second).cwiseAbs().maxCoeff() > 0.05, "a is moving");
  CHECK(arflex_host_adopt(&b, arflex_host_state(&a)->name, kCall) == 0, "ADOPT");
  CHECK(arflex_host_start(&b, kCall) == 0, "start b");
  CHECK(arflex_host_start(&fresh, kCall) == 0, "start fresh");
  std::map<uint64_t, Q> qb;
  Q fresh_first = Q::Constant(1e9), a_then = Q::Zero();
  bool fresh_seen = false;
  deadline = Now() + kWait;
  while (Now() < deadline && qb.size() < 1000) {
    bool any = false;
    if (ra.Read(&ref, &seq) == 1) {
      for (int j = 0; j < 6; ++j) qa[ref.seq][j] = ref.q[j];
      any = true;
    }
    if (rb.Read(&ref, &seq) == 1) {
      for (int j = 0; j < 6; ++j) qb[ref.seq][j] = ref.q[j];
      any = true;
    }
    if (!fresh_seen && rf.Read(&ref, &seq) == 1) {
      for (int j = 0; j < 6; ++j) fresh_first[j] = ref.q[j];
      a_then = qa.rbegin()->second;
      fresh_seen = true;
      any = true;
    }
    if (!any) sched_yield();
  }
  CHECK(qb.size() >= 1000 && fresh_seen, "b wrote %zu references", qb.size());
  // b's references carry on a's seq and equal a's, cycle for cycle
  size_t common = 0;
  double worst = 0;
  for (const auto& [k, q] : qb) {
    auto it = qa.find(k);
    if (it == qa.end()) continue;
    ++common;
    worst = std::max(worst, (q - it->second).cwiseAbs().maxCoeff());
  }
  const double fresh_jump = (fresh_first - a_then).cwiseAbs().maxCoeff();
  printf("state_transfer: b's first seq %llu (a's newest before b's START around it), %zu references "
         "of both under the same seq, largest difference %.3g rad; a fresh half without the state "
         "starts %.3f rad away from a\n",
         (unsigned long long)qb.begin()->first, common, worst, fresh_jump);
  CHECK(qb.begin()->first > 1500, "b continued a's sequence (first seq %llu)",
        (unsigned long long)qb.begin()->first);
  CHECK(common >= 500, "only %zu references under the same seq", common);
  CHECK(worst < 1e-9, "b differs from a by %g rad under the same seq", worst);
  CHECK(fresh_jump > 0.05, "without the state the half would have started %g rad away", fresh_jump);
  // a state block of another type: the START is refused, the half stays READY
  static const struct arflex_port_type other_t = {ARFLEX_TYPE_TCP_CORRECTION_STATE_NAME, 1, 0,
                                                  sizeof(struct arflex_tcp_correction_state)};
  struct arflex_port seg;
  char name[ARFLEX_OBJ_NAME_SIZE];
  snprintf(name, sizeof(name), "/arflex.%s.other.state", rid);
  struct arflex_port_spec spec = {ARFLEX_PORT_STATE, other_t, 1, ARFLEX_OVERFLOW_NONE};
  CHECK(arflex_port_create(&seg, name, &spec) == 0, "create the other state");
  struct arflex_tcp_correction_state cs;
  memset(&cs, 0, sizeof(cs));
  arflex_state_write(&seg, &cs, sizeof(cs));
  CHECK(arflex_host_adopt(&wrong, name, kCall) == 0, "ADOPT of another type is the hook's to judge");
  r = arflex_host_start(&wrong, kCall);
  arflex_port_destroy(&seg);
  CHECK(r == -EPROTOTYPE, "START after adopting another type: %d", r);
  CHECK(arflex_ctl_state(wrong.ctl) == ARFLEX_STATE_READY, "refused START leaves it READY");
  (void)other;
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
  auto write_js = [&](const Q& q) {
    struct arflex_joint_state js;
    memset(&js, 0, sizeof(js));
    js.t_ns = (int64_t)Now();
    js.seq = ++js_seq;
    for (int j = 0; j < 6; ++j) js.q[j] = q[j];
    arflex_state_write(js_out, &js, sizeof(js));
  };
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


// ---- force-guard ----------------------------------------------------------------------------

// Writes a resting robot at q (torques = nominal gravity) plus extra joint torque, and a
// wrench = tool weight + extra contact force (world frame, what a push adds).
void WriteRobot(struct arflex_host* script, const Model& m, const Q& q, const Q& extra_tau,
                const Eigen::Vector3d& push_world, uint64_t* seq) {
  struct arflex_joint_state js;
  memset(&js, 0, sizeof(js));
  js.t_ns = (int64_t)Now();
  js.seq = ++*seq;
  const Q tau = m.GravityTorque(q, 0) + extra_tau;
  for (int j = 0; j < 6; ++j) {
    js.q[j] = q[j];
    js.tau[j] = tau[j];
  }
  struct arflex_wrench w;
  memset(&w, 0, sizeof(w));
  w.t_ns = js.t_ns;
  w.seq = js.seq;
  Eigen::Vector3d f0, t0;
  m.ToolWeightWrench(q, 0, &f0, &t0);
  // The arm pushes back against a push on the tool: sensor force = weight - R^T push.
  const Eigen::Vector3d f = f0 - m.Flange(q).linear().transpose() * push_world;
  for (int k = 0; k < 3; ++k) {
    w.force[k] = f[k];
    w.torque[k] = t0[k];
  }
  arflex_state_write(arflex_host_output(script, "joint_state"), &js, sizeof(js));
  arflex_state_write(arflex_host_output(script, "wrench"), &w, sizeof(w));
}

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

// ---- teach + replay -------------------------------------------------------------------------

void CaseTeachReplay() {
  static struct arflex_host script, teach, traj;
  Model m;
  const std::string dir = MakeDataDir();
  CHECK(!dir.empty(), "mkdtemp");
  std::string env = "ARFLEX_DATA_DIR=" + dir;
  char* envp[] = {const_cast<char*>(env.c_str()), nullptr};
  int r = MakeScript(&script, {{"joint_state", kJsT}, {"wrench", kWT}, {"safety", kST}});
  CHECK(r == 0, "script: %d", r);
  struct arflex_safety_state safety;
  memset(&safety, 0, sizeof(safety));
  safety.mode = ARFLEX_SAFETY_STATE_MODE_NORMAL;
  safety.power_scale = 1;
  arflex_state_write(arflex_host_output(&script, "safety"), &safety, sizeof(safety));
  r = Make(&teach, "teach", "teach", kMs, envp);
  if (r != 0) RemoveDir(dir);
  CHECK(r == 0, "teach: %d", r);
  Q q;
  q << 0, 0.2, 0.5, 0, 0.6, 0;
  uint64_t wseq = 0;
  WriteRobot(&script, m, q, Q::Zero(), Eigen::Vector3d::Zero(), &wseq);
  bool ok = arflex_host_bind(&teach, "joint_state", arflex_host_output_name(&script, "joint_state"), kCall) == 0 &&
            arflex_host_bind(&teach, "wrench", arflex_host_output_name(&script, "wrench"), kCall) == 0 &&
            arflex_host_bind(&teach, "safety", arflex_host_output_name(&script, "safety"), kCall) == 0 &&
            SetI(&teach, "save_slot", 3) == 0 && arflex_host_start(&teach, kCall) == 0 &&
            arflex_host_set_param(&teach, "teach", 1, nullptr, kCall) == 0;
  if (!ok) RemoveDir(dir);
  CHECK(ok, "bind/start teach");
  Reader tr;
  CHECK(tr.Open(&teach, "joint_ref", &kRefT) == 0, "open teach ref");
  // The test plays a perfect robot: the measured position is teach's reference; the hand
  // pulls 60 N along +y for 1500 of teach's cycles, then along -z for 1000, then lets go; at
  // 3000 a protective stop comes and the hand pulls along +x for 400 cycles: the arm must not
  // yield; at 3400 the stop ends and the hand is gone.
  std::vector<Q> taught, frozen;
  uint64_t first = 0, seq = 0;
  const uint64_t dl = Now() + kWait;
  struct arflex_joint_ref ref;
  while (Now() < dl) {
    if (tr.Read(&ref, &seq) != 1) {
      sched_yield();
      continue;
    }
    if (!first) first = seq;
    const uint64_t k = seq - first;
    Q qr;
    for (int j = 0; j < 6; ++j) qr[j] = ref.q[j];
    taught.push_back(qr);
    Eigen::Vector3d hand = Eigen::Vector3d::Zero();
    if (k < 1500) hand = Eigen::Vector3d(0, 60, 0);
    else if (k < 2500) hand = Eigen::Vector3d(0, 0, -60);
    else if (k >= 3000 && k < 3400) hand = Eigen::Vector3d(60, 0, 0);
    else if (k >= 3600) break;
    if (k >= 3010 && k < 3400) frozen.push_back(qr);
    const uint32_t mode = k >= 3000 && k < 3400 ? ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP
                                                : ARFLEX_SAFETY_STATE_MODE_NORMAL;
    if (mode != safety.mode) {  // written before the force, read by teach after it
      safety.mode = mode;
      ++safety.seq;
      arflex_state_write(arflex_host_output(&script, "safety"), &safety, sizeof(safety));
    }
    WriteRobot(&script, m, qr, Q::Zero(), hand, &wseq);
  }
  const Eigen::Vector3d p0 = m.Tcp(q).translation(), p1 = m.Tcp(taught.back()).translation();
  printf("teach: TCP moved by (%.4f, %.4f, %.4f) m\n", p1.x() - p0.x(), p1.y() - p0.y(), p1.z() - p0.z());
  ok = p1.y() - p0.y() > 0.1 && p0.z() - p1.z() > 0.05 && std::fabs(p1.x() - p0.x()) < 0.01;
  bool held = frozen.size() > 100;
  for (const Q& f : frozen) held = held && (f - frozen.front()).norm() == 0;
  ok = ok && held;
  if (!ok) RemoveDir(dir);
  CHECK(ok, "the arm did not follow the hand (or yielded during the protective stop: %zu "
        "frozen samples, held %d)", frozen.size(), held);
  // Leave teach mode, save.
  const std::string path = arflex::cellkin::ProgramPath(dir, 3);
  ok = arflex_host_set_param(&teach, "teach", 0, nullptr, kCall) == 0 &&
       arflex_host_set_param(&teach, "save", 1, nullptr, kCall) == 0;
  struct stat st;
  const uint64_t d2 = Now() + 10 * kSec;
  while (ok && stat(path.c_str(), &st) != 0 && Now() < d2) sched_yield();
  arflex::cellkin::Program prog;
  std::string err;
  ok = ok && arflex::cellkin::LoadProgramFile(path, m, &prog, &err);
  if (!ok) RemoveDir(dir);
  CHECK(ok, "saved program %s: %s", path.c_str(), err.c_str());
  printf("teach: %zu waypoints saved\n", prog.motions.size() + 1);
  // Recording faithful: every waypoint lies on the taught path (samples the test saw).
  std::vector<Q> wps{prog.start};
  for (const auto& mo : prog.motions) {
    Q w;
    for (int j = 0; j < 6; ++j) w[j] = mo.v[j];
    wps.push_back(w);
  }
  // (distance to the polyline through the observed references: the test may miss cycles)
  double worst_rec = 0;
  for (const Q& w : wps) {
    double best = 1e9;
    for (size_t i = 0; i < taught.size(); ++i) {
      best = std::min(best, (taught[i] - w).norm());
      if (i == 0) continue;
      const Q ab = taught[i] - taught[i - 1];
      const double l2 = ab.squaredNorm();
      const double t = l2 > 0 ? std::min(1.0, std::max(0.0, (w - taught[i - 1]).dot(ab) / l2)) : 0.0;
      best = std::min(best, (taught[i - 1] + t * ab - w).norm());
    }
    worst_rec = std::max(worst_rec, best);
  }
  // Replay: trajectory with the saved program, no joint_state bound: starts at `start`.
  r = Make(&traj, "trajectory", "trajectory", kMs, envp);
  RemoveDir(dir);
  CHECK(worst_rec < 1e-4, "a waypoint is %.5f rad from the taught path", worst_rec);
  CHECK(r == 0, "trajectory: %d", r);
  CHECK(SetI(&traj, "program", 3) == 0 && arflex_host_start(&traj, kCall) == 0, "start replay");
  Reader rr;
  CHECK(rr.Open(&traj, "joint_ref", &kRefT) == 0, "open replay");
  // Distance of each waypoint from the replayed path: the polyline through the observed
  // references (consecutive reads are a few cycles apart at most; the path is smooth).
  std::vector<double> best(wps.size(), 1e9);
  const uint64_t d3 = Now() + kWait;
  uint64_t still = 0;
  Q last = Q::Constant(1e9);
  bool have_last = false;
  while (Now() < d3) {
    if (rr.Read(&ref, &seq) != 1) {
      sched_yield();
      continue;
    }
    Q qr;
    for (int j = 0; j < 6; ++j) qr[j] = ref.q[j];
    for (size_t i = 0; i < wps.size(); ++i) {
      double d = (qr - wps[i]).norm();
      if (have_last) {
        const Q ab = qr - last;
        const double l2 = ab.squaredNorm();
        const double t = l2 > 0 ? std::min(1.0, std::max(0.0, (wps[i] - last).dot(ab) / l2)) : 0.0;
        d = std::min(d, (last + t * ab - wps[i]).norm());
      }
      best[i] = std::min(best[i], d);
    }
    still = have_last && (qr - last).norm() == 0 ? still + 1 : 0;
    last = qr;
    have_last = true;
    if (best.back() < 1e-9 && still > 100) break;
  }
  double worst = 0;
  for (double b : best) worst = std::max(worst, b);
  const double tcp_err = (m.Tcp(last).translation() - p1).norm();
  printf("replay: %llu cycles; passes within %.2e rad of every waypoint; final TCP %.2e m from "
         "the taught one\n", (unsigned long long)seq, worst, tcp_err);
  // Stated tolerance: every recorded waypoint within 0.2 mrad, the end within 1 um.
  CHECK(worst < 2e-4, "replay missed a waypoint by %g rad", worst);
  CHECK(tcp_err < 1e-6, "replay ends %g m from the taught end", tcp_err);
  CHECK(arflex_host_stop(&traj, kCall) == 0 && arflex_host_stop(&teach, kCall) == 0, "stop");
}

// ---- tools ----------------------------------------------------------------------------------

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

// ---- invalid input values -------------------------------------------------------------------

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

// ---- bad input ------------------------------------------------------------------------------

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

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: %s <trajectory|program_switch|late_robot|invalid_input|bad_program|force_guard|teach_replay|tools> <bin dir> <bundles dir>\n", argv[0]);
    return 2;
  }
  bindir = argv[2];
  bundlesdir = argv[3];
  snprintf(rid, sizeof(rid), "cell-%d", (int)getpid());
  const std::string c = argv[1];
  if (c == "trajectory") CaseTrajectory();
  else if (c == "force_guard") CaseForceGuard();
  else if (c == "teach_replay") CaseTeachReplay();
  else if (c == "tools") CaseTools();
  else if (c == "bad_program") CaseBadProgram();
  else if (c == "program_switch") CaseProgramSwitch();
  else if (c == "state_transfer") CaseStateTransfer();
  else if (c == "late_robot") CaseLateRobot();
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
