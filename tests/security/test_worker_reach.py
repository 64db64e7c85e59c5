"""Workers cannot reach each other (issue 18): an attacker worker tries each
way of signalling a victim worker started beside it, in the same mode; the
victim is unharmed (alive, not stopped, still answering) and the attacker's
call is refused. A thread bomb stops at the worker's own limit.

The attacker implements grader/build/shim/submission_abi.h directly: fetchColor's
direction (pid, path, 0) tries signal path `path` on `pid` and answers 1 in
red when the kernel accepted the call, 0 when it refused it.
"""
from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from grader import PROJECT_ROOT
from grader.worker import Limits, SubmissionFailure, Worker, sandbox, uids
from grader.worker.native import null_library

pytestmark = [pytest.mark.sandbox]

BWRAP = sandbox.sandbox_problem()
DROP = sandbox.privilege_drop_problem()
ISOLATED = [pytest.param("sandbox", marks=pytest.mark.skipif(BWRAP is not None, reason=f"no bubblewrap: {BWRAP}")),
            pytest.param("privilege-drop", marks=pytest.mark.skipif(DROP is not None, reason=f"no privilege drop: {DROP}"))]

@pytest.fixture(autouse=True)
def victims_run_between_calls(monkeypatch):
    """A worker stopped between calls (issue 32) would hide a SIGSTOP sent by
    the worker beside it, and the grader's SIGCONT would undo it: here they
    run between calls, so a stop can only be the attacker's."""
    monkeypatch.setattr(Worker, "stop_between_calls", False)


ATTACKER = r"""
#define _GNU_SOURCE
#include "submission_abi.h"
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/syscall.h>
#include <linux/sockios.h>
#include <unistd.h>

static void *sleep_forever(void *unused) { (void)unused; for (;;) pause(); return NULL; }

/* 1 when the kernel accepted the attack, 0 when it refused it. */
static int attack(pid_t pid, int path)
{
    int p[2];
    if (pipe(p) != 0) return 0;
    int ok = 0;
    switch (path) {
    case 1: ok = kill(pid, SIGSTOP) == 0; break;
    case 2: /* the kernel sends SIGSTOP to the pipe's owner when it becomes readable */
        ok = fcntl(p[0], F_SETOWN, pid) == 0 && fcntl(p[0], F_SETSIG, SIGSTOP) == 0 &&
             fcntl(p[0], F_SETFL, O_ASYNC | O_NONBLOCK) == 0 && write(p[1], "x", 1) == 1; break;
    case 3: { struct f_owner_ex owner = { F_OWNER_PID, pid };
        ok = fcntl(p[0], F_SETOWN_EX, &owner) == 0 && fcntl(p[0], F_SETFL, O_ASYNC) == 0 && write(p[1], "x", 1) == 1;
        break; }
    case 4: { int on = 1; ok = ioctl(p[0], FIOSETOWN, &pid) == 0 && ioctl(p[0], FIOASYNC, &on) == 0; break; }
    case 5: ok = ioctl(p[0], SIOCSPGRP, &pid) == 0; break;
    case 6: ok = ioctl(p[0], TIOCSPGRP, &pid) == 0; break;
    case 7: { siginfo_t si; memset(&si, 0, sizeof si); si.si_code = SI_QUEUE;
        ok = syscall(SYS_rt_sigqueueinfo, pid, SIGSTOP, &si) == 0; break; }
    case 8: { int fd = (int)syscall(SYS_pidfd_open, pid, 0);
        ok = fd >= 0 && syscall(SYS_pidfd_send_signal, fd, SIGSTOP, NULL, 0) == 0; break; }
    case 9: ok = syscall(SYS_tgkill, pid, pid, SIGSTOP) == 0; break;
    case 10: ok = fcntl(p[0], F_SETSIG, SIGKILL) == 0; break;      /* alone, on its own pipe */
    case 11: { int on = 1; ok = ioctl(p[0], FIOASYNC, &on) == 0; break; }
    }
    close(p[0]); close(p[1]);
    return ok;
}

/* Threads (small stacks, asleep) until the kernel refuses one. */
static int thread_bomb(void)
{
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    pthread_attr_setstacksize(&attr, 16384);
    int made = 0;
    pthread_t t;
    while (made < 5000 && pthread_create(&t, &attr, sleep_forever, NULL) == 0)
        made++;
    return made;
}

int sub_abi_version(void) { return SUB_ABI_VERSION; }
void *sub_create(char *m, size_t s) { (void)m; (void)s; return calloc(1, 8); }
void sub_destroy(void *map) { free(map); }
int sub_set_faces(void *map, const float *t, int w, int h, char *m, size_t s)
{ (void)map; (void)t; (void)w; (void)h; (void)m; (void)s; return SUB_OK; }
int sub_fetch_batch(void *map, const double *d, size_t n, double *rgb, char *m, size_t s)
{
    (void)map; (void)m; (void)s;
    for (size_t i = 0; i < n; i++) {
        int path = (int)d[3*i+1];
        rgb[3*i] = path == 99 ? thread_bomb() : path ? attack((pid_t)d[3*i], path) : 0.25;
        rgb[3*i+1] = rgb[3*i+2] = 0.25;
    }
    return SUB_OK;
}
int sub_read_texture_batch(void *map, const float *a, const double *uv, size_t n, double *rgb, char *m, size_t s)
{ (void)map; (void)a; (void)uv; (void)m; (void)s; memset(rgb, 0, n * 24); return SUB_OK; }
int sub_record_fetch_batch(void *map, const double *d, size_t n, const double *t, double *rgb, double *c,
                           struct sub_texture_call *calls, char *m, size_t s)
{ (void)map; (void)d; (void)n; (void)t; (void)rgb; (void)c; (void)calls; (void)m; (void)s; return SUB_ERR_ARGUMENT; }
int sub_load_cross(void *map, const char *path, char *m, size_t s)
{ (void)map; (void)path; (void)m; (void)s; return 0; }
"""

