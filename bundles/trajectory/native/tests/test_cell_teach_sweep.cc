// test_cell_teach_sweep.cc - test_cell: cell.teach_sweep (docs/DECISIONS.md D63): a teach half
// killed with SIGKILL while it records leaves its journal in the data folder; the next teach half
// that starts there removes it once it runs, and nothing else: not the journal of a half that
// runs on (teach1, recording throughout), not its own, not a symlink or another uid's file named
// like a dead half's journal (nor the symlink's target). Real teach processes under the host
// API on a scripted perfect robot (the pure checks: teach.sweep).
#include <signal.h>

#include <set>

#include "teach_rig.h"

namespace celltest {

namespace {

bool Exists(const std::string& p) {
  struct stat st;
  return lstat(p.c_str(), &st) == 0;
}

// The regular files of `dir` named teach-rec-*.bin.
std::set<std::string> Journals(const std::string& dir) {
  std::set<std::string> s;
  if (DIR* d = opendir(dir.c_str())) {
    while (struct dirent* e = readdir(d)) {
      struct stat st;
      const std::string p = dir + "/" + e->d_name;
      if (strncmp(e->d_name, "teach-rec-", 10) == 0 && lstat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode))
        s.insert(p);
    }
    closedir(d);
  }
  return s;
}

pid_t DeadPid() {
  const pid_t p = fork();
  if (p == 0) _exit(0);
  int st;
  if (p > 0) waitpid(p, &st, 0);
  return p;
}

}  // namespace

void CaseTeachSweep() {
  static struct arflex_host script, t1, tk, t2;
  static arflex_teach_state s1, sk, s2;
  Model m;
  DirGuard dir{MakeDataDir()};
  CHECK(!dir.d.empty(), "mkdtemp");
  const std::string victim = dir.d + ".victim";
  struct FileGuard {  // the planted file outside the folder goes with the case, failed or not
    std::string p;
    ~FileGuard() { unlink(p.c_str()); }
  } victim_guard{victim};
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
  const Eigen::Vector3d pull(0, 60, 0);

  // teach1 records throughout; teach_killed records too, then is killed (SIGKILL)
  CHECK(Teach(&t1, "teach1", &script, envp) == 0 && arflex_host_start(&t1, kCall) == 0, "teach1 in teach mode");
  CHECK(Teach(&tk, "teach-killed", &script, envp) == 0 && arflex_host_start(&tk, kCall) == 0,
        "teach-killed in teach mode");
  Reader r1;
  StateReader st1, stk;
  CHECK(r1.Open(&t1, "joint_ref", &kRefT) == 0 && st1.Open(&t1) == 0 && stk.Open(&tk) == 0, "the halves' outputs");
  CHECK(Drive(&script, m, &r1, &st1, &s1, pull, &wseq,
              [&](const arflex_teach_state& v) { return v.rec_count > 200 && stk.Read(&sk) >= 0 && sk.rec_count > 200; }),
        "both record (teach1 %u, teach_killed %u waypoints)", s1.rec_count, sk.rec_count);
  CHECK(sk.journal_pid == (uint32_t)tk.pid, "teach_killed's block names its pid %u (%d)", sk.journal_pid, (int)tk.pid);
  const std::string j1 = Journal(dir.d, s1), jk = Journal(dir.d, sk);
  const uint64_t dj = Now() + 10 * kSec;
  while (Now() < dj && !(Exists(j1) && Exists(jk))) sched_yield();
  CHECK(Exists(j1) && Exists(jk), "both journals written: %s, %s", j1.c_str(), jk.c_str());
  CHECK(arflex_host_kill(&tk, SIGKILL) == 0 && arflex_host_wait_exit(&tk, kCall) == 0, "kill -9 teach_killed");
  CHECK(WIFSIGNALED(arflex_host_exit_status(&tk)), "teach_killed died of its signal");
  CHECK(Exists(jk), "the killed half's journal is left behind: %s", jk.c_str());

  // planted: a symlink to a file outside, another uid's file, named like a dead half's journal
  char name[96];
  const pid_t gone = DeadPid();
  CHECK(gone > 0, "a pid that is gone");
  CHECK(WriteText(victim, "precious\n"), "the victim file");
  snprintf(name, sizeof(name), "/teach-rec-%d-00000000000000aa.bin", (int)gone);
  const std::string link = dir.d + name;
  CHECK(symlink(victim.c_str(), link.c_str()) == 0, "symlink %s", link.c_str());
  snprintf(name, sizeof(name), "/teach-rec-%d-00000000000000bb.bin", (int)gone);
  const std::string foreign = dir.d + name;
  const bool root = geteuid() == 0;
  if (root) {
    CHECK(WriteText(foreign, "not a journal\n") && chmod(foreign.c_str(), 0600) == 0 &&
              lchown(foreign.c_str(), 12345, 12345) == 0,
          "a file of uid 12345");
  } else {
    printf("teach_sweep: not root: no file of another uid planted\n");
  }

  // teach2 starts in the folder: once it runs, the killed half's journal is gone, nothing else
  const uint64_t t_start = Now();
  CHECK(Teach(&t2, "teach2", &script, envp) == 0 && arflex_host_start(&t2, kCall) == 0, "teach2");
  StateReader st2;
  CHECK(st2.Open(&t2) == 0, "teach2's state block");
  CHECK(Drive(&script, m, &r1, &st1, &s1, pull, &wseq,
              [&](const arflex_teach_state&) { return !Exists(jk) && st2.Read(&s2) >= 0 && s2.journal_pid != 0; }),
        "the killed half's journal %s removed after teach2's start", jk.c_str());
  printf("teach_sweep: the killed half's journal removed %.0f ms after teach2's spawn\n", (Now() - t_start) / 1e6);
  const std::string j2 = Journal(dir.d, s2);
  const uint64_t d2 = Now() + 10 * kSec;
  while (Now() < d2 && !Exists(j2)) sched_yield();
  CHECK(Exists(j1), "the running teach1's journal is kept");
  CHECK(Exists(j2), "teach2's own journal %s", j2.c_str());
  CHECK(Exists(link) && Slurp(victim) == "precious\n", "the symlink and its target are left as they are");
  CHECK(!root || Exists(foreign), "the other uid's file is left");
  const std::set<std::string> js = Journals(dir.d), want = root ? std::set<std::string>{j1, j2, foreign}
                                                                 : std::set<std::string>{j1, j2};
  CHECK(js == want, "the folder holds %zu journal files, the live halves' and the other uid's file", js.size());
  // teach1 recorded on
  const uint32_t n1 = s1.rec_count;
  CHECK(Drive(&script, m, &r1, &st1, &s1, pull, &wseq, [&](const arflex_teach_state& v) { return v.rec_count > n1 + 20; }),
        "teach1 records on (%u -> %u)", n1, s1.rec_count);
  printf("teach_sweep: journals left: %zu (teach1 pid %u, teach2 pid %u%s)\n", js.size(), s1.journal_pid, s2.journal_pid,
         root ? ", uid 12345's file" : "");
  CHECK(arflex_host_stop(&t1, kCall) == 0 && arflex_host_stop(&t2, kCall) == 0, "stop");
}

}  // namespace celltest
