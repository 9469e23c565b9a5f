// teach: the recording's journal, kept by the writer thread (docs/DECISIONS.md D57; teach_internal.h),
// and the sweep of the journals of halves that are gone (D63, teach_sweep.h).
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "teach_internal.h"
#include "teach_sweep.h"

namespace teach {

// ---- the journal (writer thread) ------------------------------------------------------------

bool WriteAll(int fd, const void* buf, size_t len, off_t off) {
  const char* p = static_cast<const char*>(buf);
  while (len) {
    const ssize_t n = pwrite(fd, p, len, off);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    len -= (size_t)n;
    off += n;
  }
  return true;
}

void JournalFail(const char* what) {
  if (!g.journal_failed)
    fprintf(stderr, "teach: the recording's journal %s: %s: %s (an update in a change set will be refused)\n",
            g.journal.c_str(), what, strerror(errno));
  g.journal_failed = true;
}

// Brings the journal file up to the recording: the waypoints first, then the header's count,
// so a reader never finds a count beyond what the file holds (teach_rec_load refuses a size
// that is not header + count waypoints, and the new half retries for a while).

void SyncJournal() {
  // An adopted recording brings its nonce (Adopt writes it before it bumps the episode): the
  // journal is then named after it.
  (void)g.episode.load(std::memory_order_acquire);
  const uint64_t nonce = g.st.rec_nonce;
  if (g.journal_fd >= 0 && nonce != g.journal_nonce) CloseJournal();
  if (g.journal_fd < 0) {
    if (g.journal_failed) return;
    char name[64];
    teach_rec_name(name, sizeof(name), g.pid, nonce);
    g.journal_nonce = nonce;
    g.journal = g.dir + "/" + name;
    if (mkdir(g.dir.c_str(), 0700) != 0 && errno != EEXIST) return JournalFail("its folder");
    g.journal_fd = open(g.journal.c_str(), O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (g.journal_fd < 0) return JournalFail("create");
    if (fchmod(g.journal_fd, 0600) != 0) return JournalFail("chmod");
    // D63: held while this half lives (released by the kernel when it dies, kill -9 too): a
    // sweeper keeps a journal whose lock is held even when its pid looks gone
    if (flock(g.journal_fd, LOCK_EX | LOCK_NB) != 0)
      fprintf(stderr, "teach: the recording's journal %s: lock: %s (a sweep relies on the pid alone)\n",
              g.journal.c_str(), strerror(errno));
    g.journal_count = 0;
    g.journal_episode = ~0u;
  }
  for (int attempt = 0; attempt < 4; ++attempt) {
    const uint32_t ep = g.episode.load(std::memory_order_acquire);
    const uint32_t n = g.pub_count.load(std::memory_order_acquire);
    if (ep == g.journal_episode && n == g.journal_count) return;
    uint32_t from = ep == g.journal_episode && n > g.journal_count ? g.journal_count : 0;
    if (from == 0 && ftruncate(g.journal_fd, TEACH_REC_HEADER + (off_t)n * 48) != 0)
      return JournalFail("truncate");
    if (n > from && !WriteAll(g.journal_fd, g.points[from].data(), (size_t)(n - from) * 48,
                              TEACH_REC_HEADER + (off_t)from * 48))
      return JournalFail("write");
    if (g.episode.load(std::memory_order_acquire) != ep) continue;  // started over meanwhile
    unsigned char hdr[TEACH_REC_HEADER];
    teach_rec_header(hdr, g.pid, g.journal_nonce, n);
    if (!WriteAll(g.journal_fd, hdr, sizeof(hdr), 0)) return JournalFail("write its header");
    g.journal_count = n;
    g.journal_episode = ep;
    return;
  }
}

void CloseJournal() {
  if (g.journal_fd >= 0) {
    close(g.journal_fd);
    g.journal_fd = -1;
    unlink(g.journal.c_str());  // the next half has read it, or nothing needs it
  }
}

// ---- D63: the journals of halves that are gone --------------------------------------------

void AskSweep() {
  g.sweep_pending.store(true, std::memory_order_release);
  sem_post(&g.sem);
}

void Sweep() {
  struct teach_sweep_count n;
  const int r = teach_sweep(
      g.dir.c_str(), g.pid, geteuid(), [](void*, const char* line) { fprintf(stderr, "%s\n", line); }, nullptr, &n);
  if (r == 0 && n.removed + n.kept + n.refused > 0)
    fprintf(stderr, "teach: swept %s: %u journal(s) of halves that are gone removed, %u of running halves kept, %u refused\n",
            g.dir.c_str(), n.removed, n.kept, n.refused);
}

}  // namespace teach
