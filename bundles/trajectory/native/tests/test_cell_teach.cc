// test_cell_teach.cc - test_cell: cell.teach_replay (the harness: cell_rig.h).
#include "cell_rig.h"

namespace celltest {

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
  uint64_t first = 0, seq = 0, k = 0;
  // The deadline is on progress, not on the whole pull: a half that stops writing its
  // reference fails in kWait, a slow one (the sanitizer build under load: a few ms per cycle,
  // teach runs SCHED_OTHER here) is waited for, within the ctest limit.
  uint64_t dl = Now() + kWait;
  struct arflex_joint_ref ref;
  while (Now() < dl) {
    if (tr.Read(&ref, &seq) != 1) {
      sched_yield();
      continue;
    }
    dl = Now() + kWait;
    if (!first) first = seq;
    k = seq - first;
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
        "frozen samples, held %d; %llu of teach's cycles seen, the last %.1f s ago)", frozen.size(), held,
        (unsigned long long)k, (double)(Now() + kWait - dl) / kSec);
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
  uint64_t d3 = Now() + kWait;  // on progress, as above
  uint64_t still = 0;
  Q last = Q::Constant(1e9);
  bool have_last = false;
  while (Now() < d3) {
    if (rr.Read(&ref, &seq) != 1) {
      sched_yield();
      continue;
    }
    d3 = Now() + kWait;
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

}  // namespace celltest
