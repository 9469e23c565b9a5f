// test_cell_teach_state.cc - test_cell: cell.teach_state (docs/DECISIONS.md D57): teach's
// motion and recording handed to a new half through the host API, with real processes: the
// ADOPT reads the old half's journal (mailbox thread), the START joins the state block's tail;
// the recording is taken whole or the ADOPT / the START is refused, the old half untouched.
// (The harness: cell_rig.h; the checks themselves: teach.rec.)
#include "teach_rig.h"

namespace celltest {

void CaseTeachState() {
  static struct arflex_host script, t1, t2, t3, t4;
  static arflex_teach_state s, s2;
  Model m;
  DirGuard dir{MakeDataDir()};
  CHECK(!dir.d.empty(), "mkdtemp");
  std::string env = "ARFLEX_DATA_DIR=" + dir.d;
  char* envp[] = {const_cast<char*>(env.c_str()), nullptr};
  CHECK(MakeScript(&script, {{"joint_state", kJsT}, {"wrench", kWT}, {"safety", kST}}) == 0, "script");
  struct arflex_safety_state safety{};
  safety.mode = ARFLEX_SAFETY_STATE_MODE_NORMAL;
  safety.power_scale = 1;
  arflex_state_write(arflex_host_output(&script, "safety"), &safety, sizeof(safety));
  Q q;
  q << 0, 0.2, 0.5, 0, 0.6, 0;
  uint64_t wseq = 0;
  WriteRobot(&script, m, q, Q::Zero(), Eigen::Vector3d::Zero(), &wseq);
  CHECK(Teach(&t1, "teach1", &script, envp) == 0, "teach1");
  CHECK(arflex_host_state(&t1) != nullptr, "teach's contract declares a state block");
  CHECK(arflex_host_start(&t1, kCall) == 0, "start teach1 in teach mode");
  Reader r1;
  StateReader st1;
  CHECK(r1.Open(&t1, "joint_ref", &kRefT) == 0 && st1.Open(&t1) == 0, "teach1's outputs");
  const Eigen::Vector3d pull(0, 60, 0), none = Eigen::Vector3d::Zero();
  CHECK(Drive(&script, m, &r1, &st1, &s, pull, &wseq, [](const arflex_teach_state& v) { return v.rec_count > 300; }),
        "300 waypoints recorded (%u)", s.rec_count);
  const std::string j1 = Journal(dir.d, s);
  struct stat fs;
  CHECK(stat(j1.c_str(), &fs) == 0 && (fs.st_mode & 0777) == 0600, "the journal %s, mode 0600", j1.c_str());

  // (1) taken whole: ADOPT, 20 waypoints more, START
  CHECK(Teach(&t2, "teach2", &script, envp) == 0, "teach2");
  CHECK(arflex_host_adopt(&t2, arflex_host_state(&t1)->name, kCall) == 0, "ADOPT of teach1's state by teach2");
  const uint32_t at_adopt = s.rec_count;
  CHECK(Drive(&script, m, &r1, &st1, &s, pull, &wseq,
              [&](const arflex_teach_state& v) { return v.rec_count > at_adopt + 20; }),
        "20 waypoints more");
  CHECK(arflex_host_start(&t2, kCall) == 0, "START teach2 (adopts)");
  Reader r2;
  StateReader st2;
  CHECK(r2.Open(&t2, "joint_ref", &kRefT) == 0 && st2.Open(&t2) == 0, "teach2's outputs");
  const uint64_t dl = Now() + 5 * kSec;
  int got = 0;
  while (got != 1 && Now() < dl) got = st2.Read(&s2);
  CHECK(got == 1, "teach2's state block");
  printf("teach_state: teach1 recorded %u at the ADOPT, teach2 started with %u (teach1 then %u)\n", at_adopt,
         s2.rec_count, s.rec_count);
  CHECK(s2.rec_count >= at_adopt + 20, "teach2's recording: %u waypoints", s2.rec_count);
  CHECK(s2.rec_key[0] == s.rec_key[0] && s2.rec_key[1] == s.rec_key[1] && s2.rec_nonce == s.rec_nonce,
        "the chain goes on under the same key and nonce");
  CHECK((s2.flags & ARFLEX_TEACH_STATE_FLAG_TEACH) != 0, "teach mode goes on");
  const uint32_t taken = at_adopt + 20;
  const std::string j2 = Journal(dir.d, s2);
  const uint64_t d2 = Now() + 10 * kSec;
  while ((stat(j2.c_str(), &fs) != 0 || fs.st_size < 64 + 48 * (off_t)taken) && Now() < d2) sched_yield();
  const std::string b1 = Slurp(j1), b2 = Slurp(j2);
  CHECK(b1.size() >= 64 + 48 * (size_t)taken && b2.size() >= 64 + 48 * (size_t)taken, "journals %zu, %zu bytes",
        b1.size(), b2.size());
  CHECK(b1.compare(64, 48 * (size_t)taken, b2, 64, 48 * (size_t)taken) == 0,
        "teach2's first %u waypoints are teach1's, byte for byte", taken);
  CHECK(arflex_host_stop(&t2, kCall) == 0, "stop teach2");

  // (2) more than the tail (128) recorded between ADOPT and START: the START is refused
  CHECK(Teach(&t3, "teach3", &script, envp) == 0, "teach3");
  CHECK(arflex_host_adopt(&t3, arflex_host_state(&t1)->name, kCall) == 0, "ADOPT by teach3");
  const uint32_t at3 = s.rec_count;
  CHECK(Drive(&script, m, &r1, &st1, &s, pull, &wseq,
              [&](const arflex_teach_state& v) { return v.rec_count > at3 + 140; }),
        "140 waypoints more (%u -> %u)", at3, s.rec_count);
  int r = arflex_host_start(&t3, kCall);
  printf("teach_state: START after %u more waypoints: %d (%s)\n", s.rec_count - at3, r, strerror(-r));
  CHECK(r == -ENODATA, "teach3's START: %d", r);

  // (3) a forged journal: the ADOPT is refused
  CHECK(Drive(&script, m, &r1, &st1, &s, none, &wseq,
              [&, seen = 0u, since = 0ull](const arflex_teach_state& v) mutable {
                if (v.rec_count != seen) {
                  seen = v.rec_count;
                  since = v.seq;
                }
                return v.seq - since > 300;
              }),
        "the arm at rest");
  {
    const int fd = open(j1.c_str(), O_RDWR);
    CHECK(fd >= 0, "open %s", j1.c_str());
    double x;
    const off_t at = 64 + 48 * 5 + 8;
    bool ok = pread(fd, &x, 8, at) == 8;
    x += 1e-6;
    ok = ok && pwrite(fd, &x, 8, at) == 8;
    close(fd);
    CHECK(ok, "forge waypoint 5");
  }
  CHECK(Teach(&t4, "teach4", &script, envp) == 0, "teach4");
  r = arflex_host_adopt(&t4, arflex_host_state(&t1)->name, kCall);
  printf("teach_state: ADOPT of a forged journal: %d (%s)\n", r, strerror(-r));
  CHECK(r == -EBADMSG, "teach4's ADOPT: %d", r);

  // teach1 ran on through all of it
  const uint64_t before = s.seq;
  CHECK(Drive(&script, m, &r1, &st1, &s, none, &wseq, [&](const arflex_teach_state& v) { return v.seq > before + 100; }),
        "teach1 runs on");
  CHECK(arflex_host_stop(&t1, kCall) == 0, "stop teach1");
}

}  // namespace celltest
