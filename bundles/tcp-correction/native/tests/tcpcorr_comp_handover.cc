// tcpcorr_comp_handover.cc - tcpcorr.comp.switch and tcpcorr.comp.adopt: the reference moves to
// another provider (bumpless, D35) and another half takes the correction over (state transfer,
// D41) (the harness: tcpcorr_comp_rig.h).
#include "tcpcorr_comp_rig.h"

namespace tcpcorr_comp {

void CaseSwitch(Rig& rig) {
  // Bumpless transfer (D35): the reference input moves to another provider whose value is
  // 10 mrad away on joint 0: the output takes the new value over 0.5 s, never by a step; a
  // provider 200 mrad away is passed on at once (not faded: the robot's acquisition judges).
  rig.Watch(200 * kMs, false, true, Eigen::Vector3d::Zero());  // the correction's ramp done
  const arflex_joint_ref before = rig.last;
  const double excess = rig.max_jump_excess;
  CHECK(rig.MakeFeeder2(0.01) == 0, "feeder2");
  arflex_joint_ref ref2;  // what feeder2 holds
  std::memset(&ref2, 0, sizeof(ref2));
  ref2.t_ns = 1;
  ref2.seq = 1;
  for (int i = 0; i < 6; ++i) ref2.q[i] = kRef[i] + (i == 0 ? 0.01 : 0.0);
  CHECK(arflex_host_bind(&rig.corr, "reference", arflex_host_output_name(&rig.feeder2, "reference"), 2 * kSec) == 0,
        "BIND reference to feeder2");
  double worst = 0;  // the largest output step per cycle, any joint
  {
    // The fade takes 500 of the corrector's cycles (0.5 s at 1 ms): wait for 600 of its outputs,
    // not for wall time (a loaded machine skips releases; 800 ms of wall time failed at load 18).
    arflex_joint_ref prev = rig.last;
    const uint64_t from = prev.seq;
    const uint64_t deadline = arflex_sys_now_ns() + 20 * kSec;
    while (rig.last.seq < from + 600 && arflex_sys_now_ns() < deadline) {
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

void CaseAdopt(Rig& rig, const char* exe) {
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

}  // namespace tcpcorr_comp
