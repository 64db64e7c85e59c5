"""Attacks on the worker from inside, by a motivated student (issue 11):
forged replies, switching guard pages off, patching the grader's code,
signalling the grader. Each gets a verdict charged to the submission; none
gets correct values or a harness error.

The attacker is a small C library implementing grader/build/shim/submission_abi.h
directly: fetchColor's x picks an attack on the reply pipe, readTexture's v
an attack on the memory around the face before it reads addr[int(u)]
(u = the face's float count reads one float past its end).
"""
from __future__ import annotations

import signal
import subprocess
from pathlib import Path

import numpy as np
import pytest

from grader import PROJECT_ROOT
from grader.worker import SubmissionFailure, SubmissionRunner, Worker, WorkerHarnessError, sandbox

pytestmark = [pytest.mark.sandbox]   # whole gradings / workers (tests/conftest.py's markers)

ABI_DIR = PROJECT_ROOT / "grader" / "build" / "shim"
BWRAP = sandbox.sandbox_problem()
DROP = sandbox.privilege_drop_problem()
MODES = ["plain",
         pytest.param("sandbox", marks=pytest.mark.skipif(BWRAP is not None, reason=f"no bubblewrap: {BWRAP}")),
         pytest.param("privilege-drop", marks=pytest.mark.skipif(DROP is not None, reason=f"no privilege drop: {DROP}"))]

