// tcpcorr.comp.*: the tcp-correction RT half under the rt-core host API. The test plays the
// rest of the cell: a "feeder" instance whose reference and tcp_pose segments it writes, and
// the plant: the measured TCP is the nominal TCP of the corrected output, shifted by a fixed
// error (what the true arm does differently from the nominal model).
//
//   tcpcorr_comp_test <case> <tcp-correction exe> <contract>   cases: converge, hold, invalid, switch
//
// The corrector's ports, parameters (max_rate, max_sigma, track_tol, orientation, ... with
// their defaults), period and safe mode come from the bundle's contract
// (arflex_host_load_contract, docs/DECISIONS.md D32/D34); the rate-limit check uses the
// contract's max_rate. The harness's own choices: SCHED_OTHER, no mlock or cpu_dma_latency, no
// heartbeat watchdog. The feeder plays the motion source, vision and the robot: it is the
// test's own provider, not a component, and its segments are declared here.
// Every case ends by checking that no /dev/shm or /dev/mqueue object of its runtime id and no
// child process is left. Waits are on conditions with deadlines; nothing asserts on timing.
#include <dirent.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

extern "C" {
#include "arflex/host.h"
#include "arflex/host_contract.h"
#include "helper.h" /* rt-core test kit: leak checks */
}
#include "arflex_cellmodel/kinematics.h"
#include "arflex_types/joint_ref.h"
#include "arflex_types/joint_state.h"
#include "arflex_types/pose.h"
#include "arflex_types/sample.h"
#include "arflex_types/tcp_correction_state.h"

namespace {

constexpr uint64_t kSec = 1000000000ull;
constexpr uint64_t kMs = 1000000ull;
double max_rate;            // rad/s: the contract's default of max_rate
double period_s;            // s: the contract's period
const char* contract_xml;

char rid[ARFLEX_ID_MAX + 1];
int failures = 0;

#define CHECK(cond, ...)                                                   \
  do {                                                                     \
    if (!(cond)) {                                                         \
      std::fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond); \
      std::fprintf(stderr, __VA_ARGS__);                                   \
      std::fputc('\n', stderr);                                            \
      ++failures;                                                          \
      goto out;                                                            \
    }                                                                      \
  } while (0)

arflex_ctl_config Config() {
  arflex_ctl_config c;
  std::memset(&c, 0, sizeof(c));
  c.period_ns = 1 * kMs;
  c.priority = 0;
  c.safe_mode = ARFLEX_SAFE_HOLD;
  c.cfg_flags = ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
  return c;
}

// rt-core's test kit (arflex_testkit): /dev/shm and /dev/mqueue objects of rid, children.
bool Leaked() {
  bool any = th_leftovers(rid) > 0;
  if (!th_no_children()) {
    std::fprintf(stderr, "leak: a child process is left\n");
    any = true;
  }
  return any;
}

