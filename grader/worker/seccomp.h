/*
 * seccomp.h - the worker's seccomp filter (seccomp.c): a small BPF assembler
 * and the policy written with it, installed once before the submission loads.
 */
#ifndef WORKER_SECCOMP_H
#define WORKER_SECCOMP_H

#include <stdint.h>

/* Keep [first, end) mapped as it is: the filter traps any call that would
 * unmap, remap or reprotect it. */
void protect(uint64_t first, uint64_t end);
/* protect() every file or kernel mapping in /proc/self/maps (before any chroot). */
int collect_protected_ranges(void);
/* No new privileges, then the filter; 0 on success. */
int install_filter(void);

/* For the SIGSYS report (faults.c): the name of a trapped syscall, and of
 * the fcntl or ioctl command that made one trap. */
const char *trapped_syscall_name(long nr);
const char *command_name(long nr, unsigned command);

#endif
