/*
 * worker.c - the only process that runs student code.
 *
 *   worker [--as-mb N] [--cpu-s N] [--fsize N] [--nproc N] [--no-seccomp]
 *          REQUEST_FD RESPONSE_FD SUBMISSION.so
 *
 * Order matters: limits, signal handlers (on an alternate stack, so a stack
 * overflow is reported too), the seccomp filter, and only then dlopen() the
 * submission, so its static initialisers already run under all of them.
 * Requests arrive on REQUEST_FD and answers leave on RESPONSE_FD (a private
 * pipe pair: student code may print to fds 1 and 2, which the grader
 * captures). The protocol is described in README.md beside this file and
 * mirrored in protocol.py, which validates every reply.
 *
 * Texture buffers are copied into read-only mappings between PROT_NONE guard
 * pages, placed so that the texels end where a guard page starts ("end") or
 * start where one ends ("start"). A SIGSEGV inside a guard page is reported as
 * an out-of-bounds read of that buffer, with the distance in bytes. Nothing
 * student-written is linked into this file.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <time.h>
#include <ucontext.h>
#include <unistd.h>

#ifdef __linux__
#include <linux/audit.h>
#include <linux/filter.h>
#include <linux/seccomp.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#endif

#include "../shim/submission_abi.h"

/* ---- protocol (keep in step with protocol.py) ---------------------------- */

#define REQUEST_MAGIC 0x4b574d45u  /* "EMWK" */
#define RESPONSE_MAGIC 0x524b4d45u /* "EMKR" */

enum { OP_SET_FACES = 1, OP_FETCH = 2, OP_READ_TEXTURE = 3, OP_TIME_FETCH = 4,
       OP_LOAD_CROSS = 5, OP_QUIT = 6 };
enum { ST_OK = 0, ST_EXCEPTION = 1, ST_ARGUMENT = 2, ST_CRASH = 3, ST_LOAD_ERROR = 4,
       ST_READY = 5, ST_BAD_REQUEST = 6 };
enum { CAUSE_SIGNAL = 0, CAUSE_GUARD_AFTER = 1, CAUSE_GUARD_BEFORE = 2,
       CAUSE_STACK_OVERFLOW = 3, CAUSE_CPU_LIMIT = 4, CAUSE_FORBIDDEN_SYSCALL = 5,
       CAUSE_TEXTURE_WRITE = 6 };
enum { PLACE_END = 0, PLACE_START = 1 };
enum { WHERE_ALL_FACES = -1 };

/* Exit codes, for when the grader sees the status but not the report. */
enum { EXIT_CRASH = 70, EXIT_LOAD = 71, EXIT_PROTOCOL = 72 };

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

/* ---- writing replies (async-signal-safe: used from handlers) ------------- */