const arflex::cellmodel::JointVector kRef = {0.2, 0.5, 0.3, 0.1, 0.8, -0.2};
const Eigen::Vector3d kPlantError(1.2e-3, -0.8e-3, 0.6e-3);  // true arm vs nominal, at the TCP

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

  int Create(const char* exe) {
    struct arflex_host_output fo[3];
    std::memset(fo, 0, sizeof(fo));
    fo[0].port = "reference";
    fo[0].spec.method = ARFLEX_PORT_STATE;
    fo[0].spec.type = {ARFLEX_TYPE_JOINT_REF_NAME, 1, 0, ARFLEX_TYPE_JOINT_REF_SIZE};
    fo[0].spec.depth = 1;
    fo[1].port = "tcp_pose";
    fo[1].spec.method = ARFLEX_PORT_STATE;
    fo[1].spec.type = {ARFLEX_TYPE_POSE_NAME, 1, 0, ARFLEX_TYPE_POSE_SIZE};
    fo[1].spec.depth = 1;
    fo[2].port = "joint_state";
    fo[2].spec.method = ARFLEX_PORT_STATE;
    fo[2].spec.type = {ARFLEX_TYPE_JOINT_STATE_NAME, 1, 0, ARFLEX_TYPE_JOINT_STATE_SIZE};
    fo[2].spec.depth = 1;
    arflex_host_opts o;
    std::memset(&o, 0, sizeof(o));
    o.runtime = rid;
    o.instance = "feeder";
    o.config = Config();
    o.outputs = fo;
    o.noutputs = 3;
    int r = arflex_host_create(&feeder, &o);
    if (r < 0) return r;
    static const arflex_host_type types[] = {ARFLEX_HOST_TYPE(JOINT_REF), ARFLEX_HOST_TYPE(JOINT_STATE),
                                             ARFLEX_HOST_TYPE(POSE), ARFLEX_HOST_TYPE(SAMPLE),
                                             ARFLEX_HOST_TYPE(TCP_CORRECTION_STATE)};
    char err[512];
    r = arflex_host_load_contract(&c, contract_xml, types, 5, err, sizeof(err));
    if (r < 0) {
      std::fprintf(stderr, "%s\n", err);
      return r;
    }
    max_rate = -1;
    for (unsigned i = 0; i < c.nparams; ++i)
      if (std::strcmp(c.params[i].name, "max_rate") == 0) max_rate = arflex_bits_f64(c.params[i].default_bits);
    if (max_rate <= 0) {
      std::fprintf(stderr, "%s: no max_rate\n", contract_xml);
      return -EINVAL;
    }
    arflex_host_contract_opts(&c, rid, "corr", &o);
    period_s = 1e-9 * static_cast<double>(o.config.period_ns);
    o.config.priority = 0;
    o.config.hb_timeout_ns = 0;
    o.config.cfg_flags |= ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
    r = arflex_host_create(&corr, &o);
    if (r < 0) return r;
    r = arflex_host_spawn(&corr, exe, nullptr, nullptr);
    if (r < 0) return r;
    r = arflex_host_wait_state(&corr, ARFLEX_STATE_READY, 10 * kSec);
    if (r < 0) return r;
    const arflex_port_type t = {ARFLEX_TYPE_JOINT_REF_NAME, 1, 0, ARFLEX_TYPE_JOINT_REF_SIZE};
    r = arflex_port_open(&out, arflex_host_output_name(&corr, "corrected"), false, false, ARFLEX_PORT_STATE, &t);
    if (r < 0) return r;
    out_open = true;
    const arflex_port_type st = {ARFLEX_TYPE_SAMPLE_NAME, 1, 0, ARFLEX_TYPE_SAMPLE_SIZE};
    r = arflex_port_open(&err_out, arflex_host_output_name(&corr, "error"), false, false, ARFLEX_PORT_STATE, &st);
    if (r < 0) return r;
    err_open = true;
    r = arflex_port_open(&size_out, arflex_host_output_name(&corr, "correction"), false, false, ARFLEX_PORT_STATE, &st);
    if (r < 0) return r;
    size_open = true;
    arflex_joint_ref ref;
    std::memset(&ref, 0, sizeof(ref));
    ref.t_ns = 1;
    ref.seq = 1;
    for (int i = 0; i < 6; ++i) ref.q[i] = kRef[i];
    arflex_state_write(arflex_host_output(&feeder, "reference"), &ref, sizeof(ref));
    r = arflex_host_bind(&corr, "reference", arflex_host_output_name(&feeder, "reference"), 2 * kSec);
    if (r == 0) r = arflex_host_bind(&corr, "tcp_pose", arflex_host_output_name(&feeder, "tcp_pose"), 2 * kSec);
    if (r == 0) r = arflex_host_start(&corr, 2 * kSec);
    return r;
  }

  ~Rig() {
    if (out_open) arflex_port_close(&out);
    if (err_open) arflex_port_close(&err_out);
    if (size_open) arflex_port_close(&size_out);
    arflex_host_destroy(&corr);
    arflex_host_destroy(&feeder);
    if (feeder2_made) arflex_host_destroy(&feeder2);
  }

  // Another half of tcp-correction (`inst`) bound to the feeder's reference and tcp_pose, with
  // its corrected output open in `o`: READY, not started.
  int Second(arflex_host* h, const char* inst, const char* exe, arflex_port* o) {
    arflex_host_opts opts;
    arflex_host_contract_opts(&c, rid, inst, &opts);
    opts.config.priority = 0;
    opts.config.hb_timeout_ns = 0;
    opts.config.cfg_flags |= ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
    int r = arflex_host_create(h, &opts);
    if (r == 0) r = arflex_host_spawn(h, exe, nullptr, nullptr);
    if (r == 0) r = arflex_host_wait_state(h, ARFLEX_STATE_READY, 10 * kSec);
    const arflex_port_type t = {ARFLEX_TYPE_JOINT_REF_NAME, 1, 0, ARFLEX_TYPE_JOINT_REF_SIZE};
    if (r == 0) r = arflex_port_open(o, arflex_host_output_name(h, "corrected"), false, false, ARFLEX_PORT_STATE, &t);
    if (r == 0) r = arflex_host_bind(h, "reference", arflex_host_output_name(&feeder, "reference"), 2 * kSec);
    if (r == 0) r = arflex_host_bind(h, "tcp_pose", arflex_host_output_name(&feeder, "tcp_pose"), 2 * kSec);
    return r;
  }

  // Reads the newest output; checks that it never jumps. Returns true on a new value.
  bool Read() {
    arflex_joint_ref v;
    arflex_sample e;
    if (arflex_state_read(&err_out, &e, sizeof(e), nullptr) == 1) {
      if (first_error_mm < 0) first_error_mm = e.value;
      last_error_mm = e.value;
    }
    if (arflex_state_read(&size_out, &e, sizeof(e), nullptr) == 1) last_size_mrad = e.value;
    if (arflex_state_read(&out, &v, sizeof(v), nullptr) != 1) return false;
    if (last.seq != 0) {
      const double cycles = static_cast<double>(v.seq - last.seq);
      for (int i = 0; i < 6; ++i) {
        const double excess = std::abs(v.q[i] - last.q[i]) - max_rate * period_s * cycles;
        if (excess > max_jump_excess) max_jump_excess = excess;
      }
    }
    last = v;
    return true;
  }

  // The plant: the measurement of the corrected output (nominal TCP + the plant's error).
  void Measure(bool valid, const Eigen::Vector3d& extra) {
    arflex::cellmodel::JointVector q;
    for (int i = 0; i < 6; ++i) q[i] = last.q[i];
    const Eigen::Isometry3d t = kin.Tcp(q);
    arflex_pose p;
    std::memset(&p, 0, sizeof(p));
    p.seq = ++pose_seq;
    const Eigen::Vector3d pos = t.translation() + kPlantError + extra;
    const Eigen::Quaterniond quat(t.linear());
    for (int i = 0; i < 3; ++i) p.p[i] = pos(i);
    p.quat[0] = quat.w();
    p.quat[1] = quat.x();
    p.quat[2] = quat.y();
    p.quat[3] = quat.z();
    for (int i = 0; i < 3; ++i) p.cov[i] = meas_var;
    p.valid = valid ? 1 : 0;
    p.n_views = valid ? 4 : 0;
    arflex_state_write(arflex_host_output(&feeder, "tcp_pose"), &p, sizeof(p));
  }

  // Writes a measurement of the last output (as Measure) made malformed: 1 position NaN,
  // 2 quaternion not unit, 3 a negative variance, 4 validity flag 2, 5 orientation Inf.
  void MeasureMalformed(int how, const Eigen::Vector3d& extra) {
    arflex::cellmodel::JointVector q;
    for (int i = 0; i < 6; ++i) q[i] = last.q[i];
    const Eigen::Isometry3d t = kin.Tcp(q);
    arflex_pose p;
    std::memset(&p, 0, sizeof(p));
    p.seq = ++pose_seq;
    const Eigen::Vector3d pos = t.translation() + kPlantError + extra;
    const Eigen::Quaterniond quat(t.linear());
    for (int i = 0; i < 3; ++i) p.p[i] = pos(i);
    p.quat[0] = quat.w();
    p.quat[1] = quat.x();
    p.quat[2] = quat.y();
    p.quat[3] = quat.z();
    p.valid = 1;
    p.n_views = 4;
    if (how == 1) p.p[1] = std::nan("");
    if (how == 2) p.quat[0] *= 1.5;
    if (how == 3) p.cov[2] = -1e-9;
    if (how == 4) p.valid = 2;
    if (how == 5) p.quat[3] = HUGE_VAL;
    arflex_state_write(arflex_host_output(&feeder, "tcp_pose"), &p, sizeof(p));
  }

  // Reads until `n` new outputs in a row equal the one before them: the correction has come
  // to rest (it slews at max_rate towards its target). False when it has not within 20 s.
  bool Settle(int n) {
    const uint64_t deadline = arflex_sys_now_ns() + 20 * kSec;
    Read();
    arflex_joint_ref prev = last;
    int same = 0;
    while (same < n && arflex_sys_now_ns() < deadline) {
      if (!Read() || last.seq == prev.seq) continue;
      bool equal = true;
      for (int i = 0; i < 6; ++i) equal = equal && last.q[i] == prev.q[i];
      same = equal ? same + 1 : 0;
      prev = last;
    }
    return same >= n;
  }

  uint64_t Errors() {
    arflex_stats st;
    return arflex_ctl_stats_read(corr.ctl, &st) == 0 ? st.update_errors : 0;
  }
  bool WaitErrors(uint64_t above) {
    const uint64_t deadline = arflex_sys_now_ns() + 20 * kSec;
    while (Errors() <= above && arflex_sys_now_ns() < deadline) Read();
    return Errors() > above;
  }

  // Runs the loop (a measurement every 20 ms of wall time) until the true TCP error is
  // below `tol` or the deadline passes. Returns the final error (m).
  double Converge(double tol) {
    const uint64_t deadline = arflex_sys_now_ns() + 30 * kSec;
    uint64_t last_measure = 0;
    double err = 1.0;
    while (arflex_sys_now_ns() < deadline) {
      if (!Read()) continue;
      arflex::cellmodel::JointVector q;
      for (int i = 0; i < 6; ++i) q[i] = last.q[i];
      err = (kin.Tcp(q).translation() + kPlantError - kin.Tcp(kRef).translation()).norm();
      if (err < tol) break;
      if (arflex_sys_now_ns() - last_measure > 20 * kMs) {
        Measure(true, Eigen::Vector3d::Zero());
        last_measure = arflex_sys_now_ns();
      }
    }
    return err;
  }

  // Reads outputs for `ns` of wall time (to watch a hold or a ramp), measuring with `valid`.
  void Watch(uint64_t ns, bool measure, bool valid, const Eigen::Vector3d& extra) {
    const uint64_t end = arflex_sys_now_ns() + ns;
    uint64_t last_measure = 0;
    while (arflex_sys_now_ns() < end) {
      Read();
      if (measure && arflex_sys_now_ns() - last_measure > 20 * kMs) {
        Measure(valid, extra);
        last_measure = arflex_sys_now_ns();
      }
    }
  }
};

