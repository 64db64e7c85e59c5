/*
 * privileges.h - privilege-drop mode (privileges.c).
 */
#ifndef WORKER_PRIVILEGES_H
#define WORKER_PRIVILEGES_H

/* chroot into `dir` (NULL: none), then uid/gid for good (uid < 0: keep),
 * no new privileges, not dumpable; 0 on success. */
int drop_privileges(const char *dir, long uid, long gid);
/* 1: the worker now runs in a pid namespace of its own; 0: refused, nothing
 * changed; -1: failed. Only the worker returns. */
int enter_pid_namespace(void);

#endif
