// tcpcorr_comp_convert.cc - tcpcorr.comp.convert: a declared state conversion executed (D52).
// A half publishing the 1.0 state block (arflex.TcpCorrectionState, what a 1.0.x version's
// contract declares) is in the middle of a provider-change fade; a 1.1 half (its contract's
// arflex.TcpCorrectionState2, converting from 1.0) with blend_time 0.2 s adopts it. The
// conversion says: the fade goes on over 1.0's fixed 0.5 s (blend_duration = 0.5), whatever
// the new half's parameter; a new fade then takes the parameter. (The harness: tcpcorr_comp_rig.h.)
#include <map>

#include "tcpcorr_comp_rig.h"

namespace tcpcorr_comp {
namespace {

const arflex_port_type kV1 = {ARFLEX_TYPE_TCP_CORRECTION_STATE_NAME, 1, 0, ARFLEX_TYPE_TCP_CORRECTION_STATE_SIZE};
const arflex_port_type kV2 = {ARFLEX_TYPE_TCP_CORRECTION_STATE2_NAME, 1, 0, ARFLEX_TYPE_TCP_CORRECTION_STATE2_SIZE};

// Reads the newest value of the state block `name` of type `t` into `out` (len bytes) within
// 5 s; false when the segment is not of that type or nothing passing `ok` was published.
template <typename V, typename F>
bool ReadState(const char* name, const arflex_port_type& t, V* out, F ok) {
  arflex_port p{};
  if (arflex_port_open(&p, name, false, false, ARFLEX_PORT_STATE, &t) != 0) return false;
  bool got = false;
  const uint64_t deadline = arflex_sys_now_ns() + 5 * kSec;
  while (!got && arflex_sys_now_ns() < deadline) got = arflex_state_read(&p, out, sizeof(V), nullptr) == 1 && ok(*out);
  arflex_port_close(&p);
  return got;
}

}  // namespace

void CaseConvert(Rig& rig, const char* exe) {
  static arflex_host old_h, next_h;
  arflex_port oout{}, nout{};
  // The 1.0 half: publishes arflex.TcpCorrectionState 1.0; takes the corrector's state so the
  // converged correction goes along (this executable adopts either block; the DRCR's plan
  // decides which one is offered).
  int r = rig.Second(&old_h, "0-corr", exe, &oout, &kV1);
  if (r == 0) r = arflex_host_adopt(&old_h, arflex_host_state(&rig.corr)->name, 2 * kSec);
  if (r == 0) r = arflex_host_start(&old_h, 2 * kSec);
  CHECK(r == 0, "the 1.0 half: %d", r);
  const std::string old_state = arflex_host_state(&old_h)->name;
  arflex_tcp_correction_state v1{};
  CHECK(ReadState(old_state.c_str(), kV1, &v1, [](const arflex_tcp_correction_state& v) { return v.out_seq > 0; }),
        "the 1.0 half publishes a 1.0 block");
  // A provider change: feeder2 10 mrad away on joint 0, faded out over 0.5 s.
  CHECK(rig.MakeFeeder2(0.01) == 0, "feeder2");
  const char* ref2 = arflex_host_output_name(&rig.feeder2, "reference");
  CHECK(arflex_host_bind(&old_h, "reference", ref2, 2 * kSec) == 0, "BIND the 1.0 half to feeder2");
  CHECK(ReadState(old_state.c_str(), kV1, &v1,
                  [](const arflex_tcp_correction_state& v) { return v.blend_t >= 0.1 && v.blend_t < 0.2; }),
        "the 1.0 half's fade 0.1-0.2 s in");
  // The 1.1 half, blend_time 0.2 s: told the 1.0 half's block, on the same reference.
  r = rig.Second(&next_h, "1-corr", exe, &nout);
  if (r == 0) r = arflex_host_set_param(&next_h, "blend_time", arflex_f64_bits(0.2), nullptr, 2 * kSec);
  if (r == 0) r = arflex_host_bind(&next_h, "reference", ref2, 2 * kSec);
  if (r == 0) r = arflex_host_adopt(&next_h, old_state.c_str(), 2 * kSec);
  // Both halves write under the same seqs (the new one continues the old one's): collect both,
  // the old one's from before the START, until the fade is over, then compare value for value.
  std::map<uint64_t, arflex_joint_ref> olds, news;
  const uint64_t deadline = arflex_sys_now_ns() + 10 * kSec;
  while (r == 0 && olds.empty() && arflex_sys_now_ns() < deadline) {
    arflex_joint_ref v;
    if (arflex_state_read(&oout, &v, sizeof(v), nullptr) == 1) olds[v.seq] = v;
  }
  if (r == 0) r = arflex_host_start(&next_h, 2 * kSec);
  while (r == 0 && arflex_sys_now_ns() < deadline && (news.size() < 700 || olds.size() < 700)) {
    arflex_joint_ref v;
    if (arflex_state_read(&oout, &v, sizeof(v), nullptr) == 1) olds[v.seq] = v;
    if (arflex_state_read(&nout, &v, sizeof(v), nullptr) == 1) news[v.seq] = v;
  }
  arflex_tcp_correction_state2 v2{};
  const std::string next_state = arflex_host_state(&next_h)->name;
  const bool read2 = ReadState(next_state.c_str(), kV2, &v2, [](const arflex_tcp_correction_state2&) { return true; });
  // The step a half that took the fade's duration from its parameter would have made at the
  // adoption: the rest of the fade at the adopted time under 0.5 s against under 0.2 s.
  const auto rest = [](double t, double d) {
    const double u = std::min(t / d, 1.0);
    return 1.0 - u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
  };
  const double unconverted = 0.01 * std::abs(rest(v1.blend_t, 0.5) - rest(v1.blend_t, 0.2));
  int same = 0;
  double diff = 0, first_step = -1;
  for (const auto& [seq, n] : news) {
    auto o = olds.find(seq);
    if (o == olds.end()) continue;
    ++same;
    for (int i = 0; i < 6; ++i) diff = std::max(diff, std::abs(n.q[i] - o->second.q[i]));
  }
  if (!news.empty()) {
    const auto& first = news.begin()->second;
    auto before = olds.lower_bound(first.seq);
    if (before != olds.begin()) {
      --before;
      first_step = std::abs(first.q[0] - before->second.q[0]) / static_cast<double>(first.seq - before->first);
    }
  }
  printf("convert: adopted a 1.0 block %.3f s into its fade; the 1.1 half's blend_duration %.3f s (its blend_time "
         "0.2); %d values under the same seq as the 1.0 half, largest difference %.3g rad; its first value %.4f mrad "
         "per cycle from the 1.0 half's before it (the fade under 0.2 s would have stepped %.3f mrad there)\n",
         v1.blend_t, v2.blend_duration, same, diff, 1e3 * first_step, 1e3 * unconverted);
  // A later provider change of the 1.1 half takes its parameter.
  if (r == 0) r = arflex_host_bind(&next_h, "reference", arflex_host_output_name(&rig.feeder, "reference"), 2 * kSec);
  arflex_tcp_correction_state2 v2b{};
  const bool refade = r == 0 && ReadState(next_state.c_str(), kV2, &v2b, [](const arflex_tcp_correction_state2& v) {
    return v.blend_duration == 0.2 && v.blend_t < 0.2;
  });
  arflex_port_close(&oout);
  arflex_port_close(&nout);
  arflex_host_shutdown(&old_h, 5 * kSec);
  arflex_host_shutdown(&next_h, 5 * kSec);
  arflex_host_wait_exit(&old_h, 10 * kSec);
  arflex_host_wait_exit(&next_h, 10 * kSec);
  arflex_host_destroy(&old_h);
  arflex_host_destroy(&next_h);
  CHECK(r == 0, "the 1.1 half: %d", r);
  CHECK(read2, "the 1.1 half publishes a TcpCorrectionState2 block");
  CHECK(v2.blend_duration == 0.5, "converted blend_duration %.6f s, the conversion says 0.5", v2.blend_duration);
  CHECK(same > 300, "values under the same seq: %d", same);
  CHECK(diff < 1e-12, "the 1.1 half differs from the 1.0 half by %.3g rad under the same seq", diff);
  CHECK(first_step >= 0 && first_step < 0.05e-3, "first value %.4f mrad per cycle from the old half's",
        1e3 * first_step);
  CHECK(unconverted > 1e-3, "the fade's two durations differ by only %.3g rad here", unconverted);
  CHECK(refade, "a new fade of the 1.1 half takes blend_time 0.2 s (blend_duration %.3f)", v2b.blend_duration);
}

}  // namespace tcpcorr_comp