static int write_all(int fd, const void *data, size_t size)
{
    const char *p = data;
    while (size > 0) {
        ssize_t n = write(fd, p, size);
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
        _exit(EXIT_PROTOCOL);
}

static void reply_text(uint32_t status, const char *text)
{
    reply(status, 0, text, strlen(text));
}

/* ---- guarded texture mappings -------------------------------------------- */

struct guarded {
    char *mapping;         /* whole mapping, guards included */
    size_t mapping_size;
    char *data;            /* the texels */
    size_t size;
    int where;             /* face, or WHERE_ALL_FACES */
};

/* Slots: the six-face buffer in placement p at p, face f in placement p at
 * 2 + 2*f + p. */
#define SLOT_COUNT 14
static struct guarded slots[SLOT_COUNT];
static size_t page_size;

static void guarded_free(struct guarded *g)
{
    if (g->mapping)
        munmap(g->mapping, g->mapping_size);
    memset(g, 0, sizeof *g);
}

/* Copy `size` bytes between two PROT_NONE guard pages; read-only afterwards,
 * so a write into the texture faults too. */
static int guarded_copy(struct guarded *g, const void *src, size_t size, int placement, int where)
{
    size_t body = (size + page_size - 1) / page_size * page_size;
    if (body == 0)
        body = page_size;
    size_t total = body + 2 * page_size;
    char *m = mmap(NULL, total, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED)
        return -1;
    if (mprotect(m + page_size, body, PROT_READ | PROT_WRITE) != 0) {
        munmap(m, total);
        return -1;
    }
    char *data = placement == PLACE_END ? m + page_size + body - size : m + page_size;
    memcpy(data, src, size);
    mprotect(m + page_size, body, PROT_READ);
    g->mapping = m;
    g->mapping_size = total;
    g->data = data;
    g->size = size;
    g->where = where;
    return 0;
}

/* ---- crash reports ------------------------------------------------------- */

static char *stack_top;    /* near the top of the main thread's stack */
static size_t stack_limit;

static void report_crash(const struct crash_report *r)
{
    reply(ST_CRASH, 0, r, sizeof *r);
    _exit(EXIT_CRASH);
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
    if (signo == SIGSEGV || signo == SIGBUS) {
        for (int i = 0; i < SLOT_COUNT; i++) {
            const struct guarded *g = &slots[i];
            char *first = g->mapping, *last = g->mapping + g->mapping_size;
            if (!first || addr < first || addr >= last)
                continue;
            r.where = g->where;
            if (addr >= g->data && addr < g->data + g->size) {
                r.cause = CAUSE_TEXTURE_WRITE;   /* readable: only a write faults here */
                r.distance = addr - g->data;
            } else if (addr < g->data) {
                r.cause = CAUSE_GUARD_BEFORE;
                r.distance = g->data - addr;
            } else {
                r.cause = CAUSE_GUARD_AFTER;
                r.distance = addr - (g->data + g->size);
            }
            report_crash(&r);
        }
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
        if (write(scratch[1], src + n, 1) != 1 || read(scratch[0], &c, 1) != 1 || c == 0)
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

#define MAX_FILTER 256
static struct sock_filter program[MAX_FILTER];
static unsigned short program_length;

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
    /* Our crash handlers stay ours, and limits cannot be raised. */
    on_arg_in_set(__NR_rt_sigaction, guarded_signals,
                  sizeof guarded_signals / sizeof guarded_signals[0], FAIL(EPERM));
    on_call(__NR_setrlimit, FAIL(EPERM));
    on_nonnull(__NR_prlimit64, 2, FAIL(EPERM));
    for (size_t i = 0; i < sizeof forbidden_names / sizeof forbidden_names[0]; i++) {
        long nr = forbidden_names[i].nr;
        int handled = nr == __NR_clone || nr == __NR_openat || nr == __NR_kill ||
                      nr == __NR_tgkill || nr == __NR_tkill;
#ifdef __NR_open
        handled = handled || nr == __NR_open;
#endif
        if (!handled)
            on_call(nr, TRAP);
    }
    ret(ALLOW);
    if (program_length >= MAX_FILTER)
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
    stack_t ss = { .ss_sp = alternate_stack, .ss_size = sizeof alternate_stack, .ss_flags = 0 };
    sigaltstack(&ss, NULL);
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
        ssize_t n = read(fd, p, size);
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
    for (int i = 0; i < SLOT_COUNT; i++)
        guarded_free(&slots[i]);
    if (guarded_copy(&slots[placement], payload + sizeof dims, texels, (int)placement, WHERE_ALL_FACES) != 0) {
        reply_text(ST_BAD_REQUEST, "cannot map the texture (address-space limit?)");
        return;
    }
    face_w = dims[0];
    face_h = dims[1];
    message[0] = 0;
    reply_status(sub.set_faces(map, (const float *)slots[placement].data, face_w, face_h,
                               message, sizeof message), 0, NULL, 0);
}

static const struct guarded *six_faces(void)
{
    return slots[PLACE_END].mapping ? &slots[PLACE_END]
         : slots[PLACE_START].mapping ? &slots[PLACE_START] : NULL;
}

static void read_texture(const char *payload, uint64_t size, uint64_t n)
{
    int32_t head[2];
    const struct guarded *all = six_faces();
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
    /* Each face in its own guarded mapping, so reading past it faults. */
    struct guarded *g = &slots[2 + 2 * face + placement];
    size_t face_bytes = (size_t)face_w * (size_t)face_h * 3 * sizeof(float);
    if (!g->mapping && guarded_copy(g, all->data + (size_t)face * face_bytes, face_bytes, placement, face) != 0) {
        reply_text(ST_BAD_REQUEST, "cannot map the face (address-space limit?)");
        return;
    }
    double *uv = malloc(n * 2 * sizeof(double) + 1), *rgb = malloc(n * 3 * sizeof(double) + 1);
    if (!uv || !rgb) {
        reply_text(ST_BAD_REQUEST, "out of memory for the batch");
        free(uv);
        free(rgb);
        return;
    }
    memcpy(uv, payload + sizeof head, n * 2 * sizeof(double));
    message[0] = 0;
    int status = sub.read_texture_batch(map, (const float *)g->data, uv, n, rgb, message, sizeof message);
    reply_status(status, n, rgb, n * 3 * sizeof(double));
    free(uv);
    free(rgb);
}

/* FETCH: rgb for n directions. TIME_FETCH: the same `repeats` times, replying
 * with the nanoseconds each sub_fetch_batch call took. */
static void fetch(const char *payload, uint64_t size, uint64_t n, int timed)
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
    int status = SUB_OK;
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
        case OP_FETCH: fetch(payload, h.payload_bytes, h.count, 0); break;
        case OP_TIME_FETCH: fetch(payload, h.payload_bytes, h.count, 1); break;
        case OP_READ_TEXTURE: read_texture(payload, h.payload_bytes, h.count); break;
        case OP_LOAD_CROSS: load_cross(payload, h.payload_bytes); break;
        case OP_QUIT: free(payload); return 0;
        default: reply_text(ST_BAD_REQUEST, "unknown op"); break;
        }
        free(payload);
    }
}

