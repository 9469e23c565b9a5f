// teach - RT half of the teach component (README.md): in teach mode the arm yields to a
// guiding hand (Cartesian admittance M a + D v = F_ext on the TCP position, orientation held,
// the tool's weight compensated with the nominal model) and the path is recorded; a rising
// edge of `save` writes it as a program file that trajectory replays (start, via points, ptp:
// one smooth motion through every recorded point).
//
// Ports: in joint_state (arflex.JointState), in wrench (arflex.Wrench), in safety
// (arflex.SafetyState, optional: a protective stop freezes the arm), out joint_ref
// (arflex.JointRef). Recording: a preallocated buffer of kMaxPoints joint waypoints, a new one
// whenever the reference moved more than record_step (rad, any joint) from the last one. The
// file is written by a non-RT writer thread woken with sem_post (async-signal-safe, never
// blocks) to <data dir>/program-<save_slot>.arp (cellkin::DataDir(): $ARFLEX_DATA_DIR, else
// ./data, created 0700 if missing), atomically (temporary file + rename).
//
// Update in a change set (docs/DECISIONS.md D57): the state block arflex.TeachState carries the
// motion and what identifies the recording (count, a keyed checksum chain, the newest
// TEACH_REC_TAIL waypoints); the writer thread keeps the recording in a journal file in the data
// folder (teach_rec.h). A new half reads the journal when the ADOPT arrives (adopt_prepare,
// mailbox thread) and joins it with the state block's tail at its START (adopt, RT thread, no
// I/O); it takes the recording only whole and refuses the ADOPT or the START otherwise.
// The journals of halves that are gone (killed: they could not remove theirs) are removed by
// the writer thread after this half's first cycle and whenever a recording begins (D63,
// teach_sweep.h): never a running half's, a link or another uid's file.
#include <fcntl.h>
#include <pthread.h>
#include <semaphore.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "arflex/component.h"
#include "arflex_types/joint_ref.h"
#include "arflex_types/joint_state.h"
#include "arflex_types/safety_state.h"
#include "arflex_types/teach_state.h"
#include "arflex_types/wrench.h"
#include "cellkin.h"
#include "teach_rec.h"
#include "teach_internal.h"

