// force-guard - RT half of the force-guard component (README.md): watches the joint torques
// and the wrist wrench against the nominal model's inverse dynamics (cellkin::ContactMonitor); above a threshold it puts the cell in a
// protective stop in the same cycle and keeps it there until an operator reset.
//
// Ports: in joint_state (arflex.JointState), in wrench (arflex.Wrench), out safety
// (arflex.SafetyState, written every cycle). An unbound input is simply not checked.
//
// Latch: on a trip the RT half sets ARFLEX_FLAG_RESET_REQUIRED in its own control block with
// arflex_component_require_reset()
// (the RT process is the writer of `flags`, rt-core/docs/ABI.md §3), so rt-core calls the safe
// hook instead of update until the operator's RESET command clears it; the safe hook keeps
// writing PROTECTIVE_STOP. A rising edge 0 -> 1 of the mutable parameter `reset` clears it as
// well. Runtime heartbeat loss (rt-core safe mode) also writes PROTECTIVE_STOP, with the
// HEARTBEAT_LOST reason.
//
// State block (contract <state type="arflex.ForceGuardState">, docs/DECISIONS.md D52): every
// cycle the latch (latched, its reason, the trips), the safety output's seq and the contact
// monitor's filter are published; the next version adopts them at its START in a change set's
// update. A latched stop survives the update: the new half sets RESET_REQUIRED on its own control
// block and writes PROTECTIVE_STOP until the operator's reset. Fail closed: a block it cannot
// read (another type or major version, a value outside its bounds) starts the new half latched
// too (it cannot know whether the old one had stopped the cell), not refused: a refused START is
// restarted without a state, i.e. unlatched.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "arflex/component.h"
#include "arflex_types/force_guard_state.h"
#include "arflex_types/joint_state.h"
#include "arflex_types/safety_state.h"
#include "arflex_types/wrench.h"
#include "cellkin.h"