ATTACKER = r"""
#define _GNU_SOURCE
#include "submission_abi.h"
#include <dlfcn.h>
#include <fcntl.h>
#include <pthread.h>
#include <setjmp.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/auxv.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

typedef struct { const float *texels; int w, h; } map_t;

/* The reply fd: the second-to-last word of the worker's command line. */
static int reply_fd(void)
{
    char buf[4096];
    int fd = open("/proc/self/cmdline", O_RDONLY);
    ssize_t n = fd >= 0 ? read(fd, buf, sizeof buf - 1) : -1;
    if (fd >= 0) close(fd);
    if (n <= 0) return -1;    /* no /proc (privilege-drop chroot) */
    buf[n] = 0;
    const char *words[64];
    int count = 0;
    for (ssize_t i = 0; i < n && count < 64; i += (ssize_t)strlen(buf + i) + 1)
        words[count++] = buf + i;
    return count >= 3 ? atoi(words[count - 2]) : -1;
}

static void forge(uint32_t magic, uint32_t status, uint64_t count, const void *payload, uint64_t size)
{
    struct { uint32_t magic, status; uint64_t count, size; } h = { magic, status, count, size };
    int fd = reply_fd();
    /* Without /proc (privilege-drop chroot): every write-only fd from 3 on. */
    for (int f = fd < 0 ? 3 : fd; f <= (fd < 0 ? 255 : fd); f++) {
        if ((fcntl(f, F_GETFL) & O_ACCMODE) != O_WRONLY) continue;
        (void)!write(f, &h, sizeof h);
        if (size) (void)!write(f, payload, size);
    }
}

#define MAGIC 0x524b4d45u

int sub_abi_version(void) { return SUB_ABI_VERSION; }
void *sub_create(char *m, size_t s) { (void)m; (void)s; return calloc(1, sizeof(map_t)); }
void sub_destroy(void *map) { free(map); }
int sub_set_faces(void *map, const float *t, int w, int h, char *m, size_t s)
{ (void)m; (void)s; map_t *p = map; p->texels = t; p->w = w; p->h = h; return SUB_OK; }

int sub_fetch_batch(void *map, const double *d, size_t n, double *rgb, char *m, size_t s)
{
    (void)map; (void)m; (void)s;
    for (size_t i = 0; i < n; i++) {
        int x = (int)d[3*i];
        rgb[3*i] = rgb[3*i+1] = rgb[3*i+2] = 0.5;
        if (x == 10) forge(MAGIC, 2, 0, "grader bug", 10);              /* ARGUMENT */
        if (x == 11) forge(MAGIC, 6, 0, "bad request", 11);             /* BAD_REQUEST */
        if (x == 12) forge(0x12345678u, 0, n, rgb, n * 24);              /* bad magic */
        if (x == 13) forge(MAGIC, 8, 0, "setup", 5);                     /* SETUP_ERROR, late */
        if (x == 14) forge(MAGIC, 0, n + 1, rgb, (n + 1) * 24);          /* impossible count */
        if (x == 15) { char r[256] = {0}; ((int32_t *)r)[0] = 11; ((int32_t *)r)[2] = 99;
                       forge(MAGIC, 3, 0, r, 256); }                     /* crash, impossible cause */
        if (x == 16) { siginfo_t si; memset(&si, 0, sizeof si); si.si_code = SI_QUEUE;
                       syscall(SYS_rt_sigqueueinfo, getppid(), SIGWINCH, &si); }
        if (x == 17) { int pfd = (int)syscall(SYS_pidfd_open, getppid(), 0);
                       syscall(SYS_pidfd_send_signal, pfd, SIGWINCH, NULL, 0); }
        if (x == 18) syscall(SYS_seccomp, 1, 0, NULL);                  /* stack a filter of our own */
        if (x == 19) syscall(SYS_msgget, 1234, 01666);                   /* a queue that outlives us */
        if (x == 20) syscall(SYS_personality, 0x0400000);                /* READ_IMPLIES_EXEC */
        if (x == 21) { struct timespec t = {0, 0}; syscall(SYS_clock_settime, 12345, &t); }   /* a clock that does not exist: harmless if let through */
    }
    return SUB_OK;
}

static uintptr_t page_of(const void *p) { return (uintptr_t)p & ~(uintptr_t)4095; }

/* Escape from the crash handler: cancel ourselves (deferred), so the next
 * cancellation point unwinds the thread into our cleanup handler, which
 * jumps back here. If the handler made a glibc write(), that was the point. */
static sigjmp_buf escape;
static void jump_back(void *unused) { (void)unused; siglongjmp(escape, 1); }

static float read_escaping(const float *addr, long index)
{
    volatile float value = 0.75f;
    if (sigsetjmp(escape, 1) == 0) {
        pthread_cleanup_push(jump_back, NULL);
        pthread_cancel(pthread_self());
        value = addr[index];
        pthread_cleanup_pop(0);
    }
    return value;
}

int sub_read_texture_batch(void *map, const float *addr, const double *uv, size_t n, double *rgb,
                           char *m, size_t s)
{
    map_t *p = map;
    (void)m; (void)s;
    size_t floats = (size_t)p->w * (size_t)p->h * 3;
    uintptr_t past = page_of(addr + floats - 1) + 4096;     /* the guard page after the face */
    for (size_t i = 0; i < n; i++) {
        int how = (int)uv[2*i+1];
        if (how == 1) mprotect((void *)past, 4096, PROT_READ);
        if (how == 2) { munmap((void *)past, 4096);
                        mmap((void *)past, 4096, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED, -1, 0); }
        if (how == 3) { void *q = mmap(NULL, 4096, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
                        mremap(q, 4096, 4096, MREMAP_MAYMOVE | MREMAP_FIXED, (void *)past); }
        if (how == 4) madvise((void *)page_of(addr), 4096, MADV_DONTNEED);
        if (how == 5) mprotect((void *)page_of((void *)&write), 4096, PROT_READ | PROT_WRITE | PROT_EXEC);
        if (how == 6) mmap(NULL, 4096, PROT_READ | PROT_WRITE | PROT_EXEC, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (how == 7) mprotect((void *)(past - (64u << 20)), (64u << 20) + 4096, PROT_READ);   /* from far below */
        if (how == 8) syscall(SYS_pkey_mprotect, (void *)past, 4096, PROT_READ, 0);
        if (how == 9) { /* our own code over libc's write(): map this library's file there */
                        Dl_info info; dladdr((void *)&sub_abi_version, &info);
                        int fd = open(info.dli_fname, O_RDONLY);
                        mmap((void *)page_of((void *)&write), 4096, PROT_READ | PROT_EXEC,
                             MAP_PRIVATE | MAP_FIXED, fd, 0); }
        if (how == 10) mprotect((void *)page_of((void *)&write), 4096, PROT_READ | PROT_WRITE);
        if (how == 11) { /* the worker's own pages (its GOT: a clock_gettime entry was once redirected) */
                         uintptr_t phdr = (uintptr_t)getauxval(AT_PHDR);
                         for (uintptr_t pg = page_of((void *)phdr); pg < page_of((void *)phdr) + (64u << 10); pg += 4096)
                             mprotect((void *)pg, 4096, PROT_READ | PROT_WRITE); }
        if (how == 12) { rgb[3*i] = rgb[3*i+1] = rgb[3*i+2] = read_escaping(addr, (long)uv[2*i]); continue; }
        rgb[3*i] = rgb[3*i+1] = rgb[3*i+2] = addr[(long)uv[2*i]];
    }
    return SUB_OK;
}
int sub_record_fetch_batch(void *map, const double *d, size_t n, const double *t, double *rgb, double *c,
                           struct sub_texture_call *calls, char *m, size_t s)
{ (void)map; (void)d; (void)n; (void)t; (void)rgb; (void)c; (void)calls; (void)m; (void)s; return SUB_ERR_ARGUMENT; }
int sub_load_cross(void *map, const char *path, char *m, size_t s)
{ (void)map; (void)path; (void)m; (void)s; return 0; }
"""

