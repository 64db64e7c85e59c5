/*
 * worker.c - the only process that runs student code.
 *
 *   worker [--as-mb N] [--cpu-s N] [--fsize N] [--nproc N] [--nofile N] [--sigpending N]
 *          --texture-bytes-fd N
 *          [--chroot DIR --uid N --gid N [--pid-namespace]] [--no-seccomp] [--check-drop]
 *          [--progress-fd N]
 *          REQUEST_FD RESPONSE_FD SUBMISSION.so
 *
 * Order matters: limits, signal handlers (on an alternate stack, so a stack
 * overflow is reported too), the C++ runtime preloaded, the faces' size read
 * from its pipe (a worker prepared ahead waits there), the texture windows
 * reserved, privileges dropped (privilege-drop mode: chroot into a folder
 * holding only the submission, then uid/gid nobody), the seccomp filter, a
 * SANDBOXED message (the last one the grader can trust: no student code has
 * run yet), and only then dlopen() the submission, so its static
 * initialisers already run under all of them.
 * Requests arrive on REQUEST_FD and answers leave on RESPONSE_FD (a private
 * pipe pair: student code may print to fds 1 and 2, which the grader
 * captures). The protocol is described in README.md beside this file and
 * mirrored in protocol.py, which validates every reply.
 * Textures live in guarded windows (faults.c), the filter is seccomp.c's.
 * Nothing student-written is linked into this file.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <setjmp.h>
#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "../build/shim/submission_abi.h"
#include "faults.h"
#include "privileges.h"
#include "protocol.h"
#include "seccomp.h"

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

void reply(uint32_t status, uint64_t count, const void *payload, uint64_t size)
{
    struct header h = { RESPONSE_MAGIC, status, count, size };
    if (write_all(response_fd, &h, sizeof h) != 0 ||
        (size > 0 && write_all(response_fd, payload, size) != 0))
        for (;;)
            syscall(__NR_exit_group, EXIT_PROTOCOL);
}

void reply_text(uint32_t status, const char *text)
{
    reply(status, 0, text, strlen(text));
}

/* ---- set-up -------------------------------------------------------------- */

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
    int (*record_fetch_batch)(void *, const double *, size_t, const double *, double *, double *,
                              struct sub_texture_call *, char *, size_t);
} sub;

/* RECORD_FETCH's reply, per direction: rgb, the number of readTexture calls,
 * the call whose answer was returned, then the first SUB_RECORDED_CALLS calls
 * (face, offset, u, v). */
_Static_assert(SUB_RECORDED_CALLS == 4, "protocol.py's RECORDED_CALLS");
#define RECORD_ROW (5 + 4 * SUB_RECORDED_CALLS)

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
    SYMBOL(record_fetch_batch, "sub_record_fetch_batch")
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

/* RECORD_FETCH: fetchColor for n directions with readTexture's calls logged
 * and answered with the request's tags, or (tagged = 0) with the student's
 * readTexture (submission_abi.h); one input per call as in FETCH; a row of
 * RECORD_ROW doubles per direction. */
static void record_fetch(const char *payload, uint64_t size, uint64_t n)
{
    uint64_t tagged;
    const size_t head = sizeof tagged + 3 * SUB_RECORDED_CALLS * sizeof(double);
    if (size < head || size - head != n * 3 * sizeof(double) || !six.data) {
        reply_text(ST_BAD_REQUEST, six.data ? "RECORD_FETCH size mismatch" : "RECORD_FETCH before SET_FACES");
        return;
    }
    memcpy(&tagged, payload, sizeof tagged);
    static double tags[3 * SUB_RECORDED_CALLS];
    memcpy(tags, payload + sizeof tagged, sizeof tags);
    double *dirs = malloc(n * 3 * sizeof(double) + 1), *rows = malloc(n * RECORD_ROW * sizeof(double) + 1);
    if (!dirs || !rows || faults_begin(n) != 0) {
        reply_text(ST_BAD_REQUEST, "out of memory for the batch");
        free(dirs);
        free(rows);
        return;
    }
    memcpy(dirs, payload + head, n * 3 * sizeof(double));
    volatile int status = SUB_OK;
    for (volatile uint64_t k = 0; k < n && status == SUB_OK; k++) {
        *progress = k;
        message[0] = 0;
        if (sigsetjmp(lookup_escape, 0)) {
            fault_recorded(k);
            for (int c = 0; c < RECORD_ROW; c++)
                rows[RECORD_ROW * k + c] = __builtin_nan("");
            continue;
        }
        double *row = rows + RECORD_ROW * k;
        for (int c = 0; c < RECORD_ROW; c++)
            row[c] = __builtin_nan("");
        in_lookup = 1;
        status = sub.record_fetch_batch(map, dirs + 3 * k, 1, tagged ? tags : NULL, row, row + 3,
                                        (struct sub_texture_call *)(row + 5), message, sizeof message);
        in_lookup = 0;
    }
    faults_end();
    reply_status(status, n, rows, n * RECORD_ROW * sizeof(double));
    faults_free();
    free(dirs);
    free(rows);
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
        case OP_RECORD_FETCH: record_fetch(payload, h.payload_bytes, h.count); break;
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

int main(int argc, char **argv)
{
    long as_mb = 0, cpu_s = 0, nproc = -1, nofile = -1, sigpending = -1, uid = -1, gid = -1;
    long long texture_bytes = 0;
    long long fsize = 0;
    const char *chroot_dir = NULL;
    int seccomp = 1, check_drop = 0, i = 1, progress_fd = -1, pid_namespace = 0, size_fd = -1;
    for (; i < argc && strncmp(argv[i], "--", 2) == 0; i++) {
        if (!strcmp(argv[i], "--as-mb") && i + 1 < argc) as_mb = atol(argv[++i]);
        else if (!strcmp(argv[i], "--cpu-s") && i + 1 < argc) cpu_s = atol(argv[++i]);
        else if (!strcmp(argv[i], "--fsize") && i + 1 < argc) fsize = atoll(argv[++i]);
        else if (!strcmp(argv[i], "--nproc") && i + 1 < argc) nproc = atol(argv[++i]);
        else if (!strcmp(argv[i], "--nofile") && i + 1 < argc) nofile = atol(argv[++i]);
        else if (!strcmp(argv[i], "--sigpending") && i + 1 < argc) sigpending = atol(argv[++i]);
        else if (!strcmp(argv[i], "--texture-bytes-fd") && i + 1 < argc) size_fd = atoi(argv[++i]);
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
    if (argc - i != 3 || (uid >= 0) != (gid >= 0) || size_fd < 0)
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

    set_limits(as_mb, cpu_s, nproc, nofile, sigpending);
    /* Unbuffered, so output printed just before a crash is not lost. */
    setvbuf(stdout, NULL, _IONBF, 0);
    install_handlers();
    preload_runtime();
    /* The faces' size, 8 bytes, read here: before anything depends on it and
     * before any student code (a worker prepared ahead waits here). At the
     * pipe's end of file the worker was never needed. */
    uint64_t size = 0;
    int got = read_exact(size_fd, &size, sizeof size);
    close(size_fd);
    if (got != 0)
        return setup_failed("no face size at the gate");
    if (size == 0 || size > (4096ull << 20))
        return EXIT_LOAD;       /* as a bad argument: before the set-up report */
    texture_bytes = (long long)size;
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
    if (fsize >= 0) set_limit(RLIMIT_FSIZE, (rlim_t)fsize, (rlim_t)fsize);   /* after the progress page's mapping */
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

