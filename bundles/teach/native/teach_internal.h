// teach's RT half, shared by its files (teach.cc: the component; teach_journal.cc: the
// recording's journal on the writer thread, and the sweep of dead halves' journals (D63); teach_handover.cc: taking a recording over from an
// old half, D57). One process, one State.
#pragma once

#include <pthread.h>
#include <semaphore.h>

#include <atomic>
#include <cstdint>
#include <string>

#include "arflex/component.h"
#include "arflex_types/joint_state.h"
#include "arflex_types/safety_state.h"
#include "arflex_types/teach_state.h"
#include "arflex_types/wrench.h"
#include "cellkin.h"
#include "teach_rec.h"

namespace teach {

using arflex::cellkin::Q;
static_assert(sizeof(Q) == 6 * sizeof(double), "a waypoint is 6 doubles, contiguous");
constexpr size_t kMaxPoints = TEACH_REC_MAX;
static_assert(TEACH_REC_TAIL == ARFLEX_TEACH_STATE_TAIL_MAX, "the tail of arflex.TeachState");
static_assert(sizeof(((struct arflex_teach_state*)nullptr)->tail) == TEACH_REC_TAIL * 48, "tail");
// Taking over a moving arm (docs/DECISIONS.md D35: teach replaces trajectory while the arm
// moves): the reference starts at the measured joints and, from the measured joint speeds,
// ramps the speed down to zero over kTakeoverStopS (trajectory's default stop_time), along the
// path the arm was on. Holding the first measured pose at once would leave the stop to the
// servo, which brakes a 0.2 rad/s base joint hard enough for the force guard to read 800 N and
// latch a protective stop (ChangeSetIT, before this). An arm slower than kRestSpeed is at rest.
constexpr double kTakeoverStopS = 0.3;
constexpr double kRestSpeed = 1e-3;

struct State {
  arflex::cellkin::Model model;
  struct arflex_port* out = nullptr;
  struct arflex_input* in_js = nullptr;
  struct arflex_input* in_w = nullptr;
  struct arflex_input* in_safety = nullptr;
  struct arflex_safety_state safety{};
  bool have_safety = false;
  int p_teach, p_mass, p_damping, p_deadband, p_max_speed, p_payload, p_step, p_save, p_slot;
  struct arflex_joint_state js{};
  struct arflex_wrench w{};
  bool have_js = false, have_w = false, initialized = false;
  bool teach_prev = false, save_prev = false;
  Q q_ref = Q::Zero();
  Q brake_v0 = Q::Zero();        // measured joint speeds when the reference was taken over
  double brake_t = kTakeoverStopS;  // time into the take-over ramp; >= kTakeoverStopS: none
  Eigen::Vector3d x = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
  Eigen::Matrix3d r_hold = Eigen::Matrix3d::Identity();
  uint64_t seq = 0;
  // recording (RT thread writes points and count; the writer reads under `saving`)
  Q* points = nullptr;
  size_t count = 0;
  std::atomic<bool> saving{false};
  std::atomic<size_t> save_count{0};
  std::atomic<long> save_slot{0};
  std::atomic<bool> quit{false};
  std::atomic<uint64_t> saved{0}, save_errors{0}, dropped{0};
  sem_t sem;
  pthread_t writer;
  bool writer_started = false;
  std::string dir;
  // D57: the state block, the recording's chain and journal
  struct arflex_teach_state st{};  // RT: the recording's part is kept up to date, published
  uint64_t* chain = nullptr;       // chain[i]: over the first i waypoints (teach_rec.h)
  uint32_t pid = 0;
  std::atomic<uint32_t> pub_count{0};  // waypoints the writer may copy
  std::atomic<uint32_t> episode{0};    // changes when the recording starts over
  int journal_fd = -1;                 // writer thread
  std::string journal;                 // its path
  uint32_t journal_count = 0, journal_episode = ~0u;
  uint64_t journal_nonce = 0;
  bool journal_failed = false;
  bool preloaded = false;          // mailbox: the old half's journal read (adopt_prepare)
  uint32_t preload_count = 0;
  char why[512] = {0};             // RT: why the adopt hook refused (printed by the writer)
  std::atomic<bool> why_pending{false};
  // D63: the journals of halves that are gone are swept by the writer thread once this half has
  // started (its state block published: it no longer names a dead half's journal) and whenever
  // a new recording begins
  bool sweep_asked = false;              // RT
  std::atomic<bool> sweep_pending{false};
};

extern State g;

// the recording (teach.cc, RT thread)
void RecReset();
void RecAppend(const Q& q);
// the journal (teach_journal.cc, writer thread)
void SyncJournal();
void CloseJournal();
void AskSweep();  // RT safe (an atomic store and sem_post)
void Sweep();     // writer thread
// the hand-over (teach_handover.cc): the ADOPT on the mailbox thread, the START on the RT thread
int AdoptPrepare(struct arflex_component* c, void* user, const struct arflex_adopted_state* s);
int Adopt(struct arflex_component* c, void* user, const struct arflex_adopted_state* s);

}  // namespace teach
