/*
 * faults.c - texture windows between guard pages, and crash reports.
 *
 * Textures live in two fixed windows reserved once before the filter: a
 * read-only MAP_SHARED view of a memfd between PROT_NONE guards, one for the
 * six faces and one for the single face readTexture gets. The windows never
 * change after start-up, and the filter refuses mprotect/munmap/mremap/
 * madvise/mmap(MAP_FIXED) on them (and on every library's code and
 * relocations), so a guard cannot be switched off from inside. The texels
 * end where a guard starts ("end") or start where one ends ("start").
 *
 * A fault is reported with what it hit: a guard before or after the texels
 * (with the distance in bytes), the read-only texels themselves (a write),
 * the stack's end, the CPU limit, or a syscall the filter trapped (by name,
 * with its path or command). Inside one input of a per-input loop, a fault
 * jumps back to the loop instead (lookup_escape).
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <ucontext.h>
#include <unistd.h>

#include "faults.h"
#include "seccomp.h"

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

char *region;       /* the whole reservation, guards included */
size_t region_size;
struct window six, one;
int one_face = -1, one_placement = -1;   /* what `one` holds */
size_t page_size;

static size_t round_pages(size_t n)
{
    return (n + page_size - 1) / page_size * page_size;
}

/* Reserve the windows (before the filter and RLIMIT_FSIZE). */
int reserve_windows(size_t six_capacity)
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
int window_fill(struct window *w, const char *src, size_t size, int placement, int where)
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

char *stack_top;    /* near the top of the main thread's stack */
size_t stack_limit;

/* Grading past a fault: while the main thread is inside one submission call
 * of FETCH's or READ_TEXTURE's per-input loop (in_lookup), a fault that only
 * that input caused (SIGSEGV, SIGBUS, SIGFPE, SIGILL) jumps back to the loop
 * instead of ending the worker: the input is reported as crashed, with its
 * crash report, and the loop goes on with the next one. Nothing of the
 * worker's changes: the guard pages stay as they are, the signal mask and
 * our alternate stack are set again after the jump. A crash-heavy
 * submission then costs about what a correct one does, where each crash used
 * to cost a fresh worker and the narrowing down (issue 19). */
sigjmp_buf lookup_escape;
volatile sig_atomic_t in_lookup;
pid_t main_tid;
struct crash_report last_fault;
stack_t our_altstack;

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

/* ---- trapped syscalls ---------------------------------------------------- */

int scratch[2] = { -1, -1 };

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

static void on_forbidden_syscall(int signo, siginfo_t *info, void *context)
{
    struct crash_report r;
    memset(&r, 0, sizeof r);
    r.signo = signo;
    r.si_code = info->si_code;
    r.cause = CAUSE_FORBIDDEN_SYSCALL;
    r.where = info->si_syscall;
    append(r.text, sizeof r.text, trapped_syscall_name(info->si_syscall));
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

void install_handlers(void)
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
    sa.sa_sigaction = on_forbidden_syscall;
    sigaction(SIGSYS, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
}