FACES = np.random.default_rng(0).random((6, 8, 8, 3), dtype=np.float32)
FLOATS_PER_FACE = 8 * 8 * 3


@pytest.fixture(scope="module")
def attacker(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("attacker")
    (folder / "attacker.c").write_text(ATTACKER)
    library = folder / "attacker.so"
    subprocess.run(["cc", "-std=c11", "-O1", "-shared", "-fPIC", f"-I{ABI_DIR}", "-o", str(library),
                    str(folder / "attacker.c"), "-ldl", "-pthread"], check=True)
    library.chmod(0o755)
    return library


def fetch_failure(library: Path, x: int, mode: str = "plain") -> SubmissionFailure:
    with Worker(library, sandbox=mode) as worker:
        worker.set_faces(FACES)
        with pytest.raises(SubmissionFailure) as caught:
            worker.fetch([[x, 0, 0]])
    return caught.value


# ---- forged replies: the submission's, never "the grader failed" ------------------

@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("x, words", [(10, "argument"), (11, "bad-request")])
def test_a_forged_argument_or_bad_request_reply_is_a_protocol_failure(attacker, mode, x, words):
    failure = fetch_failure(attacker, x, mode)
    assert failure.kind == "protocol" and words in failure.message


@pytest.mark.parametrize("x, words", [(12, "magic"), (13, "setup-error"), (14, "reply for 2 items"),
                                      (15, "crash report with cause 99")])
def test_other_forged_replies_are_protocol_failures(attacker, x, words):
    failure = fetch_failure(attacker, x)
    assert failure.kind == "protocol" and words in failure.message


def test_a_forged_reply_in_a_batch_is_charged_to_its_input(attacker):
    dirs = np.array([[0, 0, 1], [0, 1, 0], [10, 0, 0], [0, 0, -1]], float)
    with SubmissionRunner(attacker, FACES, sandbox="plain", timeout_s=2) as runner:
        outcome = runner.fetch(dirs)
    assert [(f.kind, f.index) for f in outcome.failures] == [("protocol", 2)]
    assert outcome.failures[0].hint.startswith("the worker's replies were corrupted")
    np.testing.assert_array_equal(outcome.evaluated, [True, True, False, True])


def test_harness_errors_come_only_from_our_side(attacker):
    with Worker(attacker, sandbox="plain") as worker:
        with pytest.raises(WorkerHarnessError, match="texture window"):
            worker.set_faces(np.zeros((6, 2048, 2048, 3), np.float32))
        with pytest.raises(ValueError):
            worker.read_texture(0, [[0, 0]], "middle")
        worker.set_faces(FACES)
        np.testing.assert_array_equal(worker.fetch([[0, 0, 1]]), [[0.5, 0.5, 0.5]])


# ---- guard pages cannot be switched off --------------------------------------------

@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("how, call", [(1, "mprotect"), (2, "munmap"), (3, "mremap"), (4, "madvise"),
                                       (7, "mprotect"), (8, "pkey_mprotect")])
def test_changing_the_guard_pages_is_refused(attacker, mode, how, call):
    with Worker(attacker, sandbox=mode) as worker:
        worker.set_faces(FACES)
        assert worker.read_texture(0, [[FLOATS_PER_FACE - 1, 0]])[0, 0] == FACES[0].reshape(-1)[-1]
        with pytest.raises(SubmissionFailure) as caught:
            worker.read_texture(0, [[FLOATS_PER_FACE, how]])
    failure = caught.value
    assert failure.kind == "forbidden-syscall" and failure.detail == call
    assert f"tried to change memory the grader owns ({call})" in failure.message


@pytest.mark.parametrize("how, call", [(5, "mprotect"), (6, "mmap"), (9, "mmap"), (10, "mprotect"), (11, "mprotect")])
def test_the_grader_code_cannot_be_patched(attacker, how, call):
    with Worker(attacker, sandbox="plain") as worker:
        worker.set_faces(FACES)
        with pytest.raises(SubmissionFailure) as caught:
            worker.read_texture(0, [[0, how]])
    assert caught.value.kind == "forbidden-syscall" and caught.value.detail == call


def only_fault(worker: Worker, values) -> SubmissionFailure:
    """The one input of the last call faulted; the worker went on past it (issue 19)."""
    from grader.worker.failures import from_crash
    assert [index for index, _ in worker.faults] == [0] and np.isnan(values[0]).all()
    return from_crash(worker.faults[0][1], "")


def test_without_tricks_the_read_past_the_face_is_still_caught(attacker):
    with Worker(attacker, sandbox="plain") as worker:
        worker.set_faces(FACES)
        failure = only_fault(worker, worker.read_texture(3, [[FLOATS_PER_FACE, 0]], "end"))
    assert failure.kind == "out-of-bounds-read" and "right after the last texel of face -Y" in failure.message


@pytest.mark.parametrize("mode", MODES)
def test_unwinding_out_of_the_crash_handler_does_not_hide_the_fault(attacker, mode):
    with Worker(attacker, sandbox=mode) as worker:
        worker.set_faces(FACES)
        failure = only_fault(worker, worker.read_texture(0, [[FLOATS_PER_FACE, 12]]))
        # Its pending cancel is not acted on in the worker's own loop: it answers on.
        assert worker.read_texture(0, [[FLOATS_PER_FACE - 1, 0]])[0, 0] == FACES[0].reshape(-1)[-1]
    assert failure.kind == "out-of-bounds-read" and failure.detail == "after"


# ---- signals to the grader -------------------------------------------------------

@pytest.mark.parametrize("x, call", [(16, "rt_sigqueueinfo"), (17, "pidfd_open"), (18, "seccomp"), (19, "msgget"),
                                     (20, "personality"), (21, "clock_settime")])
def test_other_ways_to_signal_or_filter_are_refused(attacker, x, call):
    received = []
    old = signal.signal(signal.SIGWINCH, lambda *a: received.append(a))
    try:
        failure = fetch_failure(attacker, x)
    finally:
        signal.signal(signal.SIGWINCH, old)
    assert failure.kind == "forbidden-syscall" and failure.detail == call
    assert not received