namespace teach {

State g;


// ---- the recording (RT thread) --------------------------------------------------------------

void RecReset() {
  g.count = 0;
  const uint64_t seed = teach_rec_seed(g.st.rec_key, g.st.rec_nonce);
  g.chain[0] = seed;
  g.st.rec_count = 0;
  g.st.rec_hash = seed;
  g.st.tail_hash = seed;
  g.st.tail_first = 0;
  g.st.tail_count = 0;
  g.pub_count.store(0, std::memory_order_release);
  g.episode.fetch_add(1, std::memory_order_acq_rel);
  sem_post(&g.sem);
}

void RecAppend(const Q& q) {
  const size_t k = g.count;
  for (int j = 0; j < 6; ++j) g.points[k][j] = q[j];
  double p[6];
  for (int j = 0; j < 6; ++j) p[j] = q[j];
  g.chain[k + 1] = teach_rec_next(g.st.rec_key, g.chain[k], p);
  g.count = k + 1;
  if (g.st.tail_count == TEACH_REC_TAIL) {
    memmove(g.st.tail, g.st.tail + 6, (TEACH_REC_TAIL - 1) * 6 * sizeof(double));
    g.st.tail_count--;
    g.st.tail_first++;
    g.st.tail_hash = g.chain[g.st.tail_first];
  }
  memcpy(g.st.tail + 6 * g.st.tail_count, p, sizeof(p));
  g.st.tail_count++;
  g.st.rec_count = (uint32_t)g.count;
  g.st.rec_hash = g.chain[g.count];
  g.pub_count.store((uint32_t)g.count, std::memory_order_release);
  sem_post(&g.sem);  // the writer brings the journal up to date
}

void Save();

void* Writer(void*) {
  for (;;) {
    while (sem_wait(&g.sem) != 0 && errno == EINTR) {
    }
    if (g.why_pending.exchange(false)) fprintf(stderr, "teach: START refused: %s\n", g.why);
    // A save requested just before shutdown is still written; then quit.
    if (g.saving.load(std::memory_order_acquire)) Save();
    if (g.sweep_pending.exchange(false, std::memory_order_acq_rel)) Sweep();
    if (g.quit.load()) {
      CloseJournal();
      return nullptr;
    }
    SyncJournal();
  }
}

void Save() {
  {
    const size_t n = g.save_count.load();
    arflex::cellkin::Program p;
    p.origin = "teach (" + std::to_string(n) + " recorded waypoints)";
    if (n > 0) {
      p.has_start = true;
      p.start = g.points[0];
      // First a joint motion to the first point: a replay that begins where the arm is (its
      // measured position, e.g. where teaching ended) goes there before it follows the path.
      arflex::cellkin::Motion m0{};
      m0.kind = arflex::cellkin::Motion::kPtp;
      for (int j = 0; j < 6; ++j) m0.v[j] = g.points[0][j];
      m0.speed = 1.0;
      p.motions.push_back(m0);
    }
    for (size_t i = 1; i < n; ++i) {
      arflex::cellkin::Motion m{};
      // One smooth motion through every recorded point, ending (at rest) on the last one.
      m.kind = i + 1 < n ? arflex::cellkin::Motion::kVia : arflex::cellkin::Motion::kPtp;
      for (int j = 0; j < 6; ++j) m.v[j] = g.points[i][j];
      m.speed = 1.0;
      p.motions.push_back(m);
    }
    std::string err;
    if (mkdir(g.dir.c_str(), 0700) != 0 && errno != EEXIST) {
      fprintf(stderr, "teach: cannot save: data directory %s: %s\n", g.dir.c_str(), strerror(errno));
      g.save_errors++;
    } else if (n < 2) {
      fprintf(stderr, "teach: nothing to save (%zu waypoint(s) recorded)\n", n);
      g.save_errors++;
    } else if (!arflex::cellkin::WriteProgramFile(
                   arflex::cellkin::ProgramPath(g.dir, g.save_slot.load()), p, &err)) {
      fprintf(stderr, "teach: save failed: %s\n", err.c_str());
      g.save_errors++;
    } else {
      fprintf(stderr, "teach: saved %zu waypoints to %s\n", n,
              arflex::cellkin::ProgramPath(g.dir, g.save_slot.load()).c_str());
      g.saved++;
    }
    g.saving.store(false, std::memory_order_release);
  }
}


int Configure(struct arflex_component* c, void*) {
  static const struct arflex_port_type js_t = {ARFLEX_TYPE_JOINT_STATE_NAME, 1, 0,
                                               sizeof(struct arflex_joint_state)};
  static const struct arflex_port_type w_t = {ARFLEX_TYPE_WRENCH_NAME, 1, 0,
                                              sizeof(struct arflex_wrench)};
  static const struct arflex_port_type ref_t = {ARFLEX_TYPE_JOINT_REF_NAME, 1, 0,
                                                sizeof(struct arflex_joint_ref)};
  static const struct arflex_port_type s_t = {ARFLEX_TYPE_SAFETY_STATE_NAME, 1, 0,
                                              sizeof(struct arflex_safety_state)};
  int r = arflex_component_output(c, "joint_ref", ARFLEX_PORT_STATE, &ref_t, &g.out);
  if (r < 0) {
    fprintf(stderr, "teach: output joint_ref: %s\n", strerror(-r));
    return r;
  }
  if ((r = arflex_component_input(c, "joint_state", ARFLEX_PORT_STATE, &js_t, &g.in_js)) < 0 ||
      (r = arflex_component_input(c, "wrench", ARFLEX_PORT_STATE, &w_t, &g.in_w)) < 0 ||
      (r = arflex_component_input(c, "safety", ARFLEX_PORT_STATE, &s_t, &g.in_safety)) < 0)
    return r;
  const char* names[] = {"teach", "mass", "damping", "deadband_n", "max_speed",
                         "payload_kg", "record_step", "save", "save_slot"};
  int* idx[] = {&g.p_teach, &g.p_mass, &g.p_damping, &g.p_deadband, &g.p_max_speed,
                &g.p_payload, &g.p_step, &g.p_save, &g.p_slot};
  for (int i = 0; i < 9; ++i) {
    *idx[i] = arflex_component_param(c, names[i]);
    if (*idx[i] < 0) {
      fprintf(stderr, "teach: parameter '%s' missing from the control block\n", names[i]);
      return -ENOENT;
    }
  }
  // D57: the state block (absent when the contract declares none: publishing is then a no-op)
  static const struct arflex_port_type st_t = {ARFLEX_TYPE_TEACH_STATE_NAME, 1, 0,
                                               sizeof(struct arflex_teach_state)};
  r = arflex_component_state(c, &st_t, nullptr);
  if (r < 0 && r != -ENOENT) return r;
  arflex_component_adopt_prepare(c, AdoptPrepare);  // the journal is read off the RT thread
  g.dir = arflex::cellkin::DataDir();
  g.pid = (uint32_t)getpid();
  if (getrandom(g.st.rec_key, sizeof(g.st.rec_key), 0) != (ssize_t)sizeof(g.st.rec_key) ||
      getrandom(&g.st.rec_nonce, sizeof(g.st.rec_nonce), 0) != (ssize_t)sizeof(g.st.rec_nonce)) {
    fprintf(stderr, "teach: no random key for the recording's checksum: %s\n", strerror(errno));
    return -EIO;
  }
  g.st.journal_pid = g.pid;
  g.points = new (std::nothrow) Q[kMaxPoints];
  g.chain = new (std::nothrow) uint64_t[kMaxPoints + 1];
  if (!g.points || !g.chain) {
    delete[] g.points;
    delete[] g.chain;
    return -ENOMEM;
  }
  if (sem_init(&g.sem, 0, 0) != 0) {
    delete[] g.points;
    delete[] g.chain;
    return -errno;
  }
  RecReset();
  r = pthread_create(&g.writer, nullptr, Writer, nullptr);
  if (r != 0) {
    sem_destroy(&g.sem);
    delete[] g.points;
    delete[] g.chain;
    return -r;
  }
  g.writer_started = true;
  return 0;
}

void Cleanup(struct arflex_component*, void*) {
  if (g.writer_started) {
    // wait for a save in progress, then stop the writer
    g.quit.store(true);
    sem_post(&g.sem);
    pthread_join(g.writer, nullptr);
  }
  sem_destroy(&g.sem);
  delete[] g.points;
  delete[] g.chain;
  g.points = nullptr;
  g.chain = nullptr;
}

// Publishes the state block (D57): the motion of this cycle; the recording's part is kept up
// to date by RecReset/RecAppend. RT safe (a seqlock write).
void PublishBlock(struct arflex_component* c, uint64_t stamp_ns) {
  g.st.t_ns = (int64_t)stamp_ns;
  g.st.seq++;
  g.st.out_seq = g.seq;
  g.st.flags = (g.initialized ? ARFLEX_TEACH_STATE_FLAG_INITIALIZED : 0u) |
               (g.teach_prev ? ARFLEX_TEACH_STATE_FLAG_TEACH : 0u) |
               (g.saving.load(std::memory_order_relaxed) ? ARFLEX_TEACH_STATE_FLAG_SAVING : 0u);
  g.st.journal_pid = g.pid;
  g.st.brake_t = g.brake_t;
  for (int j = 0; j < 6; ++j) {
    g.st.q_ref[j] = g.q_ref[j];
    g.st.brake_v0[j] = g.brake_v0[j];
  }
  for (int i = 0; i < 3; ++i) {
    g.st.x[i] = g.x[i];
    g.st.v[i] = g.v[i];
    for (int k = 0; k < 3; ++k) g.st.r_hold[3 * i + k] = g.r_hold(i, k);
  }
  arflex_component_state_publish(c, &g.st, sizeof(g.st), stamp_ns);
}

// Every cycle (update and safe): the state block, then, once, the sweep of the journals of
// halves that are gone (D63: this half's block no longer names a dead half's journal).
void Publish(struct arflex_component* c, uint64_t stamp_ns) {
  if (arflex_component_state_open(c)) PublishBlock(c, stamp_ns);
  if (!g.sweep_asked) {
    g.sweep_asked = true;
    AskSweep();
  }
}

int Start(struct arflex_component* c, void*) {
  g.have_js = g.have_w = false;
  g.teach_prev = false;
  g.save_prev = arflex_param_bool(c, g.p_save);
  g.v.setZero();
  return 0;
}

void Record(struct arflex_component* c, bool force) {
  if (g.saving.load(std::memory_order_acquire)) return;  // the writer is reading the buffer
  if (g.count > 0 && !force) {
    const double d = (g.q_ref - g.points[g.count - 1]).cwiseAbs().maxCoeff();
    if (d < arflex_param_f64(c, g.p_step)) return;
  }
  if (g.count > 0 && force && (g.q_ref - g.points[g.count - 1]).cwiseAbs().maxCoeff() == 0) return;
  if (g.count >= kMaxPoints) {
    g.dropped++;
    return;
  }
  RecAppend(g.q_ref);
}

int Update(struct arflex_component* c, void*, uint64_t release_ns) {
  if (arflex_input_state_read(g.in_js, &g.js, sizeof(g.js), nullptr) == 1) g.have_js = true;
  if (arflex_input_state_read(g.in_w, &g.w, sizeof(g.w), nullptr) == 1) g.have_w = true;
  if (!g.initialized) {
    if (!g.have_js) return 0;  // nothing is commanded before the arm's position is known
    for (int j = 0; j < 6; ++j) {
      g.q_ref[j] = g.js.q[j];
      g.brake_v0[j] = g.js.qd[j];
    }
    g.brake_t = g.brake_v0.cwiseAbs().maxCoeff() > kRestSpeed ? 0.0 : kTakeoverStopS;
    g.initialized = true;
  }
  if (arflex_input_state_read(g.in_safety, &g.safety, sizeof(g.safety), nullptr) == 1)
    g.have_safety = true;
  if (!arflex_input_bound(g.in_safety)) g.have_safety = false;
  // A protective stop (or a bound safety input that has not spoken yet) freezes the arm: it
  // no longer yields to the hand until the guard is reset.
  const bool stopped = arflex_input_bound(g.in_safety) &&
                       (!g.have_safety || g.safety.mode == ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP);
  const double dt = arflex_component_ctl(c)->config.period_ns * 1e-9;
  if (g.brake_t < kTakeoverStopS) {
    // Bringing a moving arm to rest (see kTakeoverStopS); a protective stop ends it where it is
    // (the robot makes its own stop); teach mode begins once the arm is at rest.
    g.brake_t = stopped ? kTakeoverStopS : g.brake_t + dt;
    const double s = std::max(0.0, 1.0 - g.brake_t / kTakeoverStopS);
    if (!stopped) g.q_ref += g.brake_v0 * (s * dt);
  }
  const bool teach = arflex_param_bool(c, g.p_teach) && g.brake_t >= kTakeoverStopS;
  if (teach && !g.teach_prev) {
    // Teach mode begins: a new recording from here, holding the orientation.
    const Eigen::Isometry3d t = g.model.Tcp(g.q_ref);
    g.x = t.translation();
    g.r_hold = t.linear();
    g.v.setZero();
    if (!g.saving.load(std::memory_order_acquire)) RecReset();
    if (g.sweep_asked) AskSweep();  // D63: a new recording, a new look for dead halves' journals
    Record(c, true);
  }
  if (!teach && g.teach_prev) Record(c, true);  // the end point
  g.teach_prev = teach;

  if (teach && stopped) {
    g.v.setZero();
    g.x = g.model.Tcp(g.q_ref).translation();
  } else if (teach) {
    Eigen::Vector3d f_hand = Eigen::Vector3d::Zero();
    if (g.have_w && g.have_js) {
      Q qm;
      for (int j = 0; j < 6; ++j) qm[j] = g.js.q[j];
      const Eigen::Vector3d f(g.w.force[0], g.w.force[1], g.w.force[2]);
      f_hand = g.model.ContactForceWorld(qm, f, arflex_param_f64(c, g.p_payload));
      const double db = arflex_param_f64(c, g.p_deadband), n = f_hand.norm();
      if (n > db)
        f_hand *= 1.0 - db / n;
      else
        f_hand.setZero();
    }
    const double mass = arflex_param_f64(c, g.p_mass), damp = arflex_param_f64(c, g.p_damping);
    const Eigen::Vector3d a = (f_hand - damp * g.v) / mass;
    g.v += a * dt;
    const double vmax = arflex_param_f64(c, g.p_max_speed), vn = g.v.norm();
    if (vn > vmax) g.v *= vmax / vn;
    const Eigen::Vector3d x_next = g.x + g.v * dt;
    Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
    target.translation() = x_next;
    target.linear() = g.r_hold;
    Q q = g.q_ref;
    const double err = g.model.Ik(target, &q, 3);
    bool inside = q.allFinite() && err < 1e-4;
    for (int j = 0; j < 6 && inside; ++j)
      inside = q[j] > g.model.lower(j) && q[j] < g.model.upper(j);
    if (inside) {
      g.q_ref = q;
      g.x = x_next;
    } else {
      g.v.setZero();  // at a joint limit or out of reach: the arm stops yielding that way
    }
    Record(c, false);
  } else {
    g.v.setZero();
  }
  const bool save = arflex_param_bool(c, g.p_save);
  if (save && !g.save_prev && !g.saving.load(std::memory_order_acquire)) {
    g.save_count.store(g.count);
    g.save_slot.store((long)arflex_param_i64(c, g.p_slot));
    g.saving.store(true, std::memory_order_release);
    sem_post(&g.sem);
  }
  g.save_prev = save;

  struct arflex_joint_ref ref;
  ref.t_ns = (int64_t)release_ns;
  ref.seq = ++g.seq;
  for (int j = 0; j < 6; ++j) ref.q[j] = g.q_ref[j];
  const int w = arflex_state_write(g.out, &ref, sizeof(ref));
  Publish(c, release_ns);
  return w;
}

// rt-core safe mode: stop yielding, hold the reference.
int Safe(struct arflex_component* c, void*, enum arflex_safe_mode, bool) {
  g.v.setZero();
  Publish(c, arflex_sys_now_ns());
  return 0;
}

const struct arflex_component_ops kOps = {
    "teach", nullptr, Configure, Start, Update, nullptr, Cleanup, Safe, Adopt,
};

}  // namespace teach

int main(int argc, char** argv) { return arflex_component_main(argc, argv, &teach::kOps); }
