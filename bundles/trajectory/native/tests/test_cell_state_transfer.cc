// test_cell_state_transfer.cc - test_cell: cell.state_transfer (the harness: cell_rig.h).
#include "cell_rig.h"

namespace celltest {

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

}  // namespace celltest
