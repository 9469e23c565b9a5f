// test_cell_force_guard_state.cc - test_cell: cell.force_guard_state (docs/DECISIONS.md D52):
// force-guard's state block handed to its next version. A latched protective stop survives the
// adoption (fail closed, shared/SAFETY.md), the contact monitor's filter goes on, and a block
// the new half cannot read starts it latched. (The harness: cell_rig.h.)
#include "arflex_types/force_guard_state.h"
#include "cell_rig.h"

namespace celltest {
namespace {

const struct arflex_port_type kFgsT = {ARFLEX_TYPE_FORCE_GUARD_STATE_NAME, 1, 0, sizeof(arflex_force_guard_state)};

// The newest value of `h`'s state block that passes `ok`, within 5 s.
template <typename F>
bool GuardState(struct arflex_host* h, struct arflex_force_guard_state* st, F ok) {
  struct arflex_port* own = arflex_host_state(h);
  if (!own) return false;
  struct arflex_port p;
  if (arflex_port_open(&p, own->name, false, false, ARFLEX_PORT_STATE, &kFgsT) != 0) return false;
  bool got = false;
  const uint64_t deadline = Now() + 5 * kSec;
  while (!got && Now() < deadline) got = arflex_state_read(&p, st, sizeof(*st), nullptr) == 1 && ok(*st);
  arflex_port_close(&p);
  return got;
}

// The newest safety value of `rd` that passes `ok`, within 5 s.
template <typename F>
bool Safety(Reader* rd, struct arflex_safety_state* s, F ok) {
  const uint64_t deadline = Now() + 5 * kSec;
  while (Now() < deadline)
    if (rd->Read(s, nullptr) == 1 && ok(*s)) return true;
  return false;
}

bool Stopped(const struct arflex_safety_state& s) { return s.mode == ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP; }
bool Normal(const struct arflex_safety_state& s) { return s.mode == ARFLEX_SAFETY_STATE_MODE_NORMAL; }

uint32_t CtlFlags(struct arflex_host* h) { return __atomic_load_n(&h->ctl->flags, __ATOMIC_ACQUIRE); }

// Another guard half, bound to the script's joint_state and wrench, READY.
int Guard(struct arflex_host* h, const char* inst, struct arflex_host* script) {
  int r = Make(h, inst, "force-guard", kMs);
  if (r == 0) r = arflex_host_bind(h, "joint_state", arflex_host_output_name(script, "joint_state"), kCall);
  if (r == 0) r = arflex_host_bind(h, "wrench", arflex_host_output_name(script, "wrench"), kCall);
  return r;
}

}  // namespace

void CaseForceGuardState() {
  static struct arflex_host script, g1, g2, g3, g4;
  Model m;
  uint64_t wseq = 0;
  CHECK(MakeScript(&script, {{"joint_state", kJsT}, {"wrench", kWT}}) == 0, "script");
  Q q;
  q << 0.1, 0.2, 0.5, 0.1, 0.6, 0.2;
  WriteRobot(&script, m, q, Q::Zero(), Eigen::Vector3d::Zero(), &wseq);
  CHECK(Guard(&g1, "guard", &script) == 0, "guard");
  CHECK(arflex_host_state(&g1) != nullptr, "the contract's state block has a segment");
  CHECK(arflex_host_start(&g1, kCall) == 0, "START guard");
  Reader r1;
  CHECK(r1.Open(&g1, "safety", &kST) == 0, "safety of guard");
  struct arflex_safety_state s{};
  CHECK(Safety(&r1, &s, Normal), "guard NORMAL at rest");
  // A push of 1000 N: latched.
  WriteRobot(&script, m, q, Q::Zero(), Eigen::Vector3d(1000, 0, 0), &wseq);
  CHECK(Safety(&r1, &s, Stopped), "guard stops on the push");
  WriteRobot(&script, m, q, Q::Zero(), Eigen::Vector3d::Zero(), &wseq);  // the push is gone
  // Two joint samples 1 ms apart, joint 0 accelerating: the monitor's filter has a previous
  // sample and an inertial allowance (torques = gravity + the inertial term: no contact).
  struct arflex_joint_state js{};
  js.t_ns = (int64_t)Now();
  js.seq = ++wseq;
  Q qd = Q::Zero();
  const Q tau0 = m.InverseDynamics(q, qd, Q::Zero(), 0);
  for (int j = 0; j < 6; ++j) {
    js.q[j] = q[j];
    js.tau[j] = tau0[j];
  }
  arflex_state_write(arflex_host_output(&script, "joint_state"), &js, sizeof(js));
  struct arflex_force_guard_state st1{};
  const int64_t t_a = js.t_ns;
  CHECK(GuardState(&g1, &st1, [t_a](const arflex_force_guard_state& v) { return v.mon_t_ns == t_a; }),
        "the guard's monitor took the first sample");
  js.t_ns = t_a + (int64_t)kMs;
  js.seq = ++wseq;
  qd[0] = 0.02;  // 20 rad/s^2 over the millisecond
  const Q qdd = (qd / 1e-3);
  const Q tau1 = m.InverseDynamics(q, qd, qdd, 0);
  for (int j = 0; j < 6; ++j) {
    js.qd[j] = qd[j];
    js.tau[j] = tau1[j];
  }
  arflex_state_write(arflex_host_output(&script, "joint_state"), &js, sizeof(js));
  const int64_t t_b = js.t_ns;
  CHECK(GuardState(&g1, &st1, [t_b](const arflex_force_guard_state& v) { return v.mon_t_ns == t_b; }),
        "the guard's monitor took the second sample");
  CHECK((st1.flags & ARFLEX_FORCE_GUARD_STATE_FLAG_LATCHED) && st1.trips == 1 &&
            (st1.reason & ARFLEX_SAFETY_STATE_FLAG_FORCE_LIMIT),
        "guard's state: flags %#x, trips %llu, reason %#x", st1.flags, (unsigned long long)st1.trips, st1.reason);
  CHECK((st1.flags & ARFLEX_FORCE_GUARD_STATE_FLAG_MONITOR_PRIMED) && st1.hold_torque[0] > 0,
        "the monitor primed with an allowance (hold_torque[0] %.3f)", st1.hold_torque[0]);
  uint64_t old_seq = 0;
  {
    struct arflex_safety_state last{};
    CHECK(Safety(&r1, &last, Stopped), "guard still stopped");
    old_seq = last.seq;
  }

  // The next version adopts it: latched at once, RESET_REQUIRED on its own control block.
  CHECK(Guard(&g2, "1-guard", &script) == 0, "1-guard");
  CHECK(arflex_host_adopt(&g2, arflex_host_state(&g1)->name, kCall) == 0, "ADOPT");
  Reader r2;
  CHECK(r2.Open(&g2, "safety", &kST) == 0, "safety of 1-guard");
  CHECK(arflex_host_start(&g2, kCall) == 0, "START 1-guard");
  struct arflex_safety_state s2{};
  CHECK(Safety(&r2, &s2, [](const arflex_safety_state&) { return true; }), "1-guard writes");
  struct arflex_force_guard_state st2{};
  CHECK(GuardState(&g2, &st2, [](const arflex_force_guard_state&) { return true; }), "1-guard's state");
  printf("force_guard_state: the adopting half's first output mode %u flags %#x seq %llu (the old half's %llu); "
         "its ctl flags %#x; monitor sample %lld (the old half's %lld), hold_torque[0] %.4f N m (%.4f)\n", s2.mode,
         s2.flags, (unsigned long long)s2.seq, (unsigned long long)old_seq, CtlFlags(&g2), (long long)st2.mon_t_ns,
         (long long)st1.mon_t_ns, st2.hold_torque[0], st1.hold_torque[0]);
  CHECK(Stopped(s2), "1-guard's first output is not a stop: mode %u", s2.mode);
  CHECK((s2.flags & ARFLEX_SAFETY_STATE_FLAG_RESET_REQUIRED) && (s2.flags & ARFLEX_SAFETY_STATE_FLAG_FORCE_LIMIT),
        "1-guard's flags %#x: the latch and its cause", s2.flags);
  CHECK(s2.seq > old_seq, "its seq continues the old half's (%llu after %llu)", (unsigned long long)s2.seq,
        (unsigned long long)old_seq);
  CHECK(CtlFlags(&g2) & ARFLEX_FLAG_RESET_REQUIRED, "1-guard's control block awaits a reset");
  CHECK((st2.flags & ARFLEX_FORCE_GUARD_STATE_FLAG_LATCHED) && st2.trips == 1, "1-guard's state flags %#x trips %llu",
        st2.flags, (unsigned long long)st2.trips);
  CHECK(st2.mon_t_ns == st1.mon_t_ns && st2.hold_torque[0] == st1.hold_torque[0] && st2.hold_force == st1.hold_force,
        "the monitor's filter goes on (sample %lld, hold %.6f, against %lld, %.6f)", (long long)st2.mon_t_ns,
        st2.hold_torque[0], (long long)st1.mon_t_ns, st1.hold_torque[0]);

  // Without the state a new half would have released the stop: what the transfer avoids. (On
  // the accelerating sample a fresh half, with no previous sample to difference, reads the
  // inertial torque as contact and trips: the arm at rest here.)
  WriteRobot(&script, m, q, Q::Zero(), Eigen::Vector3d::Zero(), &wseq);
  CHECK(Guard(&g3, "2-guard", &script) == 0, "2-guard");
  Reader r3;
  CHECK(r3.Open(&g3, "safety", &kST) == 0, "safety of 2-guard");
  CHECK(arflex_host_start(&g3, kCall) == 0, "START 2-guard");
  struct arflex_safety_state s3{};
  CHECK(Safety(&r3, &s3, [](const arflex_safety_state&) { return true; }), "2-guard writes");
  CHECK(Normal(s3), "a fresh half on the same inputs: mode %u (NORMAL expected: the latch is in the state only)",
        s3.mode);

  // The operator's reset releases the adopted latch like its own.
  CHECK(arflex_host_reset(&g2, kCall) == 0, "RESET 1-guard");
  CHECK(Safety(&r2, &s2, Normal), "1-guard NORMAL after the reset");

  // A block of another type (here the script's wrench segment): latched, not refused.
  CHECK(Guard(&g4, "3-guard", &script) == 0, "3-guard");
  CHECK(arflex_host_adopt(&g4, arflex_host_output_name(&script, "wrench"), kCall) == 0, "ADOPT a wrench");
  Reader r4;
  CHECK(r4.Open(&g4, "safety", &kST) == 0, "safety of 3-guard");
  CHECK(arflex_host_start(&g4, kCall) == 0, "START 3-guard: another type is not refused");
  struct arflex_safety_state s4{};
  CHECK(Safety(&r4, &s4, [](const arflex_safety_state&) { return true; }), "3-guard writes");
  CHECK(Stopped(s4) && (s4.flags & ARFLEX_SAFETY_STATE_FLAG_RESET_REQUIRED), "3-guard: mode %u flags %#x", s4.mode,
        s4.flags);
  CHECK(CtlFlags(&g4) & ARFLEX_FLAG_RESET_REQUIRED, "3-guard's control block awaits a reset");
  for (struct arflex_host* h : {&g1, &g2, &g3, &g4}) {
    CHECK(arflex_host_shutdown(h, 5 * kSec) == 0, "SHUTDOWN");
    CHECK(arflex_host_wait_exit(h, 10 * kSec) == 0, "exit");
  }
}

}  // namespace celltest