namespace {

using arflex::cellkin::Q;

struct State {
  arflex::cellkin::Model model;
  arflex::cellkin::ContactMonitor monitor{&model};
  struct arflex_port* out = nullptr;
  struct arflex_input* in_js = nullptr;
  struct arflex_input* in_w = nullptr;
  int p_force, p_torque, p_power, p_reset, p_payload;
  struct arflex_joint_state js{};
  struct arflex_wrench w{};
  bool have_js = false, have_w = false;
  bool latched = false;
  bool reset_prev = false;
  uint32_t reason = 0;
  double force_norm = 0;
  uint64_t seq = 0;
  uint64_t trips = 0;
  struct arflex_force_guard_state state{};  // the state block published every cycle (D52)
} g;

struct arflex_ctl* Ctl(struct arflex_component* c) {
  // Only for the guard's own unlatch (the `reset` parameter edge in Safe): rt-core has a
  // public call to set RESET_REQUIRED (arflex_component_require_reset) but, on purpose, none
  // to clear it; `flags` is RT-written shared memory the component API hands out read-only.
  return const_cast<struct arflex_ctl*>(arflex_component_ctl(c));
}

int Adopt(struct arflex_component* c, void*, const struct arflex_adopted_state* a);

int Configure(struct arflex_component* c, void*) {
  static const struct arflex_port_type js_t = {ARFLEX_TYPE_JOINT_STATE_NAME, 1, 0,
                                               sizeof(struct arflex_joint_state)};
  static const struct arflex_port_type w_t = {ARFLEX_TYPE_WRENCH_NAME, 1, 0,
                                              sizeof(struct arflex_wrench)};
  static const struct arflex_port_type s_t = {ARFLEX_TYPE_SAFETY_STATE_NAME, 1, 0,
                                              sizeof(struct arflex_safety_state)};
  int r = arflex_component_output(c, "safety", ARFLEX_PORT_STATE, &s_t, &g.out);
  if (r < 0) {
    fprintf(stderr, "force-guard: output safety: %s\n", strerror(-r));
    return r;
  }
  if ((r = arflex_component_input(c, "joint_state", ARFLEX_PORT_STATE, &js_t, &g.in_js)) < 0 ||
      (r = arflex_component_input(c, "wrench", ARFLEX_PORT_STATE, &w_t, &g.in_w)) < 0)
    return r;
  // The state block (D52): without a state segment (a contract without <state>) publishing is a no-op.
  static const struct arflex_port_type st_t = {ARFLEX_TYPE_FORCE_GUARD_STATE_NAME,
                                               ARFLEX_TYPE_FORCE_GUARD_STATE_VERSION_MAJOR,
                                               ARFLEX_TYPE_FORCE_GUARD_STATE_VERSION_MINOR,
                                               ARFLEX_TYPE_FORCE_GUARD_STATE_SIZE};
  if ((r = arflex_component_state(c, &st_t, nullptr)) < 0 && r != -ENOENT) return r;
  // D61: Adopt runs between two updates as well (it only adds a latch, never clears one): at the
  // switch of an update whose new half ran in shadow it takes the old half's state again
  if ((r = arflex_component_readopt(c, Adopt)) < 0) return r;
  const char* names[] = {"force_limit_n", "torque_limit_nm", "safe_power_fraction", "reset",
                         "payload_kg"};
  int* idx[] = {&g.p_force, &g.p_torque, &g.p_power, &g.p_reset, &g.p_payload};
  for (int i = 0; i < 5; ++i) {
    *idx[i] = arflex_component_param(c, names[i]);
    if (*idx[i] < 0) {
      fprintf(stderr, "force-guard: parameter '%s' missing from the control block\n", names[i]);
      return -ENOENT;
    }
  }
  return 0;
}

int Start(struct arflex_component* c, void*) {
  g.have_js = g.have_w = false;
  g.monitor.Reset();
  g.reset_prev = arflex_param_bool(c, g.p_reset);
  // A restarted guard that was latched stays latched: rt-core keeps RESET_REQUIRED.
  g.latched = (arflex_component_ctl(c)->flags & ARFLEX_FLAG_RESET_REQUIRED) != 0;
  return 0;
}

// The latch, the output's seq and the monitor's filter (D52), after every safety value.
void PublishState(struct arflex_component* c, uint64_t release_ns) {
  if (!arflex_component_state_open(c)) return;
  struct arflex_force_guard_state& st = g.state;
  st.t_ns = (int64_t)release_ns;
  st.seq++;
  st.out_seq = g.seq;
  st.trips = g.trips;
  const arflex::cellkin::ContactMonitor::Snapshot m = g.monitor.Save();
  st.flags = (g.latched ? ARFLEX_FORCE_GUARD_STATE_FLAG_LATCHED : 0u) |
             (m.have_prev ? ARFLEX_FORCE_GUARD_STATE_FLAG_MONITOR_PRIMED : 0u);
  st.reason = g.latched ? g.reason : 0u;
  st.force_norm = g.force_norm;
  st.mon_t_ns = m.t_prev;
  for (int j = 0; j < 6; ++j) {
    st.mon_qd[j] = m.qd_prev[j];
    st.mon_q[j] = m.q[j];
    st.mon_ext[j] = m.ext[j];
    st.hold_torque[j] = m.hold_t[j];
  }
  st.hold_force = m.hold_f;
  for (int k = 0; k < 3; ++k) st.a_tool[k] = m.a_tool[k];
  arflex_component_state_publish(c, &st, sizeof(st), release_ns);
}

int Write(struct arflex_component* c, uint64_t release_ns, uint32_t extra_flags) {
  struct arflex_safety_state s;
  memset(&s, 0, sizeof(s));
  s.t_ns = (int64_t)release_ns;
  s.seq = ++g.seq;
  const bool stop = g.latched || extra_flags;
  s.mode = stop ? ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP : ARFLEX_SAFETY_STATE_MODE_NORMAL;
  s.flags = (g.latched ? g.reason | ARFLEX_SAFETY_STATE_FLAG_RESET_REQUIRED : 0) | extra_flags;
  s.power_scale = stop ? arflex_param_f64(c, g.p_power) : 1.0;
  s.force_norm = g.force_norm;
  s.force_limit = arflex_param_f64(c, g.p_force);
  const int w = arflex_state_write(g.out, &s, sizeof(s));
  PublishState(c, release_ns);
  return w;
}

void ReadInputs() {
  if (arflex_input_state_read(g.in_js, &g.js, sizeof(g.js), nullptr) == 1) g.have_js = true;
  if (arflex_input_state_read(g.in_w, &g.w, sizeof(g.w), nullptr) == 1) g.have_w = true;
  if (!arflex_input_bound(g.in_js)) g.have_js = false;
  if (!arflex_input_bound(g.in_w)) g.have_w = false;
}

// True when the edge 0 -> 1 of `reset` happened since the last call.
bool ResetEdge(struct arflex_component* c) {
  const bool now = arflex_param_bool(c, g.p_reset);
  const bool edge = now && !g.reset_prev;
  g.reset_prev = now;
  return edge;
}

// Measures the external joint torques and the contact force (sets g.force_norm) against the
// limits, widened while the arm accelerates by the monitor's allowance for what the rigid
// nominal model cannot know (cellkin.h, ContactMonitor); returns the reason bits of what is
// above a limit (0 = nothing).
uint32_t Measure(struct arflex_component* c) {
  const double payload = arflex_param_f64(c, g.p_payload);
  uint32_t reason = 0;
  if (g.have_js) {
    Q q, qd, tau;
    for (int j = 0; j < 6; ++j) {
      q[j] = g.js.q[j];
      qd[j] = g.js.qd[j];
      tau[j] = g.js.tau[j];
    }
    g.monitor.Update(g.js.t_ns, q, qd, tau, payload);
    const Q over = g.monitor.external_torque().cwiseAbs() - g.monitor.torque_allowance();
    if (over.maxCoeff() > arflex_param_f64(c, g.p_torque)) reason |= ARFLEX_SAFETY_STATE_FLAG_FORCE_LIMIT;
  } else {
    g.monitor.Reset();
  }
  g.force_norm = 0;
  double allowance = 0;
  if (g.have_w) {
    const Eigen::Vector3d f(g.w.force[0], g.w.force[1], g.w.force[2]);
    if (g.have_js) {
      g.force_norm = g.monitor.ContactForce(f, payload).norm();
      allowance = g.monitor.force_allowance();
    } else {
      // No joint angles: the tool's weight direction is unknown; the contact force is at
      // least | |F| - weight |.
      const double weight = (g.model.arm().tool_mass + payload) * arflex::cellkin::kGravity;
      g.force_norm = std::fabs(f.norm() - weight);
    }
    if (g.force_norm - allowance > arflex_param_f64(c, g.p_force))
      reason |= ARFLEX_SAFETY_STATE_FLAG_FORCE_LIMIT;
  }
  return reason;
}

int Update(struct arflex_component* c, void*, uint64_t release_ns) {
  ResetEdge(c);
  // update runs again only when RESET_REQUIRED is clear: the operator's RESET came.
  if (g.latched && !(__atomic_load_n(&arflex_component_ctl(c)->flags, __ATOMIC_ACQUIRE) &
                     ARFLEX_FLAG_RESET_REQUIRED)) {
    g.latched = false;
    g.reason = 0;
  }
  ReadInputs();
  const uint32_t reason = Measure(c);
  if (reason && !g.latched) {
    g.latched = true;
    g.reason = reason;
    ++g.trips;
    arflex_component_require_reset(c);
  }
  return Write(c, release_ns, 0);
}

int Safe(struct arflex_component* c, void*, enum arflex_safe_mode, bool) {
  struct arflex_ctl* ctl = Ctl(c);
  const uint64_t now = arflex_sys_now_ns();
  ReadInputs();
  Measure(c);  // the stop keeps publishing the current contact force (is the contact gone?)
  if (ResetEdge(c) && g.latched) {
    g.latched = false;
    g.reason = 0;
    __atomic_and_fetch(&ctl->flags, ~(uint32_t)ARFLEX_FLAG_RESET_REQUIRED, __ATOMIC_RELEASE);
    return Write(c, now, 0);
  }
  // In safe mode without a latch of ours: the runtime heartbeat is lost.
  return Write(c, now, g.latched ? 0 : ARFLEX_SAFETY_STATE_FLAG_HEARTBEAT_LOST);
}

// The adopt hook (D52): right after Start, at the START of a change set's new version, the
// state the running version published last. Latched there: latched here, RESET_REQUIRED on
// this half's own control block (rt-core then runs Safe, which writes PROTECTIVE_STOP, until
// the operator's RESET). The safety output's seq continues; the monitor goes on from the old
// half's filter (no acceleration estimate lost, so no allowance missing at the switch). A
// block this version cannot read: latched (fail closed), never refused.
int Adopt(struct arflex_component* c, void*, const struct arflex_adopted_state* a) {
  struct arflex_force_guard_state st;
  const bool known = std::strcmp(a->type_name, ARFLEX_TYPE_FORCE_GUARD_STATE_NAME) == 0 &&
                     a->major == ARFLEX_TYPE_FORCE_GUARD_STATE_VERSION_MAJOR && a->length >= sizeof(st);
  if (known) std::memcpy(&st, a->data, sizeof(st));
  if (!known || !arflex_force_guard_state_valid(&st)) {
    g.latched = true;
    g.reason = 0;  // the cause is unknown: RESET_REQUIRED alone says why
    arflex_component_require_reset(c);
    return 0;
  }
  g.seq = st.out_seq;
  g.trips = st.trips;
  g.force_norm = st.force_norm;
  g.state.seq = st.seq;
  if (st.flags & ARFLEX_FORCE_GUARD_STATE_FLAG_LATCHED) {
    g.latched = true;
    g.reason = st.reason;
    arflex_component_require_reset(c);
  }
  arflex::cellkin::ContactMonitor::Snapshot m;
  m.have_prev = (st.flags & ARFLEX_FORCE_GUARD_STATE_FLAG_MONITOR_PRIMED) != 0;
  m.t_prev = st.mon_t_ns;
  for (int j = 0; j < 6; ++j) {
    m.qd_prev[j] = st.mon_qd[j];
    m.q[j] = st.mon_q[j];
    m.ext[j] = st.mon_ext[j];
    m.hold_t[j] = st.hold_torque[j];
  }
  m.hold_f = st.hold_force;
  for (int k = 0; k < 3; ++k) m.a_tool[k] = st.a_tool[k];
  if (!g.monitor.Restore(m)) g.monitor.Reset();  // (valid() checked finiteness: not reached)
  return 0;
}

const struct arflex_component_ops kOps = {
    "force-guard", nullptr, Configure, Start, Update, nullptr, nullptr, Safe, Adopt,
};

}  // namespace

int main(int argc, char** argv) { return arflex_component_main(argc, argv, &kOps); }
