/* rt-core internal: the state of an RT half shared by the files of src/component/: component.c
 * (main: arguments, attach, configure, exit), ports.c (declaration and binding), rt.c (the RT
 * thread), commands.c (the mailbox thread), access.c (the component's accessors), state.c (the
 * state block, D41) and supervisor.c (the supervisor's death and the orphan policy). Not
 * installed, not API. */
#ifndef ARFLEX_COMPONENT_INTERNAL_H
#define ARFLEX_COMPONENT_INTERNAL_H

#include <pthread.h>
#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "arflex/component.h"
#include "arflex/mailbox.h"
#include "arflex/task.h"

#define LOAD(p) __atomic_load_n((p), __ATOMIC_ACQUIRE)
#define STORE(p, v) __atomic_store_n((p), (v), __ATOMIC_RELEASE)
#define XCHG(p, v) __atomic_exchange_n((p), (v), __ATOMIC_ACQ_REL)

struct arflex_input {
	char name[ARFLEX_NAME_SIZE];
	char type_name[ARFLEX_TYPE_NAME_SIZE];
	struct arflex_port_type type;
	enum arflex_port_method method;
	struct arflex_port *cur;      /* RT thread's binding (NULL: unbound) */
	struct arflex_port *pending;  /* mailbox -> RT; &unbind_marker = unbind */
	struct arflex_port *retired;  /* RT -> mailbox: to unmap */
	uint32_t pend_seq;            /* mailbox: requests posted */
	uint32_t done_seq;            /* RT: requests taken */
	uint32_t binding;             /* RT: providers taken (arflex_input_binding) */
	bool bound;                   /* mailbox thread's view */
	uint64_t *warnings;           /* the control block's warning counters */
	struct arflex_input_count *count; /* its rejected-value counter in the control block */
};

/* The state block (D41): the half's own state segment, and the one it adopts at START. */
struct arflex_state_block {
	struct arflex_port own;       /* /arflex.<rid>.<inst>.state, producer (configure) */
	bool open;                    /* own is mapped */
	struct arflex_port_type type; /* what own carries */
	char type_name[ARFLEX_TYPE_NAME_SIZE];
	struct arflex_port *src;      /* mailbox: the segment named by ADOPT (read-only) */
	arflex_adopt_prepare_fn prepare; /* D57: mailbox, at the ADOPT (configure sets it) */
	void *buf;                    /* mailbox: one value of src */
	int result;                   /* RT at START: 1 adopted, 0 nothing published yet, < 0 */
	uint64_t seq;                 /* RT: the adopted value's write count */
	uint64_t age_ns;              /* RT: its age when it was adopted */
};

/* The re-adopt of a running half (D61): the mailbox thread maps the segment and posts it, the
 * RT thread takes its newest value at its next cycle boundary, the mailbox thread replies and
 * unmaps. phase: READOPT_IDLE -> POSTED (mailbox) -> TAKING -> DONE (RT) -> IDLE (mailbox); a
 * post not taken by its deadline is withdrawn (POSTED -> IDLE, mailbox) so the RT thread never
 * reads a mapping that is gone. */
enum { READOPT_IDLE, READOPT_POSTED, READOPT_TAKING, READOPT_DONE };
struct arflex_readopt {
	arflex_readopt_fn fn;         /* configure */
	struct arflex_port *src;      /* mailbox maps it; RT reads it while TAKING */
	void *buf;                    /* one value of src (mailbox allocates) */
	uint32_t phase;               /* atomic */
	int result;                   /* RT -> mailbox: the hook's, or -ENODATA / a read error */
	uint64_t seq;                 /* RT: the value's write count */
	uint64_t age_ns;              /* RT: its age when it was taken */
};

