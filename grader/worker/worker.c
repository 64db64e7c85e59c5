/*
 * worker.c - the only process that runs student code.
 *
 *   worker [--as-mb N] [--cpu-s N] [--fsize N] [--nproc N] [--texture-bytes N]
 *          [--chroot DIR --uid N --gid N [--pid-namespace]] [--no-seccomp] [--check-drop]
 *          [--progress-fd N]
 *          REQUEST_FD RESPONSE_FD SUBMISSION.so
 *
 * Order matters: limits, signal handlers (on an alternate stack, so a stack
 * overflow is reported too), the C++ runtime preloaded, the texture windows
 * reserved, privileges dropped (privilege-drop mode: chroot into a folder
 * holding only the submission, then uid/gid nobody), the seccomp filter, a
 * SANDBOXED message (the last one the grader can trust: no student code has
 * run yet), and only then dlopen() the submission, so its static
 * initialisers already run under all of them.
 * Requests arrive on REQUEST_FD and answers leave on RESPONSE_FD (a private
 * pipe pair: student code may print to fds 1 and 2, which the grader
 * captures). The protocol is described in README.md beside this file and
 * mirrored in protocol.py, which validates every reply.
 *
 * Textures live in two fixed windows reserved once before the filter: a
 * read-only MAP_SHARED view of a memfd between PROT_NONE guards, one for the
 * six faces and one for the single face readTexture gets. Texels are written
 * with pwrite() on the memfd, so the windows never change after start-up, and
 * the filter refuses mprotect/munmap/mremap/madvise/mmap(MAP_FIXED) on them
 * (and on every library's code and relocations), so a guard cannot be
 * switched off from inside. The texels end where a guard starts ("end") or
 * start where one ends ("start"). A SIGSEGV inside a guard is reported as an
 * out-of-bounds read of that buffer, with the distance in bytes. Nothing
 * student-written is linked into this file.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <grp.h>
#include <setjmp.h>
#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <ucontext.h>
#include <unistd.h>

#ifdef __linux__
#include <linux/audit.h>
#include <linux/filter.h>
#include <linux/seccomp.h>
#include <linux/sockios.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#endif

#include "../shim/submission_abi.h"

/* ---- protocol (keep in step with protocol.py) ---------------------------- */

#define REQUEST_MAGIC 0x4b574d45u  /* "EMWK" */
#define RESPONSE_MAGIC 0x524b4d45u /* "EMKR" */

enum { OP_SET_FACES = 1, OP_FETCH = 2, OP_READ_TEXTURE = 3, OP_TIME_FETCH = 4,
       OP_LOAD_CROSS = 5, OP_QUIT = 6, OP_FETCH_WHOLE = 7 };
enum { ST_OK = 0, ST_EXCEPTION = 1, ST_ARGUMENT = 2, ST_CRASH = 3, ST_LOAD_ERROR = 4,
       ST_READY = 5, ST_BAD_REQUEST = 6, ST_SANDBOXED = 7, ST_SETUP_ERROR = 8, ST_FAULTS = 9 };
enum { CAUSE_SIGNAL = 0, CAUSE_GUARD_AFTER = 1, CAUSE_GUARD_BEFORE = 2,
       CAUSE_STACK_OVERFLOW = 3, CAUSE_CPU_LIMIT = 4, CAUSE_FORBIDDEN_SYSCALL = 5,
       CAUSE_TEXTURE_WRITE = 6 };
enum { PLACE_END = 0, PLACE_START = 1 };
/* Bits of the SANDBOXED message's count: what held besides the filter. */
enum { SANDBOXED_PID_NAMESPACE = 1 };
enum { WHERE_ALL_FACES = -1 };

/* Exit codes, for when the grader sees the status but not the report. */
enum { EXIT_CRASH = 70, EXIT_LOAD = 71, EXIT_PROTOCOL = 72, EXIT_SETUP = 73 };

struct header {
    uint32_t magic, op;
    uint64_t count, payload_bytes;
};

struct crash_report {      /* the ST_CRASH payload, exactly 256 bytes */
    int32_t signo, si_code, cause, where; /* where: face, WHERE_ALL_FACES or syscall nr */
    int64_t distance;      /* bytes past the end / before the start of the buffer */
    uint64_t address;      /* faulting address (si_addr) */
    char text[224];        /* syscall name and argument, NUL padded */
};

static int request_fd = -1, response_fd = -1;

/* Progress: FETCH and READ_TEXTURE evaluate one input per submission call and
 * store the index of the input about to be evaluated here, in a page shared
 * with the grader (--progress-fd, a memfd it created), so after a crash or a
 * timeout the grader can read which input was running. The submission can
 * write this page too: the grader treats it as a hint and confirms it. */
static uint64_t progress_dummy;
static volatile uint64_t *progress = &progress_dummy;

/* ---- writing replies (async-signal-safe: used from handlers) ------------- */

/* Raw syscalls, not write(): glibc's write() is a pthread cancellation
 * point, and a submission that cancelled its own thread could otherwise
 * unwind out of our crash handler into its own cleanup code. */
static int write_all(int fd, const void *data, size_t size)
{
    const char *p = data;
    while (size > 0) {
        ssize_t n = syscall(__NR_write, fd, p, size);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return -1;
        p += n;
        size -= (size_t)n;
    }
    return 0;
}

static void reply(uint32_t status, uint64_t count, const void *payload, uint64_t size)
{
    struct header h = { RESPONSE_MAGIC, status, count, size };
    if (write_all(response_fd, &h, sizeof h) != 0 ||
        (size > 0 && write_all(response_fd, payload, size) != 0))
        for (;;)
            syscall(__NR_exit_group, EXIT_PROTOCOL);
}

static void reply_text(uint32_t status, const char *text)
{
    reply(status, 0, text, strlen(text));
}

/* ---- texture windows ---------------------------------------------------- */

/* One reservation, fixed for the worker's life:
 *
 *   [guard][six-face body][guard][one-face body][guard]
 *
 * The grader sizes the six-face body for the faces it will send (one worker
 * per face size), so texels placed at its end start within a page of the
 * leading guard too, as the one-face body's do for one face.
 * Guards are PROT_NONE; bodies are read-only MAP_SHARED views of one memfd
 * (the six-face body at file offset 0, the one-face body right after it).
 * Texels are written through a second, writable view of the memfd elsewhere
 * (pwrite would meet RLIMIT_FSIZE), so no mapping changes after the filter is
 * installed, and the filter refuses any call that would change one. */
#define GUARD_BYTES ((size_t)1 << 20)

struct window {
    char *body;            /* start of the readable body */
    char *writable;        /* the same bytes, writable, elsewhere */
    size_t capacity;       /* body size */
    char *data;            /* the texels now in it (NULL: none) */
    size_t size;
    int where;             /* face, or WHERE_ALL_FACES */
};

static char *region;       /* the whole reservation, guards included */
static size_t region_size;
static struct window six, one;
static int one_face = -1, one_placement = -1;   /* what `one` holds */
static size_t page_size;

static size_t round_pages(size_t n)
{
    return (n + page_size - 1) / page_size * page_size;
}