int RunCase(const std::string& name, const char* exe) {
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
  if (name == "invalid") {
    // Validated data (docs/safety.md, README "Invalid input"): values that fail their checks
    // are not used and are counted (update_errors); the output stays where the valid ones put it.
    rig.Watch(200 * kMs, false, true, Eigen::Vector3d::Zero());  // let the ramp finish
    const arflex_joint_ref before = rig.last;
    const Eigen::Vector3d far(0.01, 0, 0);  // 10 mm: a valid measurement this far moves the output
    // 1. tcp_pose: malformed measurements claiming validity, 10 mm off: held, each kind counted.
    for (int how = 1; how <= 5; ++how) {
      const uint64_t e0 = rig.Errors();
      rig.MeasureMalformed(how, far);
      CHECK(rig.WaitErrors(e0), "malformed measurement %d was not counted", how);
      const uint64_t end = arflex_sys_now_ns() + 100 * kMs;
      uint64_t last_measure = 0;
      while (arflex_sys_now_ns() < end) {
        rig.Read();
        if (arflex_sys_now_ns() - last_measure > 20 * kMs) {
          rig.MeasureMalformed(how, far);
          last_measure = arflex_sys_now_ns();
        }
      }
      for (int i = 0; i < 6; ++i)
        CHECK(rig.last.q[i] == before.q[i], "joint %d moved on malformed measurement %d", i, how);
    }
    // 2. reference: NaN on one joint. The output holds its last value (no NaN passed on, the
    //    correction frozen even under valid measurements 10 mm off), counted; the hold word
    //    names the reference input as invalid.
    {
      arflex_joint_ref bad;
      std::memset(&bad, 0, sizeof(bad));
      bad.t_ns = 2;
      bad.seq = 2;
      for (int i = 0; i < 6; ++i) bad.q[i] = kRef[i];
      bad.q[2] = std::nan("");
      const uint64_t e0 = rig.Errors();
      arflex_state_write(arflex_host_output(&rig.feeder, "reference"), &bad, sizeof(bad));
      CHECK(rig.WaitErrors(e0), "the NaN reference was not counted");
      const uint32_t hold = arflex_ctl_hold(rig.corr.ctl);
      CHECK((hold & 0xffu) == ARFLEX_HOLD_REFERENCE && ((hold >> 8) & 0xffu) == ARFLEX_HOLD_REF_INVALID &&
                ((hold >> 16) & 0xffu) == 0u,
            "hold word 0x%x", hold);
      const uint64_t seq0 = rig.last.seq;
      rig.Watch(300 * kMs, true, true, far);
      CHECK(rig.last.seq > seq0 + 50, "the output is not written while the reference is invalid");
      for (int i = 0; i < 6; ++i)
        CHECK(rig.last.q[i] == before.q[i], "joint %d moved from %.12f to %.12f on an invalid reference", i,
              before.q[i], rig.last.q[i]);
      // Inf too.
      bad.seq = 3;
      bad.q[2] = kRef[2];
      bad.q[5] = -HUGE_VAL;
      const uint64_t e1 = rig.Errors();
      arflex_state_write(arflex_host_output(&rig.feeder, "reference"), &bad, sizeof(bad));
      CHECK(rig.WaitErrors(e1), "the Inf reference was not counted");
      rig.Watch(100 * kMs, false, true, far);
      for (int i = 0; i < 6; ++i) CHECK(rig.last.q[i] == before.q[i], "joint %d moved on an Inf reference", i);
      // A valid reference again: the hold clears and the output follows it (+ the correction).
      arflex_joint_ref good = bad;
      good.seq = 4;
      for (int i = 0; i < 6; ++i) good.q[i] = kRef[i] + (i == 0 ? 1e-3 : 0.0);
      const double excess = rig.max_jump_excess;  // the reference's own 1 mrad step is passed on as is
      arflex_state_write(arflex_host_output(&rig.feeder, "reference"), &good, sizeof(good));
      const uint64_t deadline = arflex_sys_now_ns() + 20 * kSec;
      bool moved = false;
      while (!moved && arflex_sys_now_ns() < deadline) {
        if (rig.Read()) moved = std::abs(rig.last.q[0] - before.q[0] - 1e-3) < 1e-4;
      }
      rig.max_jump_excess = excess;
      CHECK(moved, "a valid reference after invalid ones was not followed");
      CHECK((arflex_ctl_hold(rig.corr.ctl) & 0xffu) == ARFLEX_HOLD_NONE, "hold word 0x%x after a valid reference",
            arflex_ctl_hold(rig.corr.ctl));
    }
    // 3. joint_state: bound, the robot where the output is, but its values NaN: the robot's
    //    position is unknown, valid measurements 10 mm off are held (counted); a valid joint
    //    state at the output lets them in again and the output moves.
    {
      rig.Watch(200 * kMs, false, true, Eigen::Vector3d::Zero());
      // the correction may still be slewing towards what case 2 measured: at rest first
      CHECK(rig.Settle(50), "the output did not come to rest");
      const arflex_joint_ref held = rig.last;
      arflex_joint_state js;
      std::memset(&js, 0, sizeof(js));
      js.seq = 1;
      for (int i = 0; i < 6; ++i) js.q[i] = held.q[i];
      js.tau[1] = std::nan("");
      arflex_state_write(arflex_host_output(&rig.feeder, "joint_state"), &js, sizeof(js));
      const uint64_t e0 = rig.Errors();
      CHECK(arflex_host_bind(&rig.corr, "joint_state", arflex_host_output_name(&rig.feeder, "joint_state"), 2 * kSec) == 0,
            "BIND joint_state");
      CHECK(rig.WaitErrors(e0), "the NaN joint state was not counted");
      rig.Watch(300 * kMs, true, true, far);
      for (int i = 0; i < 6; ++i)
        CHECK(rig.last.q[i] == held.q[i], "joint %d moved while the robot's joint state was invalid", i);
      js.seq = 2;
      js.tau[1] = 0;
      arflex_state_write(arflex_host_output(&rig.feeder, "joint_state"), &js, sizeof(js));
      const uint64_t deadline = arflex_sys_now_ns() + 20 * kSec;
      uint64_t last_measure = 0;
      bool moved = false;
      while (!moved && arflex_sys_now_ns() < deadline) {
        if (rig.Read()) moved = rig.last.q[0] != held.q[0] || rig.last.q[1] != held.q[1];
        if (arflex_sys_now_ns() - last_measure > 20 * kMs) {
          rig.Measure(true, far);
          last_measure = arflex_sys_now_ns();
        }
      }
      CHECK(moved, "measurements were still held after a valid joint state");
    }
    printf("invalid: %llu invalid values counted as update errors\n", (unsigned long long)rig.Errors());
  }
  if (name == "switch") {
    // Bumpless transfer (D35): the reference input moves to another provider whose value is
    // 10 mrad away on joint 0: the output takes the new value over 0.5 s, never by a step; a
    // provider 200 mrad away is passed on at once (not faded: the robot's acquisition judges).
    rig.Watch(200 * kMs, false, true, Eigen::Vector3d::Zero());  // the correction's ramp done
    const arflex_joint_ref before = rig.last;
    const double excess = rig.max_jump_excess;
    struct arflex_host_output fo;
    std::memset(&fo, 0, sizeof(fo));
    fo.port = "reference";
    fo.spec.method = ARFLEX_PORT_STATE;
    fo.spec.type = {ARFLEX_TYPE_JOINT_REF_NAME, 1, 0, ARFLEX_TYPE_JOINT_REF_SIZE};
    fo.spec.depth = 1;
    arflex_host_opts o;
    std::memset(&o, 0, sizeof(o));
    o.runtime = rid;
    o.instance = "feeder2";
    o.config = Config();
    o.outputs = &fo;
    o.noutputs = 1;
    CHECK(arflex_host_create(&rig.feeder2, &o) == 0, "feeder2");
    rig.feeder2_made = true;
    arflex_joint_ref ref2;
    std::memset(&ref2, 0, sizeof(ref2));
    ref2.t_ns = 1;
    ref2.seq = 1;
    for (int i = 0; i < 6; ++i) ref2.q[i] = kRef[i] + (i == 0 ? 0.01 : 0.0);
    arflex_state_write(arflex_host_output(&rig.feeder2, "reference"), &ref2, sizeof(ref2));
    CHECK(arflex_host_bind(&rig.corr, "reference", arflex_host_output_name(&rig.feeder2, "reference"), 2 * kSec) == 0,
          "BIND reference to feeder2");
    double worst = 0;  // the largest output step per cycle, any joint
    {
      arflex_joint_ref prev = rig.last;
      const uint64_t end = arflex_sys_now_ns() + 800 * kMs;
      while (arflex_sys_now_ns() < end) {
        if (!rig.Read()) continue;
        const double cycles = static_cast<double>(rig.last.seq - prev.seq);
        for (int i = 0; i < 6; ++i) worst = std::max(worst, std::abs(rig.last.q[i] - prev.q[i]) / cycles);
        prev = rig.last;
      }
    }
    printf("switch: 10 mrad provider change, largest output step %.4f mrad per cycle\n", 1e3 * worst);
    // the quintic's peak speed is 1.875 * 10 mrad / 0.5 s = 0.0375 mrad per 1 ms cycle
    CHECK(worst < 0.05e-3, "a step of %.4f mrad per cycle after the provider change", 1e3 * worst);
    CHECK(std::abs(rig.last.q[0] - before.q[0] - 0.01) < 1e-9, "joint 0 at %.9f, expected %.9f after the blend",
          rig.last.q[0], before.q[0] + 0.01);
    for (int i = 1; i < 6; ++i) CHECK(rig.last.q[i] == before.q[i], "joint %d moved", i);
    // 200 mrad away: passed on at once
    arflex_joint_ref far = ref2;
    far.seq = 7;
    far.q[0] = kRef[0] + 0.2;
    arflex_state_write(arflex_host_output(&rig.feeder, "reference"), &far, sizeof(far));
    CHECK(arflex_host_bind(&rig.corr, "reference", arflex_host_output_name(&rig.feeder, "reference"), 2 * kSec) == 0,
          "BIND reference back to feeder");
    {
      const uint64_t deadline = arflex_sys_now_ns() + 20 * kSec;
      bool there = false;
      while (!there && arflex_sys_now_ns() < deadline) {
        if (rig.Read()) there = std::abs(rig.last.q[0] - before.q[0] - 0.2) < 1e-9;
      }
      CHECK(there, "a provider 200 mrad away was not passed on (joint 0 at %.6f)", rig.last.q[0]);
    }
    rig.max_jump_excess = excess;  // the steps above are the references' own
  }
  if (name == "adopt") {
    // State transfer (D41): a second half told this one's state segment takes the correction
    // over at its START: its first output is the old half's output, correction included (a
    // fresh half starts without the correction: its output is the bare reference).
    CHECK(arflex_host_state(&rig.corr) != nullptr, "the contract's state block has a segment");
    CHECK(rig.Settle(50), "the correction did not come to rest");
    const arflex_joint_ref old_out = rig.last;
    static arflex_host next, fresh;
    arflex_port nout{}, fout{};
    int r = rig.Second(&next, "1-corr", exe, &nout);
    if (r == 0) r = rig.Second(&fresh, "2-corr", exe, &fout);
    bool ok = r == 0;
    if (ok) ok = arflex_host_adopt(&next, arflex_host_state(&rig.corr)->name, 2 * kSec) == 0;
    if (ok) ok = arflex_host_start(&next, 2 * kSec) == 0 && arflex_host_start(&fresh, 2 * kSec) == 0;
    arflex_joint_ref nv{}, fv{};
    const uint64_t deadline = arflex_sys_now_ns() + 10 * kSec;
    bool got_n = false, got_f = false;
    while (ok && !(got_n && got_f) && arflex_sys_now_ns() < deadline) {
      got_n = got_n || arflex_state_read(&nout, &nv, sizeof(nv), nullptr) == 1;
      got_f = got_f || arflex_state_read(&fout, &fv, sizeof(fv), nullptr) == 1;
    }
    double d_adopted = 0, d_fresh = 0, d_ref = 0;
    for (int i = 0; i < 6; ++i) {
      d_adopted = std::max(d_adopted, std::abs(nv.q[i] - old_out.q[i]));
      d_fresh = std::max(d_fresh, std::abs(fv.q[i] - old_out.q[i]));
      d_ref = std::max(d_ref, std::abs(fv.q[i] - kRef[i]));
    }
    printf("adopt: the adopting half's first output %.3g mrad from the old half's (seq %llu after %llu); a fresh "
           "half's %.4f mrad (its output is the bare reference: %.3g mrad from it)\n", 1e3 * d_adopted,
           (unsigned long long)nv.seq, (unsigned long long)old_out.seq, 1e3 * d_fresh, 1e3 * d_ref);
    arflex_port_close(&nout);
    arflex_port_close(&fout);
    arflex_host_shutdown(&next, 5 * kSec);
    arflex_host_shutdown(&fresh, 5 * kSec);
    arflex_host_wait_exit(&next, 10 * kSec);
    arflex_host_wait_exit(&fresh, 10 * kSec);
    arflex_host_destroy(&next);
    arflex_host_destroy(&fresh);
    CHECK(ok && got_n && got_f, "second halves: r %d, outputs %d %d", r, got_n, got_f);
    CHECK(d_adopted < 1e-12, "the adopting half's output is %.3g rad from the old half's", d_adopted);
    CHECK(nv.seq > old_out.seq, "its seq continues the old half's (%llu, %llu)", (unsigned long long)nv.seq,
          (unsigned long long)old_out.seq);
    CHECK(d_fresh > 1e-5, "a fresh half's output only %.3g rad away: nothing to transfer", d_fresh);
  }
  if (name == "hold") {
    // Vision drops out: invalid measurements far off are held, the output does not move.
    const arflex_joint_ref before = rig.last;
    rig.Watch(300 * kMs, true, false, Eigen::Vector3d(0.01, 0, 0));
    for (int i = 0; i < 6; ++i) {
      CHECK(rig.last.q[i] == before.q[i], "joint %d moved from %.12f to %.12f while vision was out", i,
            before.q[i], rig.last.q[i]);
    }
    // Valid but uncertain measurements (1 mm standard deviation > max_sigma 0.2 mm) are held too.
    rig.meas_var = 1e-6;
    rig.Watch(300 * kMs, true, true, Eigen::Vector3d(0.01, 0, 0));
    rig.meas_var = 0;
    for (int i = 0; i < 6; ++i) {
      CHECK(rig.last.q[i] == before.q[i], "joint %d moved from %.12f to %.12f on uncertain measurements", i,
            before.q[i], rig.last.q[i]);
    }
    // Tracking interlock: the robot's joints bound and 10 mrad away from the output (a robot
    // holding in safe mode): valid, certain measurements 10 mm off are held too.
    {
      arflex_joint_state js;
      std::memset(&js, 0, sizeof(js));
      js.seq = 1;
      for (int i = 0; i < 6; ++i) js.q[i] = before.q[i] + 0.01;
      arflex_state_write(arflex_host_output(&rig.feeder, "joint_state"), &js, sizeof(js));
      CHECK(arflex_host_bind(&rig.corr, "joint_state", arflex_host_output_name(&rig.feeder, "joint_state"), 2 * kSec) == 0,
            "BIND joint_state");
      rig.Watch(300 * kMs, true, true, Eigen::Vector3d(0.01, 0, 0));
      for (int i = 0; i < 6; ++i) {
        CHECK(rig.last.q[i] == before.q[i], "joint %d moved from %.12f to %.12f while the robot did not follow", i,
              before.q[i], rig.last.q[i]);
      }
    }
    // Disabled: the correction ramps out at max_rate, to exactly the reference.
    CHECK(arflex_host_set_param(&rig.corr, "enable", 0, nullptr, 2 * kSec) == 0, "SET_PARAM enable");
    {
      const uint64_t deadline = arflex_sys_now_ns() + 20 * kSec;
      bool at_ref = false;
      while (!at_ref && arflex_sys_now_ns() < deadline) {
        if (!rig.Read()) continue;
        at_ref = true;
        for (int i = 0; i < 6; ++i) at_ref = at_ref && rig.last.q[i] == kRef[i];
      }
      CHECK(at_ref, "the output did not return to the reference");
    }
  }
  CHECK(rig.max_jump_excess < 1e-12, "output jumped %.3g rad beyond the rate limit", rig.max_jump_excess);
  CHECK(arflex_host_shutdown(&rig.corr, 5 * kSec) == 0, "SHUTDOWN");
  CHECK(arflex_host_wait_exit(&rig.corr, 10 * kSec) == 0, "exit");
out:
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: tcpcorr_comp_test <converge|hold|invalid|switch|adopt> <tcp-correction exe> <contract>\n");
    return 2;
  }
  contract_xml = argv[3];
  std::snprintf(rid, sizeof(rid), "tcc%d", static_cast<int>(getpid()));
  const std::string name = argv[1];
  if (name != "converge" && name != "hold" && name != "invalid" && name != "switch" && name != "adopt") {
    std::fprintf(stderr, "tcpcorr_comp_test: unknown case '%s'\n", argv[1]);
    return 2;
  }
  RunCase(name, argv[2]);
  if (Leaked()) ++failures;
  std::printf("tcpcorr.comp.%s: %s\n", name.c_str(), failures ? "FAIL" : "ok");
  return failures ? 1 : 0;
}
