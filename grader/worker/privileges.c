/*
 * privileges.c - what the worker may hold (its resource limits), and
 * privilege-drop mode (a root-started worker without bubblewrap): a folder
 * of its own as root, uid/gid nobody for good, and a pid namespace of its
 * own where the container allows one.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <grp.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "privileges.h"
#include "protocol.h"

void set_limit(int resource, rlim_t soft, rlim_t hard)
{
    struct rlimit r = { soft, hard };
    setrlimit(resource, &r);
}

void set_limits(long as_mb, long cpu_s, long nproc, long nofile, long sigpending)
{
    set_limit(RLIMIT_CORE, 0, 0);
    if (as_mb > 0) set_limit(RLIMIT_AS, (rlim_t)as_mb << 20, (rlim_t)as_mb << 20);
    if (cpu_s > 0) set_limit(RLIMIT_CPU, (rlim_t)cpu_s, (rlim_t)cpu_s + 1);
    if (nproc >= 0) set_limit(RLIMIT_NPROC, (rlim_t)nproc, (rlim_t)nproc);
    /* Each descriptor can pin kernel memory outside RLIMIT_AS (a full pipe
     * holds 64 KiB; F_SETPIPE_SZ is refused by the filter). */
    if (nofile >= 0) set_limit(RLIMIT_NOFILE, (rlim_t)nofile, (rlim_t)nofile);
    /* Each POSIX timer holds a queued signal: this bounds timer_create too. */
    if (sigpending >= 0) set_limit(RLIMIT_SIGPENDING, (rlim_t)sigpending, (rlim_t)sigpending);
    /* No thread may raise its priority: one the grader put at SCHED_IDLE
     * stays there (leaving it needs RLIMIT_NICE to allow nice 0). */
    set_limit(RLIMIT_NICE, 0, 0);
}

/* Privilege-drop mode: a root-started worker locks itself into `dir` (a
 * fresh folder holding only the submission) and becomes uid/gid nobody,
 * for good. */
int drop_privileges(const char *dir, long uid, long gid)
{
    if (dir && (chroot(dir) != 0 || chdir("/") != 0))
        return -1;
    if (uid >= 0) {
        if (setgroups(0, NULL) != 0 || setresgid((gid_t)gid, (gid_t)gid, (gid_t)gid) != 0 ||
            setresuid((uid_t)uid, (uid_t)uid, (uid_t)uid) != 0)
            return -1;
        /* Really gone: root cannot be taken back. */
        if (getuid() != (uid_t)uid || geteuid() != (uid_t)uid || getgid() != (gid_t)gid ||
            (uid != 0 && setresuid(0, 0, 0) == 0)) {
            errno = EPERM;
            return -1;
        }
    }
    /* No setuid program gives anything back, filter or not (under bubblewrap
     * as root the bounding set is not emptied). */
    if (prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0)
        return -1;
    return prctl(PR_SET_DUMPABLE, 0, 0, 0, 0);
}

/* A relay (see enter_pid_namespace): nothing of the worker's, then wait
 * for `child` and end with its status, 128 + n when signal n killed it
 * (bubblewrap's convention, which the grader reads the same way). */
static void relay(pid_t child)
{
    for (int fd = 0; fd < 1024; fd++)
        close(fd);
    int status;
    while (waitpid(child, &status, 0) < 0)
        if (errno != EINTR)
            _exit(EXIT_SETUP);
    _exit(WIFSIGNALED(status) ? 128 + WTERMSIG(status) : WEXITSTATUS(status));
}

/* Privilege-drop mode, where the container allows it: a pid namespace of
 * the worker's own, so it cannot name any other process at all (the uid of
 * its own and the filter already keep it from signalling one). The worker
 * becomes pid 2 under a root pid 1 that only waits (as pid 1 it would
 * ignore the signals it sends itself), and the process the grader started
 * waits for that one. 1: in the namespace; 0: unshare refused, nothing
 * changed; -1: failed. Only the worker returns. */
int enter_pid_namespace(void)
{
#ifdef __linux__
    if (unshare(CLONE_NEWPID) != 0)
        return 0;
    pid_t init = fork();
    if (init < 0)
        return -1;
    if (init > 0)
        relay(init);
    pid_t worker = fork();
    if (worker < 0)
        _exit(EXIT_SETUP);
    if (worker > 0)
        relay(worker);
    /* The namespace ends with its pid 1; the grader's kill reaches all three. */
    return 1;
#else
    return 0;
#endif
}