/* Reserve the windows (before the filter and RLIMIT_FSIZE). */
static int reserve_windows(size_t six_capacity)
{
    size_t six_body = round_pages(six_capacity ? six_capacity : page_size);
    size_t one_body = round_pages((six_body + 5) / 6);
    size_t file_size = six_body + one_body;
    region_size = 3 * GUARD_BYTES + six_body + one_body;
    int fd = (int)syscall(__NR_memfd_create, "textures", MFD_CLOEXEC);
    if (fd < 0 || ftruncate(fd, (off_t)file_size) != 0)
        return -1;
    region = mmap(NULL, region_size, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    char *writable = mmap(NULL, file_size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    if (region == MAP_FAILED || writable == MAP_FAILED)
        return -1;
    six = (struct window){ region + GUARD_BYTES, writable, six_body, NULL, 0, WHERE_ALL_FACES };
    one = (struct window){ six.body + six_body + GUARD_BYTES, writable + six_body, one_body, NULL, 0, 0 };
    if (mmap(six.body, six_body, PROT_READ, MAP_SHARED | MAP_FIXED, fd, 0) == MAP_FAILED ||
        mmap(one.body, one_body, PROT_READ, MAP_SHARED | MAP_FIXED, fd, (off_t)six_body) == MAP_FAILED)
        return -1;
    close(fd);   /* the mappings keep the memory; no fd left for the submission to find */
    return 0;
}

/* Put `size` bytes into window `w`, ending where its trailing guard starts
 * ("end") or starting where its leading guard ends ("start"); the rest of the
 * body reads as zeros (no texels of an earlier call). */
static int window_fill(struct window *w, const char *src, size_t size, int placement, int where)
{
    if (size > w->capacity)
        return -1;
    if (w->data)
        memset(w->writable + (w->data - w->body), 0, w->size);
    size_t offset = placement == PLACE_END ? w->capacity - size : 0;
    memcpy(w->writable + offset, src, size);
    w->data = w->body + offset;
    w->size = size;
    w->where = where;
    return 0;
}

/* ---- crash reports ------------------------------------------------------- */

static char *stack_top;    /* near the top of the main thread's stack */
static size_t stack_limit;

/* Grading past a fault: while the main thread is inside one submission call
 * of FETCH's or READ_TEXTURE's per-input loop (in_lookup), a fault that only
 * that input caused (SIGSEGV, SIGBUS, SIGFPE, SIGILL) jumps back to the loop
 * instead of ending the worker: the input is reported as crashed, with its
 * crash report, and the loop goes on with the next one. Nothing of the
 * worker's changes: the guard pages stay as they are, the signal mask and
 * our alternate stack are set again after the jump. A crash-heavy
 * submission then costs about what a correct one does, where each crash used
 * to cost a fresh worker and the narrowing down (issue 19). */
static sigjmp_buf lookup_escape;
static volatile sig_atomic_t in_lookup;
static pid_t main_tid;
static struct crash_report last_fault;
static stack_t our_altstack;

static void report_crash(const struct crash_report *r)
{
    if (in_lookup && (r->signo == SIGSEGV || r->signo == SIGBUS || r->signo == SIGFPE || r->signo == SIGILL) &&
        r->cause != CAUSE_FORBIDDEN_SYSCALL && syscall(__NR_gettid) == main_tid) {
        in_lookup = 0;
        last_fault = *r;
        siglongjmp(lookup_escape, 1);
    }
    reply(ST_CRASH, 0, r, sizeof *r);
    for (;;)
        syscall(__NR_exit_group, EXIT_CRASH);
}

static void on_fault(int signo, siginfo_t *info, void *context)
{
    (void)context;
    struct crash_report r;
    memset(&r, 0, sizeof r);
    r.signo = signo;
    r.si_code = info->si_code;
    r.cause = CAUSE_SIGNAL;
    r.where = WHERE_ALL_FACES;
    char *addr = info->si_addr;
    r.address = (uint64_t)(uintptr_t)addr;
    if (signo == SIGXCPU) {
        r.cause = CAUSE_CPU_LIMIT;
        report_crash(&r);
    }
    if ((signo == SIGSEGV || signo == SIGBUS) && region && addr >= region && addr < region + region_size) {
        /* The middle guard: the nearer body's. */
        const struct window *w = addr < six.body + six.capacity + GUARD_BYTES / 2 ? &six : &one;
        r.where = w->where;
        if (addr >= w->body && addr < w->body + w->capacity) {
            r.cause = CAUSE_TEXTURE_WRITE;   /* readable: only a write faults here */
            r.distance = w->data ? addr - w->data : 0;
        } else if (!w->data || addr < w->data) {
            r.cause = CAUSE_GUARD_BEFORE;
            r.distance = (w->data ? w->data : w->body) - addr;
        } else {
            r.cause = CAUSE_GUARD_AFTER;
            r.distance = addr - (w->data + w->size);
        }
        report_crash(&r);
    }
    if (signo == SIGSEGV || signo == SIGBUS) {
        /* A fault about one stack-size below the top of the stack. */
        size_t depth = (size_t)(stack_top - addr);
        if (signo == SIGSEGV && addr <= stack_top && depth <= stack_limit + (1u << 20) &&
            depth + (1u << 20) >= stack_limit)
            r.cause = CAUSE_STACK_OVERFLOW;
    }
    report_crash(&r);
}

#ifdef __linux__
struct syscall_name { long nr; const char *name; };

/* Every syscall the filter refuses by trapping, with its name for the report. */
static const struct syscall_name forbidden_names[] = {
#define NAME(n) { __NR_##n, #n },
#ifdef __NR_fork
    NAME(fork) NAME(vfork) NAME(open) NAME(creat) NAME(unlink) NAME(rename)
    NAME(rmdir) NAME(mkdir) NAME(link) NAME(symlink) NAME(chmod) NAME(chown)
    NAME(lchown) NAME(mknod)
#endif
    NAME(clone) NAME(execve) NAME(execveat) NAME(socket) NAME(socketpair)
    NAME(connect) NAME(bind) NAME(listen) NAME(ptrace) NAME(kill) NAME(tkill)
    NAME(tgkill) NAME(openat) NAME(unlinkat) NAME(renameat) NAME(renameat2)
    NAME(mkdirat) NAME(linkat) NAME(symlinkat) NAME(fchmodat) NAME(fchownat)
    NAME(mknodat) NAME(truncate) NAME(mount) NAME(umount2) NAME(pivot_root)
    NAME(chroot) NAME(unshare) NAME(setns) NAME(process_vm_readv)
    NAME(process_vm_writev) NAME(io_uring_setup) NAME(bpf) NAME(perf_event_open)
    NAME(userfaultfd) NAME(keyctl) NAME(add_key) NAME(request_key) NAME(reboot)
    NAME(init_module) NAME(finit_module) NAME(delete_module) NAME(kexec_load)
    NAME(memfd_create) NAME(remap_file_pages) NAME(shmat) NAME(process_madvise)
    NAME(pidfd_open) NAME(pidfd_send_signal) NAME(pidfd_getfd) NAME(rt_sigqueueinfo)
    NAME(rt_tgsigqueueinfo) NAME(seccomp) NAME(kcmp) NAME(name_to_handle_at)
    NAME(open_by_handle_at) NAME(fanotify_init) NAME(prctl) NAME(fcntl) NAME(ioctl)
    /* System V and POSIX IPC outlive the worker and are shared between
     * workers outside bubblewrap (privilege-drop): none. */
    NAME(shmget) NAME(msgget) NAME(semget) NAME(mq_open)
    /* The machine's state: clock, log, accounting, swap, names, I/O ports
     * (most need privileges the worker lacks in a sandbox; all matter in
     * unsafe mode), and personality (READ_IMPLIES_EXEC would get round W^X). */
    NAME(settimeofday) NAME(clock_settime) NAME(clock_adjtime) NAME(adjtimex) NAME(syslog)
    NAME(acct) NAME(swapon) NAME(swapoff) NAME(sethostname) NAME(setdomainname) NAME(quotactl)
    NAME(vhangup) NAME(personality) NAME(sync) NAME(syncfs)
#ifdef __NR_iopl
    NAME(iopl) NAME(ioperm)
#endif
    /* Refused only on the grader's memory (protected ranges) or for W^X. */
    NAME(mprotect) NAME(pkey_mprotect) NAME(munmap) NAME(madvise) NAME(mmap) NAME(mremap)
#undef NAME
};

static int scratch[2] = { -1, -1 };

/* Copy a string from an address the student passed, without faulting: the
 * kernel copies through a pipe and fails with EFAULT on a bad address. */
static void copy_user_string(const char *src, char *out, size_t out_size)
{
    size_t n = 0;
    char c;
    while (src && n + 1 < out_size && scratch[0] >= 0) {
        if (syscall(__NR_write, scratch[1], src + n, 1) != 1 || syscall(__NR_read, scratch[0], &c, 1) != 1 || c == 0)
            break;
        out[n++] = c;
    }
    out[n] = 0;
}

static void append(char *out, size_t out_size, const char *text)
{
    size_t n = strlen(out);
    while (*text && n + 1 < out_size)
        out[n++] = *text++;
    out[n] = 0;
}

/* fcntl and ioctl commands that choose which process gets a signal (SIGIO,
 * or any signal with F_SETSIG): refused, so a worker can signal no one. */
static const struct syscall_name signal_commands[] = {
    { F_SETOWN, "F_SETOWN" }, { F_SETOWN_EX, "F_SETOWN_EX" }, { F_SETSIG, "F_SETSIG" },
    { F_NOTIFY, "F_NOTIFY" }, { F_SETLEASE, "F_SETLEASE" }, { F_SETFL, "F_SETFL with O_ASYNC" },
};
static const struct syscall_name signal_ioctls[] = {
    { FIOSETOWN, "FIOSETOWN" }, { SIOCSPGRP, "SIOCSPGRP" }, { TIOCSPGRP, "TIOCSPGRP" }, { FIOASYNC, "FIOASYNC" },
};

static const char *command_name(long nr, unsigned command)
{
    const struct syscall_name *names = nr == __NR_fcntl ? signal_commands : signal_ioctls;
    size_t count = nr == __NR_fcntl ? sizeof signal_commands / sizeof signal_commands[0]
                                    : sizeof signal_ioctls / sizeof signal_ioctls[0];
    for (size_t i = 0; i < count; i++)
        if ((unsigned)names[i].nr == command)
            return names[i].name;
    return "(a command outside the allowed list)";
}

static void on_forbidden_syscall(int signo, siginfo_t *info, void *context)
{
    struct crash_report r;
    memset(&r, 0, sizeof r);
    r.signo = signo;
    r.si_code = info->si_code;
    r.cause = CAUSE_FORBIDDEN_SYSCALL;
    r.where = info->si_syscall;
    const char *name = "unknown";
    for (size_t i = 0; i < sizeof forbidden_names / sizeof forbidden_names[0]; i++)
        if (forbidden_names[i].nr == info->si_syscall)
            name = forbidden_names[i].name;
    append(r.text, sizeof r.text, name);
    long args[2] = { 0, 0 };
#if defined(__x86_64__)
    const greg_t *g = ((ucontext_t *)context)->uc_mcontext.gregs;
    args[0] = g[REG_RDI]; args[1] = g[REG_RSI];
#elif defined(__aarch64__)
    const unsigned long long *g = ((ucontext_t *)context)->uc_mcontext.regs;
    args[0] = (long)g[0]; args[1] = (long)g[1];
#else
    (void)context;
#endif
    /* The path, for the calls that take one. */
    const char *path = NULL;
    long nr = info->si_syscall;
#ifdef __NR_open
    if (nr == __NR_open || nr == __NR_creat || nr == __NR_unlink || nr == __NR_mkdir ||
        nr == __NR_rename || nr == __NR_rmdir || nr == __NR_chmod)
        path = (const char *)args[0];
#endif
    if (nr == __NR_openat || nr == __NR_unlinkat || nr == __NR_mkdirat ||
        nr == __NR_renameat || nr == __NR_renameat2 || nr == __NR_fchmodat)
        path = (const char *)args[1];
    if (nr == __NR_execve || nr == __NR_truncate)
        path = (const char *)args[0];
    if (nr == __NR_fcntl || nr == __NR_ioctl) {
        append(r.text, sizeof r.text, " ");
        append(r.text, sizeof r.text, command_name(nr, (unsigned)args[1]));
    }
    if (path) {
        char copied[160];
        copy_user_string(path, copied, sizeof copied);
        append(r.text, sizeof r.text, " ");
        append(r.text, sizeof r.text, copied);
    }
    report_crash(&r);
}

/* ---- the seccomp filter -------------------------------------------------- */

#if defined(__x86_64__)
#define OUR_AUDIT_ARCH AUDIT_ARCH_X86_64
#elif defined(__aarch64__)
#define OUR_AUDIT_ARCH AUDIT_ARCH_AARCH64
#endif

#define MAX_FILTER 4000
static struct sock_filter program[MAX_FILTER];
static unsigned short program_length;

/* Forward jumps to labels, resolved once the program is complete. */
#define MAX_LABELS 4096
static int label_at[MAX_LABELS];
static int label_count;
static struct { unsigned short insn; short label; char field; } fixups[2 * MAX_LABELS];
static int fixup_count;
static int program_broken;

static void add_fixup(int at, int label, char field)
{
    if (fixup_count >= 2 * MAX_LABELS) {
        program_broken = 1;
        return;
    }
    fixups[fixup_count].insn = (unsigned short)at;
    fixups[fixup_count].label = (short)label;
    fixups[fixup_count++].field = field;
}

static int new_label(void)
{
    if (label_count >= MAX_LABELS) {
        program_broken = 1;
        return 0;
    }
    label_at[label_count] = -1;
    return label_count++;
}

static void place(int label)
{
    label_at[label] = program_length;
}

static void emit(struct sock_filter f)
{
    if (program_length < MAX_FILTER)
        program[program_length++] = f;
}

static void jump(unsigned value, unsigned char if_true, unsigned char if_false)
{
    emit((struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, value, if_true, if_false));
}

static void load(unsigned offset)
{
    emit((struct sock_filter)BPF_STMT(BPF_LD | BPF_W | BPF_ABS, offset));
}

static void ret(unsigned action)
{
    emit((struct sock_filter)BPF_STMT(BPF_RET | BPF_K, action));
}

#define ARG_LOW(i) ((unsigned)offsetof(struct seccomp_data, args[i]))
#define ARG_HIGH(i) ((unsigned)offsetof(struct seccomp_data, args[i]) + 4)
#define TRAP SECCOMP_RET_TRAP
#define ALLOW SECCOMP_RET_ALLOW
#define FAIL(e) (SECCOMP_RET_ERRNO | ((e) & SECCOMP_RET_DATA))

/* Each rule below starts with the syscall number in the accumulator and
 * either returns or leaves it there untouched. */

/* syscall == nr -> action */
static void on_call(long nr, unsigned action)
{
    jump((unsigned)nr, 0, 1);
    ret(action);
}

/* syscall == nr -> (args[arg] & mask) ? if_set : if_clear */
static void on_flags(long nr, int arg, unsigned mask, unsigned if_set, unsigned if_clear)
{
    jump((unsigned)nr, 0, 4);
    load(ARG_LOW(arg));
    emit((struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JSET | BPF_K, mask, 0, 1));
    ret(if_set);
    ret(if_clear);
}

/* syscall == nr -> (args[arg] == value) ? if_equal : otherwise */
static void on_arg(long nr, int arg, unsigned value, unsigned if_equal, unsigned otherwise)
{
    jump((unsigned)nr, 0, 6);
    load(ARG_HIGH(arg));
    jump(0, 0, 3);
    load(ARG_LOW(arg));
    jump(value, 0, 1);
    ret(if_equal);
    ret(otherwise);
}

/* syscall == nr -> (args[0] in values) ? action : allow */
static void on_arg_in_set(long nr, const int *values, unsigned count, unsigned action)
{
    jump((unsigned)nr, 0, (unsigned char)(count + 3));
    load(ARG_LOW(0));
    for (unsigned i = 0; i < count; i++)
        jump((unsigned)values[i], (unsigned char)(count - i), 0);
    ret(ALLOW);
    ret(action);
}

/* syscall == nr -> (args[arg] != NULL) ? action : allow */
static void on_nonnull(long nr, int arg, unsigned action)
{
    jump((unsigned)nr, 0, 6);
    load(ARG_LOW(arg));
    jump(0, 0, 3);
    load(ARG_HIGH(arg));
    jump(0, 0, 1);
    ret(ALLOW);
    ret(action);
}

/* syscall == nr -> args[arg] is 0 (the caller) or `self` ? allow : action.
 * Scheduling another process: in privilege-drop mode every worker is uid
 * nobody in one pid namespace, so a submission could put another student's
 * worker, or the speed check's reference, into SCHED_IDLE to starve it. */
static void on_other_pid(long nr, int arg, unsigned self, unsigned action)
{
    jump((unsigned)nr, 0, 7);
    load(ARG_HIGH(arg));
    jump(0, 0, 3);
    load(ARG_LOW(arg));
    jump(0, 2, 0);
    jump(self, 1, 0);
    ret(action);
    ret(ALLOW);
}

/* Conditional jump on A against k (code: BPF_JEQ, BPF_JGT, BPF_JGE, BPF_JSET)
 * to labels; -1 means the next instruction. */
static void jump_to(unsigned code, unsigned k, int if_true, int if_false)
{
    int at = program_length;
    emit((struct sock_filter)BPF_JUMP(BPF_JMP | code | BPF_K, k, 0, 0));
    if (if_true >= 0)
        add_fixup(at, if_true, 't');
    if (if_false >= 0)
        add_fixup(at, if_false, 'f');
}

static void always_to(int label)
{
    int at = program_length;
    emit((struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JA, 0, 0, 0));
    add_fixup(at, label, 'k');
}

static int resolve_labels(void)
{
    for (int i = 0; i < fixup_count; i++) {
        int target = label_at[fixups[i].label], at = fixups[i].insn;
        if (target < 0 || target <= at)
            return -1;
        unsigned offset = (unsigned)(target - at - 1);
        if (fixups[i].field == 'k')
            program[at].k = offset;
        else if (offset > 255)
            return -1;
        else if (fixups[i].field == 't')
            program[at].jt = (unsigned char)offset;
        else
            program[at].jf = (unsigned char)offset;
    }
    return 0;
}

static void stmt(unsigned code, unsigned k)
{
    emit((struct sock_filter)BPF_STMT(code, k));
}

/* Memory the submission must not remap, unmap or reprotect: the texture
 * windows and every file mapping present before it is loaded (the worker,
 * ld.so, libc, the C++ runtime: their code, relocations and data), so it can
 * neither switch a guard off nor patch the code that reports a fault. */
#define MAX_RANGES 40
static struct { uint64_t first, end; } protected_ranges[MAX_RANGES];
static int range_count;

static void protect(uint64_t first, uint64_t end)
{
    if (range_count > 0 && protected_ranges[range_count - 1].end == first) {
        protected_ranges[range_count - 1].end = end;   /* adjacent: one range */
        return;
    }
    if (range_count < MAX_RANGES) {
        protected_ranges[range_count].first = first;
        protected_ranges[range_count++].end = end;
        return;
    }
    /* Too many: widen the last one (protects a gap too, which is only stricter). */
    protected_ranges[range_count - 1].end = end;
}

/* Every mapping backed by a file or the kernel ([vdso], [vvar]): code,
 * relocations (read-only after RELRO) and data of the worker, ld.so, libc
 * and the C++ runtime. Anonymous memory is left alone (malloc unmaps and
 * trims it). Read from /proc/self/maps before the filter and any chroot. */
static int collect_protected_ranges(void)
{
    FILE *maps = fopen("/proc/self/maps", "re");
    if (!maps)
        return -1;
    char line[4096];
    while (fgets(line, sizeof line, maps)) {
        unsigned long long first, end, offset, inode;
        char perms[8], dev[32];
        int name_at = 0;
        if (sscanf(line, "%llx-%llx %7s %llx %31s %llu %n", &first, &end, perms, &offset, dev, &inode,
                   &name_at) < 6 || name_at <= 0)
            continue;
        const char *name = line + name_at;
        if (name[0] == '/' || !strncmp(name, "[vdso]", 6) || !strncmp(name, "[vvar", 5))
            protect(first, end);
    }
    fclose(maps);
    return 0;
}

/* Trap when [args[a], args[a] + args[len]) overlaps a protected range; when
 * flag_mask is not 0, only if args[flag_arg] & flag_mask. Otherwise falls
 * through with the syscall number in A again. Uses scratch M[0] (end, low
 * word) and M[1] (end, high word). */
static void on_protected_overlap(long nr, int a, int len, int flag_arg, unsigned flag_mask)
{
    int skip = new_label(), in_block = new_label();
    jump_to(BPF_JEQ, (unsigned)nr, in_block, -1);
    always_to(skip);
    place(in_block);
    if (flag_mask) {
        load(ARG_LOW(flag_arg));
        jump_to(BPF_JSET, flag_mask, -1, skip);
    }
    /* end = a + len, 64 bits from two 32-bit halves with the carry. */
    load(ARG_LOW(len));
    stmt(BPF_MISC | BPF_TAX, 0);
    load(ARG_LOW(a));
    stmt(BPF_ALU | BPF_ADD | BPF_X, 0);
    stmt(BPF_ST, 0);
    int no_carry = new_label(), carried = new_label();
    emit((struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JGE | BPF_X, 0, 0, 0));   /* sum >= len: no carry */
    add_fixup(program_length - 1, no_carry, 't');
    stmt(BPF_LD | BPF_IMM, 1);
    always_to(carried);
    place(no_carry);
    stmt(BPF_LD | BPF_IMM, 0);
    place(carried);
    stmt(BPF_ST, 1);
    load(ARG_HIGH(len));
    stmt(BPF_MISC | BPF_TAX, 0);
    load(ARG_HIGH(a));
    stmt(BPF_ALU | BPF_ADD | BPF_X, 0);
    stmt(BPF_MISC | BPF_TAX, 0);
    stmt(BPF_LD | BPF_MEM, 1);
    stmt(BPF_ALU | BPF_ADD | BPF_X, 0);
    stmt(BPF_ST, 1);
    for (int i = 0; i < range_count; i++) {
        uint64_t first = protected_ranges[i].first, end = protected_ranges[i].end;
        unsigned first_hi = (unsigned)(first >> 32), first_lo = (unsigned)first;
        unsigned end_hi = (unsigned)(end >> 32), end_lo = (unsigned)end;
        int next = new_label(), check_start = new_label(), low_end = new_label(), low_start = new_label(),
            trap = new_label();
        /* call end > first? */
        stmt(BPF_LD | BPF_MEM, 1);
        jump_to(BPF_JGT, first_hi, check_start, -1);
        jump_to(BPF_JEQ, first_hi, low_end, next);
        place(low_end);
        stmt(BPF_LD | BPF_MEM, 0);
        jump_to(BPF_JGT, first_lo, check_start, next);
        /* call start < end? */
        place(check_start);
        load(ARG_HIGH(a));
        jump_to(BPF_JGT, end_hi, next, -1);
        jump_to(BPF_JEQ, end_hi, low_start, trap);
        place(low_start);
        load(ARG_LOW(a));
        jump_to(BPF_JGE, end_lo, next, trap);
        place(trap);
        ret(TRAP);
        place(next);
    }
    place(skip);
    load((unsigned)offsetof(struct seccomp_data, nr));
}

/* Trap when args[arg] & mask (and, with mask2 not 0, args[arg2] & mask2);
 * otherwise fall through with the syscall number in A again. */
static void trap_on_bits(long nr, int arg, unsigned mask, int arg2, unsigned mask2)
{
    int skip = new_label(), in_block = new_label();
    jump_to(BPF_JEQ, (unsigned)nr, in_block, -1);
    always_to(skip);
    place(in_block);
    load(ARG_LOW(arg));
    if (mask2) {
        int second = new_label();
        jump_to(BPF_JSET, mask, second, skip);
        place(second);
        load(ARG_LOW(arg2));
        jump_to(BPF_JSET, mask2, -1, skip);
    } else {
        jump_to(BPF_JSET, mask, -1, skip);
    }
    ret(TRAP);
    place(skip);
    load((unsigned)offsetof(struct seccomp_data, nr));
}

/* fcntl: only the commands a lookup's runtime may use (descriptor flags,
 * duplicates, locks, pipe size, seals); F_SETFL only without O_ASYNC.
 * Everything else traps: F_SETOWN(_EX), F_SETSIG, F_NOTIFY, F_SETLEASE and
 * O_ASYNC would have the kernel deliver a signal of the caller's choosing
 * to a pid of its choosing (a classmate's worker, the speed check's
 * reference), which kill's rule never sees. */
static const unsigned fcntl_allowed[] = {
    F_DUPFD, F_GETFD, F_SETFD, F_GETFL, F_GETLK, F_SETLK, F_SETLKW, F_OFD_GETLK, F_OFD_SETLK,
    F_OFD_SETLKW, F_DUPFD_CLOEXEC, F_GETPIPE_SZ, F_GET_SEALS,
};
/* ioctl: isatty (TCGETS), the terminal size, FIONREAD, FIONBIO and the
 * close-on-exec pair are allowed; the ones that set a signal's owner trap;
 * any other answers ENOTTY (what a pipe says to a terminal request). */
static const unsigned ioctl_allowed[] = { TCGETS, TIOCGWINSZ, FIONREAD, FIONBIO, FIOCLEX, FIONCLEX };

static void on_command(long nr, const unsigned *allowed, size_t count, const struct syscall_name *trapped,
                       size_t trapped_count, unsigned otherwise, unsigned async_command)
{
    int skip = new_label(), in_block = new_label(), allow = new_label(), trap = new_label(), async = new_label();
    jump_to(BPF_JEQ, (unsigned)nr, in_block, -1);
    always_to(skip);
    place(in_block);
    load(ARG_LOW(1));      /* the command: an unsigned int, the kernel ignores the high word */
    if (async_command)
        jump_to(BPF_JEQ, async_command, async, -1);
    for (size_t i = 0; i < count; i++)
        jump_to(BPF_JEQ, allowed[i], allow, -1);
    for (size_t i = 0; i < trapped_count; i++)
        jump_to(BPF_JEQ, (unsigned)trapped[i].nr, trap, -1);
    ret(otherwise);
    place(async);
    if (async_command) {
        load(ARG_LOW(2));
        jump_to(BPF_JSET, O_ASYNC, trap, allow);
    }
    place(allow);
    ret(ALLOW);
    place(trap);
    ret(TRAP);
    place(skip);
    load((unsigned)offsetof(struct seccomp_data, nr));
}

static const int guarded_signals[] = { SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGSYS, SIGXCPU };

static int install_filter(void)
{
    unsigned pid = (unsigned)getpid();
    const unsigned write_flags = O_WRONLY | O_RDWR | O_CREAT | O_TRUNC | O_APPEND;
    load((unsigned)offsetof(struct seccomp_data, arch));
    jump(OUR_AUDIT_ARCH, 1, 0);
    ret(TRAP);
    load((unsigned)offsetof(struct seccomp_data, nr));
#if defined(__x86_64__)
    emit((struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JGE | BPF_K, __X32_SYSCALL_BIT, 0, 1));
    ret(TRAP);
#endif
    /* Threads are allowed (clone with CLONE_THREAD); new processes are not.
     * clone3 hides its flags in memory, so it answers "not supported" and
     * glibc falls back to clone. */
    on_flags(__NR_clone, 0, CLONE_THREAD, ALLOW, TRAP);
    on_call(__NR_clone3, FAIL(ENOSYS));
    on_call(__NR_openat2, FAIL(ENOSYS));
    /* Opening for reading stays allowed (dlopen needs it); writing traps. */
    on_flags(__NR_openat, 2, write_flags, TRAP, ALLOW);
#ifdef __NR_open
    on_flags(__NR_open, 1, write_flags, TRAP, ALLOW);
#endif
    /* Signals only to ourselves (raise, abort). */
    on_arg(__NR_kill, 0, pid, ALLOW, TRAP);
    on_arg(__NR_tgkill, 0, pid, ALLOW, TRAP);
    on_arg(__NR_tkill, 0, pid, ALLOW, TRAP);
    on_arg(__NR_rt_sigqueueinfo, 0, pid, ALLOW, TRAP);
    on_arg(__NR_rt_tgsigqueueinfo, 0, pid, ALLOW, TRAP);
    on_arg(__NR_prctl, 0, PR_SET_SECCOMP, TRAP, ALLOW);
    /* W^X: no memory becomes executable after loading except the
     * submission's own file mappings (dlopen maps them from the file). */
    trap_on_bits(__NR_mprotect, 2, PROT_EXEC, 0, 0);
    trap_on_bits(__NR_pkey_mprotect, 2, PROT_EXEC, 0, 0);
    trap_on_bits(__NR_mmap, 2, PROT_EXEC, 2, PROT_WRITE);
    trap_on_bits(__NR_mmap, 2, PROT_EXEC, 3, MAP_ANONYMOUS);
    /* The grader's memory (texture windows, the code that reports faults)
     * keeps its mappings and protections. */
    on_protected_overlap(__NR_mprotect, 0, 1, 0, 0);
    on_protected_overlap(__NR_pkey_mprotect, 0, 1, 0, 0);
    on_protected_overlap(__NR_munmap, 0, 1, 0, 0);
    on_protected_overlap(__NR_madvise, 0, 1, 0, 0);
    on_protected_overlap(__NR_mmap, 0, 1, 3, MAP_FIXED);
    on_protected_overlap(__NR_mremap, 0, 1, 0, 0);
    on_protected_overlap(__NR_mremap, 4, 2, 3, MREMAP_FIXED);
    /* Our crash handlers stay ours, and limits cannot be raised. */
    on_arg_in_set(__NR_rt_sigaction, guarded_signals,
                  sizeof guarded_signals / sizeof guarded_signals[0], FAIL(EPERM));
    on_call(__NR_setrlimit, FAIL(EPERM));
    on_nonnull(__NR_prlimit64, 2, FAIL(EPERM));
    /* Scheduling, priority and memory placement of itself only (another
     * worker of uid nobody could be starved: see on_other_pid). */
    on_other_pid(__NR_sched_setscheduler, 0, pid, FAIL(EPERM));
    on_other_pid(__NR_sched_setparam, 0, pid, FAIL(EPERM));
    on_other_pid(__NR_sched_setattr, 0, pid, FAIL(EPERM));
    on_other_pid(__NR_sched_setaffinity, 0, pid, FAIL(EPERM));
    on_other_pid(__NR_migrate_pages, 0, pid, FAIL(EPERM));
    on_other_pid(__NR_move_pages, 0, pid, FAIL(EPERM));
    on_call(__NR_setpriority, FAIL(EPERM));     /* PRIO_USER reaches every process of the uid */
    on_call(__NR_ioprio_set, FAIL(EPERM));
    /* Signals by way of a descriptor's owner (see fcntl_allowed). */
    on_command(__NR_fcntl, fcntl_allowed, sizeof fcntl_allowed / sizeof fcntl_allowed[0], signal_commands,
               sizeof signal_commands / sizeof signal_commands[0] - 1, TRAP, F_SETFL);
    on_command(__NR_ioctl, ioctl_allowed, sizeof ioctl_allowed / sizeof ioctl_allowed[0], signal_ioctls,
               sizeof signal_ioctls / sizeof signal_ioctls[0], FAIL(ENOTTY), 0);
    for (size_t i = 0; i < sizeof forbidden_names / sizeof forbidden_names[0]; i++) {
        long nr = forbidden_names[i].nr;
        int handled = nr == __NR_clone || nr == __NR_openat || nr == __NR_kill ||
                      nr == __NR_tgkill || nr == __NR_tkill || nr == __NR_rt_sigqueueinfo ||
                      nr == __NR_rt_tgsigqueueinfo || nr == __NR_mprotect || nr == __NR_pkey_mprotect ||
                      nr == __NR_munmap || nr == __NR_madvise || nr == __NR_mmap || nr == __NR_mremap ||
                      nr == __NR_prctl || nr == __NR_fcntl || nr == __NR_ioctl;
#ifdef __NR_open
        handled = handled || nr == __NR_open;
#endif
        if (!handled)
            on_call(nr, TRAP);
    }
    ret(ALLOW);
    if (program_length >= MAX_FILTER || program_broken || resolve_labels() != 0)
        return -1;
    struct sock_fprog fprog = { program_length, program };
    if (prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0)
        return -1;
    return prctl(PR_SET_SECCOMP, SECCOMP_MODE_FILTER, &fprog);
}
#endif /* __linux__ */

/* ---- set-up -------------------------------------------------------------- */

static void set_limit(int resource, rlim_t soft, rlim_t hard)
{
    struct rlimit r = { soft, hard };
    setrlimit(resource, &r);
}

static void install_handlers(void)
{
    static char alternate_stack[1 << 16];
    our_altstack = (stack_t){ .ss_sp = alternate_stack, .ss_size = sizeof alternate_stack, .ss_flags = 0 };
    sigaltstack(&our_altstack, NULL);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_flags = SA_SIGINFO | SA_ONSTACK;
    sigemptyset(&sa.sa_mask);
    sa.sa_sigaction = on_fault;
    const int faults[] = { SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGXCPU };
    for (size_t i = 0; i < sizeof faults / sizeof faults[0]; i++)
        sigaction(faults[i], &sa, NULL);
#ifdef __linux__
    sa.sa_sigaction = on_forbidden_syscall;
    sigaction(SIGSYS, &sa, NULL);
#endif
    signal(SIGPIPE, SIG_IGN);
}

static int read_exact(int fd, void *out, size_t size)
{
    char *p = out;
    while (size > 0) {
        /* Not glibc's read(), a cancellation point: a cancel the submission
         * left pending in a lookup it faulted out of must not unwind us. */
        ssize_t n = syscall(__NR_read, fd, p, size);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return -1;
        p += n;
        size -= (size_t)n;
    }
    return 0;
}

/* ---- the submission ------------------------------------------------------ */

static struct {
    int (*abi_version)(void);
    void *(*create)(char *, size_t);
    int (*set_faces)(void *, const float *, int, int, char *, size_t);
    int (*fetch_batch)(void *, const double *, size_t, double *, char *, size_t);
    int (*read_texture_batch)(void *, const float *, const double *, size_t, double *, char *, size_t);
    int (*load_cross)(void *, const char *, char *, size_t);
} sub;

static void *map;
static int face_w, face_h;
static char message[1024];

/* FETCH_WHOLE's inputs per submission call: few calls (timing), and a fault
 * costs at most this many inputs evaluated twice. */
#define WHOLE_BLOCK 4096

/* The faults of one request's per-input loop: index and crash report each. */
struct fault { uint64_t index; struct crash_report report; };
static struct fault *faults;
static uint64_t fault_count;
static sigset_t loop_mask;

static int faults_begin(uint64_t n)
{
    fault_count = 0;
    faults = malloc(n * sizeof *faults + 1);   /* before any fault: no malloc after one */
    sigprocmask(SIG_SETMASK, NULL, &loop_mask);
    main_tid = (pid_t)syscall(__NR_gettid);
    return faults ? 0 : -1;
}

/* After the jump back from the handler: record input k, put back what the
 * handler's delivery changed (the mask blocked our signal; the submission
 * may have switched our alternate stack off). */
static void fault_recorded(uint64_t k)
{
    sigprocmask(SIG_SETMASK, &loop_mask, NULL);
    sigaltstack(&our_altstack, NULL);
    faults[fault_count].index = k;
    faults[fault_count].report = last_fault;
    fault_count++;
}

/* FAULTS goes before the request's own reply, when any input faulted. */
static void faults_end(void)
{
    if (fault_count)
        reply(ST_FAULTS, fault_count, faults, fault_count * sizeof *faults);
}

/* After the request's reply: a lookup that faulted inside malloc may have
 * left its lock held, so nothing is freed before the answers are out. */
static void faults_free(void)
{
    free(faults);
    faults = NULL;
}

static void reply_status(int status, uint64_t count, const void *payload, uint64_t size)
{
    if (status == SUB_OK)
        reply(ST_OK, count, payload, size);
    else
        reply_text(status == SUB_ERR_EXCEPTION ? ST_EXCEPTION : ST_ARGUMENT, message);
}

static int load_submission(const char *path)
{
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        reply_text(ST_LOAD_ERROR, dlerror());
        return -1;
    }
#define SYMBOL(field, name)                                             \
    if (!(*(void **)&sub.field = dlsym(lib, name))) {                   \
        reply_text(ST_LOAD_ERROR, "missing symbol " name);              \
        return -1;                                                      \
    }
    SYMBOL(abi_version, "sub_abi_version")
    SYMBOL(create, "sub_create")
    SYMBOL(set_faces, "sub_set_faces")
    SYMBOL(fetch_batch, "sub_fetch_batch")
    SYMBOL(read_texture_batch, "sub_read_texture_batch")
    SYMBOL(load_cross, "sub_load_cross")
#undef SYMBOL
    int version = sub.abi_version();
    if (version != SUB_ABI_VERSION) {
        snprintf(message, sizeof message, "submission ABI version %d, worker expects %d",
                 version, SUB_ABI_VERSION);
        reply_text(ST_LOAD_ERROR, message);
        return -1;
    }
    message[0] = 0;
    map = sub.create(message, sizeof message);
    if (!map) {
        reply_text(ST_EXCEPTION, message[0] ? message : "the EnvironmentMap constructor failed");
        return -1;
    }
    reply(ST_READY, SUB_ABI_VERSION, NULL, 0);
    return 0;
}

static void set_faces(const char *payload, uint64_t size, uint64_t placement)
{
    int32_t dims[4];
    if (size < sizeof dims) {
        reply_text(ST_BAD_REQUEST, "SET_FACES payload too short");
        return;
    }
    memcpy(dims, payload, sizeof dims);
    uint64_t texels = size - sizeof dims;
    if (dims[0] <= 0 || dims[1] <= 0 ||
        texels != (uint64_t)dims[0] * (uint64_t)dims[1] * 6 * 3 * sizeof(float) ||
        (placement != PLACE_END && placement != PLACE_START)) {
        reply_text(ST_BAD_REQUEST, "SET_FACES size or placement mismatch");
        return;
    }
    one_face = one_placement = -1;
    if (window_fill(&six, payload + sizeof dims, texels, (int)placement, WHERE_ALL_FACES) != 0) {
        reply_text(ST_BAD_REQUEST, "the faces do not fit the texture window");
        return;
    }
    face_w = dims[0];
    face_h = dims[1];
    message[0] = 0;
    reply_status(sub.set_faces(map, (const float *)six.data, face_w, face_h,
                               message, sizeof message), 0, NULL, 0);
}

static void read_texture(const char *payload, uint64_t size, uint64_t n)
{
    int32_t head[2];
    const char *all = six.data;
    if (size < sizeof head || size - sizeof head != n * 2 * sizeof(double) || !all) {
        reply_text(ST_BAD_REQUEST, all ? "READ_TEXTURE size mismatch" : "READ_TEXTURE before SET_FACES");
        return;
    }
    memcpy(head, payload, sizeof head);
    int face = head[0], placement = head[1];
    if (face < 0 || face > 5 || (placement != PLACE_END && placement != PLACE_START)) {
        reply_text(ST_BAD_REQUEST, "READ_TEXTURE face or placement out of range");
        return;
    }
    /* The face alone in its own window, so reading past it faults. */
    size_t face_bytes = (size_t)face_w * (size_t)face_h * 3 * sizeof(float);
    if ((face != one_face || placement != one_placement) &&
        window_fill(&one, all + (size_t)face * face_bytes, face_bytes, placement, face) != 0) {
        one_face = one_placement = -1;
        reply_text(ST_BAD_REQUEST, "cannot write the face's window");
        return;
    }
    one_face = face;
    one_placement = placement;
    double *uv = malloc(n * 2 * sizeof(double) + 1), *rgb = malloc(n * 3 * sizeof(double) + 1);
    if (!uv || !rgb) {
        reply_text(ST_BAD_REQUEST, "out of memory for the batch");
        free(uv);
        free(rgb);
        return;
    }
    memcpy(uv, payload + sizeof head, n * 2 * sizeof(double));
    if (faults_begin(n) != 0) {
        reply_text(ST_BAD_REQUEST, "out of memory for the batch");
        free(uv);
        free(rgb);
        return;
    }
    volatile int status = SUB_OK;
    /* One input per call, its index in the progress page first (see progress). */
    for (volatile uint64_t k = 0; k < n && status == SUB_OK; k++) {
        *progress = k;
        message[0] = 0;
        if (sigsetjmp(lookup_escape, 0)) {
            fault_recorded(k);
            for (int c = 0; c < 3; c++)
                rgb[3 * k + c] = __builtin_nan("");
            continue;
        }
        in_lookup = 1;
        status = sub.read_texture_batch(map, (const float *)one.data, uv + 2 * k, 1, rgb + 3 * k,
                                        message, sizeof message);
        in_lookup = 0;
    }
    faults_end();
    reply_status(status, n, rgb, n * 3 * sizeof(double));
    faults_free();
    free(uv);
    free(rgb);
}

/* FETCH: rgb for n directions. TIME_FETCH: the same `repeats` times, replying
 * with the nanoseconds each sub_fetch_batch call took. */
static void fetch(const char *payload, uint64_t size, uint64_t n, int timed, int whole)
{
    uint32_t repeats = 1;
    size_t skip = 0;
    if (timed) {
        uint32_t head[2];
        if (size < sizeof head) {
            reply_text(ST_BAD_REQUEST, "TIME_FETCH payload too short");
            return;
        }
        memcpy(head, payload, sizeof head);
        repeats = head[0];
        skip = sizeof head;
    }
    if (size - skip != n * 3 * sizeof(double) || repeats == 0 || repeats > 100000) {
        reply_text(ST_BAD_REQUEST, "FETCH size mismatch");
        return;
    }
    double *dirs = malloc(n * 3 * sizeof(double) + 1), *rgb = malloc(n * 3 * sizeof(double) + 1);
    uint64_t *times = malloc(repeats * sizeof(uint64_t));
    if (!dirs || !rgb || !times) {
        reply_text(ST_BAD_REQUEST, "out of memory for the batch");
        free(dirs); free(rgb); free(times);
        return;
    }
    memcpy(dirs, payload + skip, n * 3 * sizeof(double));
    volatile int status = SUB_OK;
    if (!timed) {
        if (faults_begin(n) != 0) {
            reply_text(ST_BAD_REQUEST, "out of memory for the batch");
            free(dirs); free(rgb); free(times);
            return;
        }
        /* FETCH: one input per call. FETCH_WHOLE (timed from outside):
         * blocks of WHOLE_BLOCK inputs per call, and a block in which an
         * input faults is evaluated again one input per call, so the fault
         * costs that input only (its time counts, the rest hardly changes). */
        const volatile uint64_t block = whole ? WHOLE_BLOCK : 1;
        for (volatile uint64_t first = 0; first < n && status == SUB_OK; first += block) {
            const volatile uint64_t count = n - first < block ? n - first : block;
            volatile int per_input = count == 1;
            if (!per_input) {
                if (sigsetjmp(lookup_escape, 0) == 0) {
                    message[0] = 0;
                    in_lookup = 1;
                    status = sub.fetch_batch(map, dirs + 3 * first, count, rgb + 3 * first, message, sizeof message);
                    in_lookup = 0;
                } else {
                    sigprocmask(SIG_SETMASK, &loop_mask, NULL);
                    sigaltstack(&our_altstack, NULL);
                    per_input = 1;
                }
            }
            /* One input per call, its index in the progress page first; a
             * fault costs that input only (see lookup_escape). */
            for (volatile uint64_t k = first; per_input && k < first + count && status == SUB_OK; k++) {
                *progress = k;
                message[0] = 0;
                if (sigsetjmp(lookup_escape, 0)) {
                    fault_recorded(k);
                    for (int c = 0; c < 3; c++)
                        rgb[3 * k + c] = __builtin_nan("");
                    continue;
                }
                in_lookup = 1;
                status = sub.fetch_batch(map, dirs + 3 * k, 1, rgb + 3 * k, message, sizeof message);
                in_lookup = 0;
            }
        }
        faults_end();
        repeats = 0;     /* FETCH and FETCH_WHOLE have no timed repeats */
    }
    for (uint32_t i = 0; i < repeats && status == SUB_OK; i++) {
        struct timespec t0, t1;
        message[0] = 0;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        status = sub.fetch_batch(map, dirs, n, rgb, message, sizeof message);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        times[i] = (uint64_t)(t1.tv_sec - t0.tv_sec) * 1000000000u + (uint64_t)t1.tv_nsec - (uint64_t)t0.tv_nsec;
    }
    if (timed)
        reply_status(status, repeats, times, repeats * sizeof(uint64_t));
    else
        reply_status(status, n, rgb, n * 3 * sizeof(double));
    faults_free();
    free(dirs); free(rgb); free(times);
}

static void load_cross(const char *payload, uint64_t size)
{
    char path[4096];
    if (size == 0 || size >= sizeof path) {
        reply_text(ST_BAD_REQUEST, "LOAD_CROSS path length");
        return;
    }
    memcpy(path, payload, size);
    path[size] = 0;
    message[0] = 0;
    int loaded = sub.load_cross(map, path, message, sizeof message);
    reply(ST_OK, (uint64_t)(loaded != 0), message, strlen(message));
}

static int serve(void)
{
    for (;;) {
        struct header h;
        if (read_exact(request_fd, &h, sizeof h) != 0)
            return 0;      /* the grader closed the pipe: done */
        if (h.magic != REQUEST_MAGIC || h.payload_bytes > ((uint64_t)1 << 34))
            return EXIT_PROTOCOL;
        char *payload = malloc(h.payload_bytes + 1);
        if (!payload || read_exact(request_fd, payload, h.payload_bytes) != 0)
            return EXIT_PROTOCOL;
        switch (h.op) {
        case OP_SET_FACES: set_faces(payload, h.payload_bytes, h.count); break;
        case OP_FETCH: fetch(payload, h.payload_bytes, h.count, 0, 0); break;
        case OP_FETCH_WHOLE: fetch(payload, h.payload_bytes, h.count, 0, 1); break;
        case OP_TIME_FETCH: fetch(payload, h.payload_bytes, h.count, 1, 0); break;
        case OP_READ_TEXTURE: read_texture(payload, h.payload_bytes, h.count); break;
        case OP_LOAD_CROSS: load_cross(payload, h.payload_bytes); break;
        case OP_QUIT: free(payload); return 0;
        default: reply_text(ST_BAD_REQUEST, "unknown op"); break;
        }
        free(payload);
    }
}

/* Setup failed before any student code ran: say so on the reply pipe (the
 * grader can trust this message: nothing else has written there yet). */
static int setup_failed(const char *what)
{
    char text[256];
    snprintf(text, sizeof text, "worker set-up: %s (%s)", what, strerror(errno));
    reply_text(ST_SETUP_ERROR, text);
    return EXIT_SETUP;
}

/* The C++ runtime, loaded before the filter and any chroot: the submission's
 * DT_NEEDED entries then resolve to these by soname, and their code is
 * protected like ours. Missing ones are fine (a C submission needs none). */
static void preload_runtime(void)
{
    static const char *const names[] = { "libm.so.6", "libgcc_s.so.1", "libstdc++.so.6" };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        dlopen(names[i], RTLD_NOW | RTLD_GLOBAL);
}

/* Privilege-drop mode: a root-started worker locks itself into `dir` (a
 * fresh folder holding only the submission) and becomes uid/gid nobody,
 * for good. */
static int drop_privileges(const char *dir, long uid, long gid)
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
static int enter_pid_namespace(void)
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

int main(int argc, char **argv)
{
    long as_mb = 0, cpu_s = 0, nproc = -1, uid = -1, gid = -1;
    long long texture_bytes = 24ll << 20;
    long long fsize = 0;
    const char *chroot_dir = NULL;
    int seccomp = 1, check_drop = 0, i = 1, progress_fd = -1, pid_namespace = 0;
    for (; i < argc && strncmp(argv[i], "--", 2) == 0; i++) {
        if (!strcmp(argv[i], "--as-mb") && i + 1 < argc) as_mb = atol(argv[++i]);
        else if (!strcmp(argv[i], "--cpu-s") && i + 1 < argc) cpu_s = atol(argv[++i]);
        else if (!strcmp(argv[i], "--fsize") && i + 1 < argc) fsize = atoll(argv[++i]);
        else if (!strcmp(argv[i], "--nproc") && i + 1 < argc) nproc = atol(argv[++i]);
        else if (!strcmp(argv[i], "--texture-bytes") && i + 1 < argc) texture_bytes = atoll(argv[++i]);
        else if (!strcmp(argv[i], "--chroot") && i + 1 < argc) chroot_dir = argv[++i];
        else if (!strcmp(argv[i], "--uid") && i + 1 < argc) uid = atol(argv[++i]);
        else if (!strcmp(argv[i], "--gid") && i + 1 < argc) gid = atol(argv[++i]);
        else if (!strcmp(argv[i], "--progress-fd") && i + 1 < argc) progress_fd = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--no-seccomp")) seccomp = 0;
        else if (!strcmp(argv[i], "--check-drop")) check_drop = 1;
        else if (!strcmp(argv[i], "--pid-namespace")) pid_namespace = 1;
        else return EXIT_LOAD;
    }
    if (check_drop)   /* can this machine run privilege-drop mode? */
        return drop_privileges(chroot_dir, uid, gid) == 0 && getuid() == (uid_t)uid ? 0 : EXIT_SETUP;
    if (argc - i != 3 || (uid >= 0) != (gid >= 0) || texture_bytes <= 0 || texture_bytes > (4096ll << 20))
        return EXIT_LOAD;
    request_fd = atoi(argv[i]);
    response_fd = atoi(argv[i + 1]);
    const char *library = argv[i + 2];
    /* Which held is told to the grader in the set-up message. */
    int in_namespace = pid_namespace && uid >= 0 ? enter_pid_namespace() : 0;
    if (in_namespace < 0)
        return setup_failed("cannot start the worker in its own pid namespace");

    char here;
    stack_top = &here;
    struct rlimit stack;
    getrlimit(RLIMIT_STACK, &stack);
    stack_limit = stack.rlim_cur == RLIM_INFINITY ? (size_t)8 << 20 : stack.rlim_cur;
    page_size = (size_t)sysconf(_SC_PAGESIZE);

    set_limit(RLIMIT_CORE, 0, 0);
    if (as_mb > 0) set_limit(RLIMIT_AS, (rlim_t)as_mb << 20, (rlim_t)as_mb << 20);
    if (cpu_s > 0) set_limit(RLIMIT_CPU, (rlim_t)cpu_s, (rlim_t)cpu_s + 1);
    if (nproc >= 0) set_limit(RLIMIT_NPROC, (rlim_t)nproc, (rlim_t)nproc);
    /* Unbuffered, so output printed just before a crash is not lost. */
    setvbuf(stdout, NULL, _IONBF, 0);
    install_handlers();
    preload_runtime();
    if (reserve_windows((size_t)texture_bytes) != 0)
        return setup_failed("cannot reserve the texture windows");
    if (progress_fd >= 0) {
        /* Mapped before the protected ranges are read: it cannot be unmapped later. */
        void *page = mmap(NULL, (size_t)page_size, PROT_READ | PROT_WRITE, MAP_SHARED, progress_fd, 0);
        close(progress_fd);
        if (page == MAP_FAILED)
            return setup_failed("cannot map the progress page");
        progress = page;
    }
    if (fsize >= 0) set_limit(RLIMIT_FSIZE, (rlim_t)fsize, (rlim_t)fsize);
    if (pipe2(scratch, O_CLOEXEC) != 0)
        scratch[0] = scratch[1] = -1;
    if (seccomp && collect_protected_ranges() != 0)
        return setup_failed("cannot read /proc/self/maps");
    protect((uint64_t)(uintptr_t)region, (uint64_t)(uintptr_t)region + region_size);
    if ((chroot_dir || uid >= 0) && drop_privileges(chroot_dir, uid, gid) != 0)
        return setup_failed("cannot drop privileges");
    if (seccomp && install_filter() != 0)
        return setup_failed("cannot install the seccomp filter");
    /* The last message from the grader's own code: from here on, anything on
     * the reply pipe may come from the submission. */
    reply(ST_SANDBOXED, in_namespace ? SANDBOXED_PID_NAMESPACE : 0, NULL, 0);
    if (load_submission(library) != 0)
        return EXIT_LOAD;
    return serve();
}