int main(int argc, char **argv)
{
    long as_mb = 0, cpu_s = 0, nproc = -1;
    long long fsize = 0;
    int seccomp = 1, i = 1;
    for (; i < argc && strncmp(argv[i], "--", 2) == 0; i++) {
        if (!strcmp(argv[i], "--as-mb") && i + 1 < argc) as_mb = atol(argv[++i]);
        else if (!strcmp(argv[i], "--cpu-s") && i + 1 < argc) cpu_s = atol(argv[++i]);
        else if (!strcmp(argv[i], "--fsize") && i + 1 < argc) fsize = atoll(argv[++i]);
        else if (!strcmp(argv[i], "--nproc") && i + 1 < argc) nproc = atol(argv[++i]);
        else if (!strcmp(argv[i], "--no-seccomp")) seccomp = 0;
        else return EXIT_LOAD;
    }
    if (argc - i != 3)
        return EXIT_LOAD;
    request_fd = atoi(argv[i]);
    response_fd = atoi(argv[i + 1]);
    const char *library = argv[i + 2];

    char here;
    stack_top = &here;
    struct rlimit stack;
    getrlimit(RLIMIT_STACK, &stack);
    stack_limit = stack.rlim_cur == RLIM_INFINITY ? (size_t)8 << 20 : stack.rlim_cur;
    page_size = (size_t)sysconf(_SC_PAGESIZE);

    set_limit(RLIMIT_CORE, 0, 0);
    if (as_mb > 0) set_limit(RLIMIT_AS, (rlim_t)as_mb << 20, (rlim_t)as_mb << 20);
    if (cpu_s > 0) set_limit(RLIMIT_CPU, (rlim_t)cpu_s, (rlim_t)cpu_s + 1);
    if (fsize >= 0) set_limit(RLIMIT_FSIZE, (rlim_t)fsize, (rlim_t)fsize);
    if (nproc >= 0) set_limit(RLIMIT_NPROC, (rlim_t)nproc, (rlim_t)nproc);
    /* Unbuffered, so output printed just before a crash is not lost. */
    setvbuf(stdout, NULL, _IONBF, 0);
    install_handlers();
#ifdef __linux__
    if (pipe2(scratch, O_CLOEXEC) != 0)
        scratch[0] = scratch[1] = -1;
    if (seccomp && install_filter() != 0) {
        reply_text(ST_LOAD_ERROR, "worker: cannot install the seccomp filter");
        return EXIT_LOAD;
    }
#else
    (void)seccomp;
#endif
    if (load_submission(library) != 0)
        return EXIT_LOAD;
    return serve();
}
