/*
 * faults.h - the texture windows between guard pages and the crash reports
 * that say what a fault hit (faults.c), shared with worker.c's request loop.
 */
#ifndef WORKER_FAULTS_H
#define WORKER_FAULTS_H

#include <setjmp.h>
#include <signal.h>
#include <stddef.h>
#include <sys/types.h>

#include "protocol.h"

#define GUARD_BYTES ((size_t)1 << 20)

struct window {
    char *body;            /* start of the readable body */
    char *writable;        /* the same bytes, writable, elsewhere */
    size_t capacity;       /* body size */
    char *data;            /* the texels now in it (NULL: none) */
    size_t size;
    int where;             /* face, or WHERE_ALL_FACES */
};

extern char *region;          /* the whole reservation, guards included */
extern size_t region_size;
extern struct window six, one;
extern int one_face, one_placement;   /* what `one` holds */
extern size_t page_size;

int reserve_windows(size_t six_capacity);
int window_fill(struct window *w, const char *src, size_t size, int placement, int where);

/* Set by main (stack overflow attribution), and the pipe through which a
 * path the student passed is copied without faulting. */
extern char *stack_top;
extern size_t stack_limit;
extern int scratch[2];

/* Grading past a fault (faults.c, "crash reports"). */
extern sigjmp_buf lookup_escape;
extern volatile sig_atomic_t in_lookup;
extern pid_t main_tid;
extern struct crash_report last_fault;
extern stack_t our_altstack;

void install_handlers(void);

#endif
