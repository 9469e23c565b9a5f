// tcpcorr_comp_rig.cc - the harness of tcpcorr_comp_test (tcpcorr_comp_rig.h).
#include "tcpcorr_comp_rig.h"

extern "C" {
#include "helper.h" /* rt-core test kit: leak checks */
}

namespace tcpcorr_comp {

arflex_ctl_config Config() {
  arflex_ctl_config c;
  std::memset(&c, 0, sizeof(c));
  c.period_ns = 1 * kMs;
  c.priority = 0;
  c.safe_mode = ARFLEX_SAFE_HOLD;
  c.cfg_flags = ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
  return c;
}

bool Leaked() {
  bool any = th_leftovers(rid) > 0;
  if (!th_no_children()) {
    std::fprintf(stderr, "leak: a child process is left\n");
    any = true;
  }
  return any;
}

int Rig::Create(const char* exe) {
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
                                           ARFLEX_HOST_TYPE(TCP_CORRECTION_STATE),
                                           ARFLEX_HOST_TYPE(TCP_CORRECTION_STATE2)};
  char err[512];
  r = arflex_host_load_contract(&c, contract_xml, types, 6, err, sizeof(err));
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

Rig::~Rig() {
  if (out_open) arflex_port_close(&out);
  if (err_open) arflex_port_close(&err_out);
  if (size_open) arflex_port_close(&size_out);
  arflex_host_destroy(&corr);
  arflex_host_destroy(&feeder);
  if (feeder2_made) arflex_host_destroy(&feeder2);
}

int Rig::Second(arflex_host* h, const char* inst, const char* exe, arflex_port* o, const arflex_port_type* state) {
  arflex_host_opts opts;
  arflex_host_contract_opts(&c, rid, inst, &opts);
  if (state) opts.state = state;
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

int Rig::MakeFeeder2(double dq0) {
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
  const int r = arflex_host_create(&feeder2, &o);
  if (r < 0) return r;
  feeder2_made = true;
  arflex_joint_ref ref2;
  std::memset(&ref2, 0, sizeof(ref2));
  ref2.t_ns = 1;
  ref2.seq = 1;
  for (int i = 0; i < 6; ++i) ref2.q[i] = kRef[i] + (i == 0 ? dq0 : 0.0);
  arflex_state_write(arflex_host_output(&feeder2, "reference"), &ref2, sizeof(ref2));
  return 0;
}

bool Rig::Read() {
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

arflex_pose Rig::Pose(const Eigen::Vector3d& extra) {
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
  return p;
}

void Rig::Measure(bool valid, const Eigen::Vector3d& extra) {
  arflex_pose p = Pose(extra);
  for (int i = 0; i < 3; ++i) p.cov[i] = meas_var;
  p.valid = valid ? 1 : 0;
  p.n_views = valid ? 4 : 0;
  arflex_state_write(arflex_host_output(&feeder, "tcp_pose"), &p, sizeof(p));
}

void Rig::MeasureMalformed(int how, const Eigen::Vector3d& extra) {
  arflex_pose p = Pose(extra);
  p.valid = 1;
  p.n_views = 4;
  if (how == 1) p.p[1] = std::nan("");
  if (how == 2) p.quat[0] *= 1.5;
  if (how == 3) p.cov[2] = -1e-9;
  if (how == 4) p.valid = 2;
  if (how == 5) p.quat[3] = HUGE_VAL;
  arflex_state_write(arflex_host_output(&feeder, "tcp_pose"), &p, sizeof(p));
}

bool Rig::Settle(int n) {
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

uint64_t Rig::Errors() {
  arflex_stats st;
  return arflex_ctl_stats_read(corr.ctl, &st) == 0 ? st.update_errors : 0;
}

bool Rig::WaitErrors(uint64_t above) {
  const uint64_t deadline = arflex_sys_now_ns() + 20 * kSec;
  while (Errors() <= above && arflex_sys_now_ns() < deadline) Read();
  return Errors() > above;
}

double Rig::Converge(double tol) {
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

void Rig::Watch(uint64_t ns, bool measure, bool valid, const Eigen::Vector3d& extra) {
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

}  // namespace tcpcorr_comp
