/* Shared test helpers: unique ids and the no-leak check every test ends with. Everything but
 * th_assert_clean is in arflex_testkit (no test framework), the one kit of every native test,
 * C or C++ (rt-core, bundles/<name>/native, simulator); th_assert_clean needs cmocka
 * (arflex_test_helper). */
#ifndef ARFLEX_TEST_HELPER_H
#define ARFLEX_TEST_HELPER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Writes "t<tag>-<pid>" (a valid runtime id, unique per test process) into @buf. */
void th_rid(char *buf, size_t size, const char *tag);

/* Counts /dev/shm/arflex.<rid>.* and /dev/mqueue/arflex.<rid>.* entries and the queues
 * registered with th_track, printing each. */
int th_leftovers(const char *rid);

/* True when this process has no child (reaped or not). */
bool th_no_children(void);

/* Number of threads of this process, once any thread just joined has left (1 s at most). */
int th_threads(void);

/* Registers the message queues of (@rid, @inst) for th_leftovers: /dev/mqueue is not always
 * mounted (containers), so the queues are also probed by name with mq_open. */
void th_track(const char *rid, const char *inst);

/* Asserts (cmocka) no leftover objects of @rid, no child process, a single thread. */
void th_assert_clean(const char *rid);

/* Removes leftovers of @rid (after a failed test, so the next one starts clean). */
void th_sweep(const char *rid);

/* Reads a whole small file into @buf (NUL-terminated). Returns bytes or -1. */
long th_read_file(const char *path, char *buf, size_t size);

#ifdef __cplusplus
}
#endif

#endif
