// cell_rig.cc - the harness of test_cell (cell_rig.h).
#include "cell_rig.h"

#include "helper.h" /* rt-core test kit: leak checks */

namespace celltest {

struct arflex_ctl_config Config(uint64_t period) {
  struct arflex_ctl_config c;
  memset(&c, 0, sizeof(c));
  c.period_ns = period;
  c.cfg_flags = ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
  return c;
}

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

// Creates instance `inst` of the component `comp` from its bundle's contract, with the
// harness's period and flags and the defaults `defs` (double parameters, within the
// contract's bounds); spawns the contract's executable from bindir and waits for READY.
int Make(struct arflex_host* h, const char* inst, const char* comp, uint64_t period,
         char* const* envp, const std::vector<Default>& defs) {
  static const struct arflex_host_type types[] = {
      ARFLEX_HOST_TYPE(JOINT_REF),    ARFLEX_HOST_TYPE(JOINT_STATE), ARFLEX_HOST_TYPE(WRENCH),
      ARFLEX_HOST_TYPE(SAFETY_STATE), ARFLEX_HOST_TYPE(TOOL_STATE),  ARFLEX_HOST_TYPE(SAMPLE),
      ARFLEX_HOST_TYPE(TRAJECTORY_STATE), ARFLEX_HOST_TYPE(TCP_CORRECTION_STATE),
      ARFLEX_HOST_TYPE(TCP_CORRECTION_STATE2), ARFLEX_HOST_TYPE(FORCE_GUARD_STATE),
      ARFLEX_HOST_TYPE(TEACH_STATE)};
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

uint64_t Now() { return arflex_sys_now_ns(); }

void WriteJointState(struct arflex_port* out, const Q& q, uint64_t* seq) {
  struct arflex_joint_state js;
  memset(&js, 0, sizeof(js));
  js.t_ns = (int64_t)Now();
  js.seq = ++*seq;
  for (int j = 0; j < 6; ++j) js.q[j] = q[j];
  arflex_state_write(out, &js, sizeof(js));
}

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

}  // namespace celltest