FACES = np.full((6, 4, 4, 3), 0.5, np.float32)
# path: the name of the call the filter traps, or None where it only fails.
PATHS = {1: "kill", 2: "fcntl F_SETOWN", 3: "fcntl F_SETOWN_EX", 4: "ioctl FIOSETOWN", 5: "ioctl SIOCSPGRP",
         6: "ioctl TIOCSPGRP", 7: "rt_sigqueueinfo", 8: "pidfd_open", 9: "tgkill", 10: "fcntl F_SETSIG",
         11: "ioctl FIOASYNC"}


@pytest.fixture(scope="module")
def attacker(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("reach")
    folder.chmod(0o755)
    (folder / "attacker.c").write_text(ATTACKER)
    library = folder / "attacker.so"
    subprocess.run(["cc", "-std=c11", "-O1", "-shared", "-fPIC", f"-I{PROJECT_ROOT / 'grader' / 'build' / 'shim'}",
                    "-o", str(library), str(folder / "attacker.c"), "-pthread"], check=True)
    library.chmod(0o755)
    return library


def state(pid: int) -> str:
    with open(f"/proc/{pid}/stat") as f:
        return f.read().rpartition(")")[2].split()[0]


def uid_of(pid: int) -> int:
    with open(f"/proc/{pid}/status") as f:
        return int(next(line for line in f if line.startswith("Uid:")).split()[1])


def assert_unharmed(victim: Worker) -> None:
    assert victim.alive and state(victim._worker_pid) not in ("T", "t")
    assert victim.fetch([[1, 0, 0]], timeout_s=10)[0, 1] == 0.25


@pytest.mark.parametrize("mode", ISOLATED)
@pytest.mark.parametrize("path", sorted(PATHS))
def test_a_worker_cannot_signal_the_worker_beside_it(attacker, mode, path):
    with Worker(attacker, sandbox=mode) as victim, Worker(attacker, sandbox=mode) as worker:
        victim.set_faces(FACES)
        worker.set_faces(FACES)
        # The victim's pid as the attacker would name it: ours, or (own pid
        # namespace) any small number it could guess.
        try:
            answer = worker.fetch([[victim._worker_pid, path, 0]], timeout_s=10)[0, 0]
        except SubmissionFailure as failure:
            assert failure.kind == "forbidden-syscall" and PATHS[path] in failure.message, failure.message
        else:
            assert answer == 0, f"path {path} ({PATHS[path]}) was accepted by the kernel"
        assert_unharmed(victim)


@pytest.mark.parametrize("namespace", [True, False], ids=["own-pid-namespace", "uid-only"])
@pytest.mark.parametrize("path", [1, 2, 3, 7, 9])
@pytest.mark.skipif(DROP is not None, reason=f"no privilege drop: {DROP}")
def test_without_the_filter_the_uid_and_namespace_still_keep_workers_apart(attacker, monkeypatch, namespace,
                                                                           path):
    """The filter off: what the kernel itself refuses in privilege-drop mode
    (another uid; another pid namespace). Every worker was uid nobody before."""
    monkeypatch.setattr(Worker, "try_pid_namespace", namespace)
    unfiltered = Limits(seccomp=False)
    with Worker(attacker, sandbox="privilege-drop") as victim, \
            Worker(attacker, sandbox="privilege-drop", limits=unfiltered) as worker:
        victim.set_faces(FACES)
        worker.set_faces(FACES)
        assert worker.pid_namespace is namespace
        accepted = worker.fetch([[victim._worker_pid, path, 0]], timeout_s=10)[0, 0]
        if path in (1, 7, 9):      # a direct signal: refused by the kernel
            assert accepted == 0
        # F_SETOWN is accepted; the kernel drops the signal at delivery (other uid).
        assert_unharmed(victim)


@pytest.mark.skipif(DROP is not None, reason=f"no privilege drop: {DROP}")
def test_each_privilege_drop_worker_has_a_uid_of_its_own(attacker):
    from grader.build.compiler import BUILD_UID
    with Worker(attacker, sandbox="privilege-drop") as a, Worker(null_library(), sandbox="privilege-drop") as b:
        seen = {uid_of(a._worker_pid), uid_of(b._worker_pid)}
        assert len(seen) == 2 and not seen & {0, 65534, BUILD_UID}
        assert all(uids.FIRST_UID <= uid < uids.FIRST_UID + uids.COUNT for uid in seen)
        assert a.pid_namespace and "own pid namespace" in a.confinement


@pytest.mark.parametrize("mode", ISOLATED)
def test_a_thread_bomb_stops_at_the_workers_limit(attacker, mode):
    limits = Limits(processes=32)
    with Worker(attacker, sandbox="plain") as victim, Worker(attacker, sandbox=mode, limits=limits) as worker:
        victim.set_faces(FACES)
        worker.set_faces(FACES)
        made = worker.fetch([[0, 99, 0]], timeout_s=20)[0, 0]
        assert 0 < made < limits.processes
        assert_unharmed(victim)


@pytest.mark.skipif(BWRAP is not None or os.geteuid() != 0, reason="bubblewrap run as root")
def test_under_bubblewrap_as_root_each_worker_has_a_uid_of_its_own_and_no_network(attacker):
    """As root, bwrap runs without a user namespace (one would map the
    sandbox's nobody to root, exempt from RLIMIT_NPROC); the worker switches
    to its own uid itself. Its other namespaces are still its own."""
    with Worker(attacker, sandbox="sandbox") as a, Worker(attacker, sandbox="sandbox") as b:
        seen = {uid_of(a._worker_pid), uid_of(b._worker_pid)}
        assert len(seen) == 2 and all(uids.FIRST_UID <= uid < uids.FIRST_UID + uids.COUNT for uid in seen)
        for kind in ("net", "pid", "mnt", "ipc"):
            assert os.readlink(f"/proc/{a._worker_pid}/ns/{kind}") != os.readlink(f"/proc/self/ns/{kind}")
        with open(f"/proc/{a._worker_pid}/status") as f:
            caps = {line.split()[0]: int(line.split()[1], 16) for line in f if line.startswith("Cap")}
        assert caps["CapEff:"] == caps["CapPrm:"] == 0


@pytest.mark.parametrize("mode", ISOLATED)
def test_the_zoos_thread_bomb_is_refused_at_the_limit_while_loading(mode):
    """tests/submissions/runtime_attacks/thread_bomb.cpp (C++, 16 KiB stacks):
    the kernel refuses its 64th task, which it throws, uncaught: std::terminate."""
    from grader.build import build_submission
    built = build_submission(PROJECT_ROOT / "tests" / "submissions" / "runtime_attacks" / "thread_bomb.cpp")
    assert built.ok, built.log
    worker = Worker(built.library, sandbox=mode)
    with pytest.raises(SubmissionFailure) as caught:
        worker.start()
    worker.close()
    assert caught.value.kind == "exception" and "what():  no more threads" in caught.value.output
