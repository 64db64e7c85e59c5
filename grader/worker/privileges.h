/*
 * privileges.h - what the worker may hold and be (privileges.c): its
 * resource limits, and privilege-drop mode.
 */
#ifndef WORKER_PRIVILEGES_H
#define WORKER_PRIVILEGES_H

#include <sys/resource.h>

void set_limit(int resource, rlim_t soft, rlim_t hard);
/* The limits set before anything else runs (a value < 0, or 0 for as_mb and
 * cpu_s: no limit of that kind); no core files; no priority above nice 0. */
void set_limits(long as_mb, long cpu_s, long nproc, long nofile, long sigpending);

/* chroot into `dir` (NULL: none), then uid/gid for good (uid < 0: keep),
 * no new privileges, not dumpable; 0 on success. */
int drop_privileges(const char *dir, long uid, long gid);
/* 1: the worker now runs in a pid namespace of its own; 0: refused, nothing
 * changed; -1: failed. Only the worker returns. */
int enter_pid_namespace(void);

#endif
