// teach: taking the motion and the recording over from an old half (docs/DECISIONS.md D57;
// teach_internal.h).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "teach_internal.h"

namespace teach {

// ---- D57: handing over to a new version -----------------------------------------------------

bool Claim(const struct arflex_adopted_state* s, const struct arflex_teach_state** v,
           struct teach_rec_claim* claim) {
  if (strcmp(s->type_name, ARFLEX_TYPE_TEACH_STATE_NAME) != 0 || s->major != 1 ||
      s->length < sizeof(struct arflex_teach_state))
    return false;
  *v = static_cast<const struct arflex_teach_state*>(s->data);
  const struct arflex_teach_state* t = *v;
  memset(claim, 0, sizeof(*claim));
  claim->key[0] = t->rec_key[0];
  claim->key[1] = t->rec_key[1];
  claim->nonce = t->rec_nonce;
  claim->pid = t->journal_pid;
  claim->count = t->rec_count;
  claim->hash = t->rec_hash;
  claim->tail_first = t->tail_first;
  claim->tail_count = t->tail_count;
  claim->tail_hash = t->tail_hash;
  claim->tail = t->tail;
  return true;
}

struct teach_rec_loaded Loaded() {
  struct teach_rec_loaded l;
  l.points = reinterpret_cast<double(*)[6]>(g.points);
  l.chain = g.chain;
  l.count = g.preload_count;
  return l;
}

// Mailbox thread, at the ADOPT: reads the old half's journal (blocking I/O belongs here) and
// checks it against the state block of now. Retries for up to ~200 ms: the old half's writer
// may be between a journal's waypoints and its header.
int AdoptPrepare(struct arflex_component*, void*, const struct arflex_adopted_state* s) {
  const struct arflex_teach_state* t;
  struct teach_rec_claim claim;
  char why[512];
  g.preloaded = false;
  if (!Claim(s, &t, &claim)) {
    fprintf(stderr, "teach: cannot take over the state block %s %u.%u (%u bytes): not arflex.TeachState 1.x\n",
            s->type_name, s->major, s->minor, s->length);
    return -EPROTOTYPE;
  }
  int r = teach_rec_check_claim(&claim, why, sizeof(why));
  if (r == 0 && claim.tail_first == 0) {
    g.preload_count = 0;  // the state block's tail holds the whole recording
    g.preloaded = true;
    fprintf(stderr, "teach: the recording (%u waypoints) is all in the state block\n", claim.count);
    return 0;
  }
  if (r != 0) {
    fprintf(stderr, "teach: cannot take over the recording of %u waypoints: %s\n", claim.count, why);
    return r;
  }
  char name[64];
  teach_rec_name(name, sizeof(name), claim.pid, claim.nonce);
  const std::string path = g.dir + "/" + name;
  for (int attempt = 0; attempt < 40; ++attempt) {
    if (attempt) usleep(5000);
    struct teach_rec_loaded l = Loaded();
    r = teach_rec_load(path.c_str(), &claim, &l, why, sizeof(why));
    if (r == 0) r = teach_rec_join(&l, &claim, why, sizeof(why));
    if (r == 0) {
      g.preload_count = l.count;
      g.preloaded = true;
      fprintf(stderr, "teach: the recording read from %s: %u waypoints, checked against the state block\n",
              path.c_str(), l.count);
      return 0;
    }
    if (r == -EPERM) break;  // nothing a wait can mend
  }
  fprintf(stderr, "teach: cannot take over the recording of %u waypoints: %s\n", claim.count, why);
  return r;
}

// RT thread, at the START after an ADOPT: the motion and the recording, whole or not at all.
// No I/O: the journal was read by AdoptPrepare; the join is O(tail).
int Adopt(struct arflex_component*, void*, const struct arflex_adopted_state* s) {
  const struct arflex_teach_state* t;
  struct teach_rec_claim claim;
  if (!Claim(s, &t, &claim)) {
    snprintf(g.why, sizeof(g.why), "the state block %s %u.%u is not arflex.TeachState 1.x", s->type_name,
             s->major, s->minor);
    g.why_pending.store(true);
    sem_post(&g.sem);
    return -EPROTOTYPE;
  }
  if (!arflex_teach_state_valid(t)) {
    snprintf(g.why, sizeof(g.why), "the state block's motion is out of its bounds (a non-finite number)");
    g.why_pending.store(true);
    sem_post(&g.sem);
    return -EINVAL;
  }
  int r;
  {
    // Without a journal read at the ADOPT only a recording that is all in the tail can be taken
    // (teach_rec_join refuses the rest: -ENODATA).
    struct teach_rec_loaded l = Loaded();
    if (!g.preloaded) l.count = 0;
    r = teach_rec_join(&l, &claim, g.why, sizeof(g.why));
    if (r == 0) {
      g.count = l.count;
      g.st.rec_key[0] = claim.key[0];
      g.st.rec_key[1] = claim.key[1];
      g.st.rec_nonce = claim.nonce;  // the chain goes on; the journal is this half's own (pid)
      g.st.rec_count = claim.count;
      g.st.rec_hash = claim.hash;
      g.st.tail_first = claim.tail_first;
      g.st.tail_count = claim.tail_count;
      g.st.tail_hash = claim.tail_hash;
      memcpy(g.st.tail, t->tail, sizeof(g.st.tail));
    }
  }
  g.preloaded = false;
  if (r < 0) {
    g.why_pending.store(true);
    sem_post(&g.sem);
    return r;
  }
  for (int j = 0; j < 6; ++j) {
    g.q_ref[j] = t->q_ref[j];
    g.brake_v0[j] = t->brake_v0[j];
  }
  g.brake_t = t->brake_t;
  for (int i = 0; i < 3; ++i) {
    g.x[i] = t->x[i];
    g.v[i] = t->v[i];
    for (int k = 0; k < 3; ++k) g.r_hold(i, k) = t->r_hold[3 * i + k];
  }
  g.seq = t->out_seq;
  g.initialized = (t->flags & ARFLEX_TEACH_STATE_FLAG_INITIALIZED) != 0;
  g.teach_prev = (t->flags & ARFLEX_TEACH_STATE_FLAG_TEACH) != 0;  // the recording goes on
  g.pub_count.store((uint32_t)g.count, std::memory_order_release);
  g.episode.fetch_add(1, std::memory_order_acq_rel);  // the writer writes its journal whole
  sem_post(&g.sem);
  return 0;
}

}  // namespace teach