struct arflex_component {
	const struct arflex_component_ops *ops;
	const char *name;
	char rid[ARFLEX_ID_MAX + 1];
	char inst[ARFLEX_ID_MAX + 1];
	char ctl_name[ARFLEX_OBJ_NAME_SIZE];
	struct arflex_ctl *ctl;
	struct arflex_mailbox mb;
	struct arflex_task task;
	bool running;
	bool configuring;
	bool safe;                    /* RT thread */
	bool safe_first;
	bool lost_seen;               /* RT thread: this cycle saw SUPERVISOR_LOST */
	bool orphan_safe;             /* RT -> mailbox: a safe cycle ran after the loss */
	bool hb_stale;                /* RT -> mailbox: the windowed heartbeat judgement */
	struct arflex_hb_window hbw;  /* RT thread */
	bool sporadic;                /* released by new samples on inputs[0] (D27) */
	uint32_t clk_binding;         /* RT thread: binding of inputs[0] clk_seen belongs to */
	uint64_t clk_seen;            /* RT thread: write count (hdr->head) of inputs[0] seen */
	uint64_t lost_ns;             /* watcher -> mailbox: when the supervisor was lost */
	bool lost_noticed;            /* mailbox thread */
	bool orphaned;                /* mailbox thread: left the loop as an orphan */
	pthread_t watcher;
	bool watching;                /* main thread: the watcher runs */
	int watch_wake[2];            /* main -> watcher: a byte (or EOF) ends the watch */
	uint64_t token;               /* the manager's mailbox token (0 without the pipe) */
	uint64_t forged_log_ns;       /* mailbox thread: when a forged request was last logged */
	uint64_t forged_unlogged;     /* mailbox thread: forged requests since that log line */
	struct arflex_port outputs[ARFLEX_MAX_OUTPUTS];
	char output_names[ARFLEX_MAX_OUTPUTS][ARFLEX_NAME_SIZE];
	unsigned noutputs;
	struct arflex_input inputs[ARFLEX_MAX_INPUTS];
	unsigned ninputs;
	struct arflex_stats stats_copy;
	struct arflex_state_block state;
	struct arflex_readopt readopt; /* D61 */
	int fault_start_err;          /* test fault (D58): > 0 refuses every START with -it */
	uint64_t fault_crash_after;   /* test fault (D68): > 0 raises SIGSEGV in that update after a START */
	uint64_t fault_updates;       /* RT thread: updates run since the last START (for the test faults) */
	uint64_t fault_late_every;    /* test fault (D73): > 0 makes every that-many-th update after a START end late */
};

/* One log line on stderr, one write (component.c). */
void arflex_comp_log(const struct arflex_component *c, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));

/* ports.c: an output's object name; the inputs' bindings: taken by the RT thread at a cycle
 * boundary, by the mailbox thread after a STOP (and the replaced ones unmapped), BIND/UNBIND;
 * closing every port at exit. */
int arflex_comp_output_obj_name(const struct arflex_component *c, const char *port, char *name,
				size_t size);
void arflex_comp_take_bindings(struct arflex_component *c);
void arflex_comp_retire_bindings(struct arflex_component *c);
int arflex_comp_bind_cmd(struct arflex_component *c, struct arflex_msg *m);
void arflex_comp_close_ports(struct arflex_component *c);

/* rt.c: the task's hooks (struct arflex_task_opts; the poll only for a sporadic half, D27). */
int arflex_comp_rt_cycle(void *arg, uint64_t release_ns);
int arflex_comp_rt_poll(void *arg, uint64_t now, uint64_t *events);
int arflex_comp_rt_start(void *arg);
int arflex_comp_rt_stop(void *arg);

/* commands.c: the mailbox thread's loop until SHUTDOWN, *@signaled or the orphan policy; STOP
 * (also at the end, when still running); the short wait and the deadline of a request the RT
 * thread takes at its cycle boundary (SET_PARAM, BIND). */
void arflex_comp_serve_loop(struct arflex_component *c, const volatile sig_atomic_t *signaled);
int arflex_comp_stop(struct arflex_component *c);
void arflex_comp_wait_short(void);
uint64_t arflex_comp_apply_deadline(const struct arflex_component *c);

/* state.c (D41): the ADOPT command (mailbox thread, not while running), the adoption at
 * START (RT thread, in the start hook's place), its report and release after START (mailbox
 * thread), and closing everything at exit. */
int arflex_comp_adopt_cmd(struct arflex_component *c, const struct arflex_msg *m);
int arflex_comp_adopt_at_start(struct arflex_component *c);
void arflex_comp_adopt_done(struct arflex_component *c);
void arflex_comp_state_close(struct arflex_component *c);

/* readopt.c (D61): READOPT (mailbox thread, while running: post, wait for the RT thread, reply,
 * unmap) and its taking at a cycle boundary (RT thread: no blocking, allocation or printing). */
int arflex_comp_readopt_cmd(struct arflex_component *c, const struct arflex_msg *m);
void arflex_comp_readopt_take(struct arflex_component *c);
/* D70: ARFLEX_FLAG_READOPT when configure registered a re-adopt hook (main thread, before READY). */
void arflex_comp_readopt_advertise(struct arflex_component *c);

/* supervisor.c (ABI.md 6.2, DECISIONS.md D10) */
#define ARFLEX_ORPHAN_POLL_NS 10000000u /* mailbox wakes every 10 ms once the supervisor is lost */
int arflex_comp_read_token(struct arflex_component *c);
int arflex_comp_watch_start(struct arflex_component *c);
void arflex_comp_watch_stop(struct arflex_component *c);
bool arflex_comp_orphan_done(struct arflex_component *c);
void arflex_comp_unlink_own(struct arflex_component *c, unsigned noutputs);

#endif /* ARFLEX_COMPONENT_INTERNAL_H */
