// teach_rig.h - what the teach cases of test_cell share (cell.teach_state, cell.teach_sweep):
// a reader of a half's state block, a perfect robot driven by teach's reference, the journal
// a state block names, a teach half made as the DRCR makes it.
#ifndef ARFLEX_TEACH_RIG_H
#define ARFLEX_TEACH_RIG_H

#include <fstream>
#include <iterator>

#include "cell_rig.h"

namespace celltest {


inline const struct arflex_port_type kTsT = {ARFLEX_TYPE_TEACH_STATE_NAME, 1, 0, sizeof(arflex_teach_state)};

// A reader of a half's state block.
struct StateReader {
  struct arflex_port port;
  bool open = false;
  int Open(struct arflex_host* h) {
    struct arflex_port* own = arflex_host_state(h);
    if (!own) return -ENOENT;
    int r = arflex_port_open(&port, own->name, false, false, ARFLEX_PORT_STATE, &kTsT);
    open = r == 0;
    return r;
  }
  int Read(arflex_teach_state* v) { return arflex_state_read(&port, v, sizeof(*v), nullptr); }
  ~StateReader() {
    if (open) arflex_port_close(&port);
  }
};

struct DirGuard {
  std::string d;
  ~DirGuard() { RemoveDir(d); }
};

// The test plays a perfect robot: the measured position is `ref`'s reference, the hand pulls
// with `hand`; until done(newest state of `st`) or 30 s.
template <typename F>
bool Drive(struct arflex_host* script, const Model& m, Reader* ref, StateReader* st, arflex_teach_state* v,
           const Eigen::Vector3d& hand, uint64_t* wseq, F done) {
  const uint64_t dl = Now() + kWait;
  struct arflex_joint_ref r;
  uint64_t seq;
  while (Now() < dl) {
    if (st->Read(v) == 1 && done(*v)) return true;
    if (ref->Read(&r, &seq) != 1) {
      sched_yield();
      continue;
    }
    Q q;
    for (int j = 0; j < 6; ++j) q[j] = r.q[j];
    WriteRobot(script, m, q, Q::Zero(), hand, wseq);
  }
  return false;
}

inline std::string Journal(const std::string& dir, const arflex_teach_state& s) {
  char name[96];
  snprintf(name, sizeof(name), "/teach-rec-%u-%016llx.bin", s.journal_pid, (unsigned long long)s.rec_nonce);
  return dir + name;
}

inline std::string Slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

inline int Teach(struct arflex_host* h, const char* inst, struct arflex_host* script, char* const* envp) {
  int r = Make(h, inst, "teach", kMs, envp, {{"record_step", 0.0002}});
  if (r == 0) r = arflex_host_bind(h, "joint_state", arflex_host_output_name(script, "joint_state"), kCall);
  if (r == 0) r = arflex_host_bind(h, "wrench", arflex_host_output_name(script, "wrench"), kCall);
  if (r == 0) r = arflex_host_bind(h, "safety", arflex_host_output_name(script, "safety"), kCall);
  // the parameters in force, as the DRCR carries them to a new version
  if (r == 0) r = arflex_host_set_param(h, "teach", 1, nullptr, kCall);
  return r;
}

}  // namespace celltest

#endif  // ARFLEX_TEACH_RIG_H
