"""Worker: one worker process (worker.c) with one submission loaded in it.

It runs in the isolation mode sandbox.resolve_mode settles (bubblewrap,
privilege-drop, or unsafe-none only when allowed), in a fresh temporary
directory, with an almost empty environment and resource limits set by
worker.c itself. The first message (SANDBOXED, sent before the submission is
loaded) is the only one believed; everything after it is the submission's. Requests go over a private pipe pair; fds 1 and 2 go to a
capped capture (capture.py). Every call has its own time limit, in the
worker's CPU time (the submission's work), with a wall-clock outer bound
(wall_bound) for code that sleeps: on expiry the worker's process group is
killed and the call raises SubmissionFailure(kind="timeout"); at the wall
bound it is marked grader_limit (a busy machine can reach it too). Anything else the submission does wrong
raises SubmissionFailure too (failures.py), including replies that blame
the grader; only the grader's own problems raise WorkerHarnessError.
"""
from __future__ import annotations

import contextlib
import fcntl
import functools
import mmap
import os
import select
import shutil
import signal
import struct
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..i18n import N_, _
from . import protocol
from .capture import CappedOutput
from .failures import (EXCEPTION, EXITED, FORBIDDEN_SYSCALL, LOAD_ERROR, PROTOCOL, TIMEOUT, SubmissionFailure, from_crash,
                       signal_name)
from . import memory, uids
from .native import worker_binary
from .sandbox import INPUT_INSIDE, ISOLATION, bwrap_command, resolve_mode

LIBRARY_NAME = "submission.so"
# A call's time limit is CPU time of the worker (the submission's work); the
# wall clock is only an outer bound this much more generous, for code that
# sleeps. Under load a correct call's wall time stretches with the queue for
# a core, never its CPU time (issue 21: set_faces took 0.21 s of its 0.5 s
# wall-clock limit at load 15 on 2 cores, and a timeout there became a
# failure to load the submission).
WALL_FACTOR, WALL_SLACK_S = 4.0, 1.0
# The bound also stretches by the time the call waited for a core (WallBound,
# issue 32: at load 30 on one core a worker gets about 1/32 of it, and a call
# spinning to its 0.3 s CPU limit took 10 s, past its 2.2 s bound), by at
# most this many bounds. The cap because the wait is not always the machine's
# doing: the worker's main thread may lower its own priority (seccomp lets a
# thread put itself at SCHED_IDLE or nice 19), and at SCHED_IDLE on a busy
# machine it waits without end while its CPU time, and so its CPU limit, does
# not move; capped, such a call still ends within 9 bounds. Under load L per
# core a call at its CPU limit t waits about L t, L t / (4 t + 1) < L / 4
# bounds: 8 covers load 32 per core at any limit.
WALL_STRETCH_MAX = 8.0
# The first input a worker evaluates may take this much CPU time beyond its
# call's limit (Worker._over_limit): a lookup that builds its tables (or a
# cache) on its first call does the work a static initialiser may do in
# start_timeout_s, and every check that starts a fresh worker pays it again
# (issue 30: resources/memory_hog.cpp fills 1 GiB on its first call, 0.4-0.8 s
# of CPU against the 0.5 s limit, and scored 98.32 or 90 by the draw). Only
# the first input's own time is forgiven, as the progress page shows it: a
# lookup that hangs later in the call gets the usual limit.
FIRST_INPUT_S = 2.0
_LOOKUPS = (protocol.FETCH, protocol.FETCH_WHOLE, protocol.READ_TEXTURE, protocol.RECORD_FETCH, protocol.TIME_FETCH)


def wall_bound(timeout_s: float) -> float:
    return WALL_FACTOR * timeout_s + WALL_SLACK_S


def _schedstat(pid: int, tid: int | None = None) -> tuple[int, int] | None:
    """(ns on a core, ns runnable but waiting for one) of thread `tid` of
    process `pid` (its main thread when None) since it began: the first two
    fields of /proc/<pid>/task/<tid>/schedstat (CONFIG_SCHED_INFO; no
    schedstats sysctl needed, readable by any uid). None where the file
    cannot be read: the task is gone, /proc hides other uids' processes
    (hidepid), the kernel has no such file."""
    try:
        with open(f"/proc/{pid}/task/{pid if tid is None else tid}/schedstat") as f:
            fields = [int(x) for x in f.read().split()[:3]]
    except (OSError, ValueError):
        return None
    return (fields[0], fields[1]) if len(fields) == 3 else None


@functools.cache
def _schedstat_counts() -> bool:
    """The kernel fills schedstat in: ours, which has run, is not "0 0 0"
    (what it says with sched_info accounting off)."""
    return any(_schedstat(os.getpid()) or ())


def run_queue_wait_ns(pid: int, tid: int | None = None) -> int | None:
    """How long (ns) thread `tid` of process `pid` (its main thread when
    None) has been runnable but waiting for a core since it began: the
    scheduler's run_delay (_schedstat). None where it cannot be read, or the
    kernel does not count it."""
    stat = _schedstat(pid, tid)
    return stat[1] if stat is not None and _schedstat_counts() else None


def thread_run_ns(pid: int, tid: int) -> int | None:
    """How long (ns) thread `tid` of process `pid` has run on a core (0: not
    yet). None where it cannot be read, or the kernel does not count it."""
    stat = _schedstat(pid, tid)
    return stat[0] if stat is not None and _schedstat_counts() else None


class WallBound:
    """The wall-clock outer bound of one call (or of loading the submission):
    `seconds` from now, stretched by the time the worker's main thread has
    waited for a core since, at most WALL_STRETCH_MAX times `seconds`. The
    main thread serves every request (static initialisers included). Not
    counted: the threads the submission starts (at SCHED_IDLE they wait for
    a core by design, and serve no request), nor the grader's thread, which
    wakes every _WATCH_S to watch the call: on a loaded machine it waits at
    each wake, and counting that stretched the bound of a call that only
    sleeps by most of its length (make test-load). Where the main thread's
    wait cannot be read (run_queue_wait_ns) the bound is unstretched."""

    # /proc is read only when the bound is this close: most calls end long before.
    _REFRESH_S = 0.1

    def __init__(self, seconds: float, worker_pid: int | None = None):
        self.seconds = seconds
        self.began = time.monotonic()
        self.stretch_s = 0.0
        self._worker: tuple[int, int] | None = None     # (pid, its wait when the bound began)
        if worker_pid is not None:
            self.watch_worker(worker_pid)

    def watch_worker(self, pid: int, born_inside: bool = False) -> None:
        """Count what the worker's main thread waits from now on (born_inside:
        all it ever waited, as it began inside this bound)."""
        wait = run_queue_wait_ns(pid)
        if wait is not None:
            self._worker = pid, 0 if born_inside else wait

    def refresh(self) -> float:
        """Read the main thread's wait now; the stretch (s)."""
        if self._worker is not None:
            now = run_queue_wait_ns(self._worker[0])
            if now is not None:
                waited = (now - self._worker[1]) / 1e9
                self.stretch_s = min(WALL_STRETCH_MAX * self.seconds, max(self.stretch_s, waited))
        return self.stretch_s

    def end(self) -> float:
        """When the bound is reached, as far as is known now (monotonic s)."""
        end = self.began + self.seconds + self.stretch_s
        if self._worker is not None and end - time.monotonic() < self._REFRESH_S:
            end = self.began + self.seconds + self.refresh()
        return end

    def left(self) -> float:
        return max(0.0, self.end() - time.monotonic())


_NO_PROGRESS = (1 << 64) - 1     # the progress page before the worker wrote it
_WATCH_S = 0.02                   # how often the progress page is looked at during a long call
PIPE_BYTES = 1 << 20


class WorkerHarnessError(RuntimeError):
    """The grader's side went wrong (a bad request, a worker that cannot
    start): never charged to the student."""


@dataclass(frozen=True)
class Limits:
    address_space_mb: int | None = 2048   # None: unlimited (AddressSanitizer builds need that)
    cpu_seconds: int | None = 120         # over the worker's life: a backstop to the per-call limits
    file_size_bytes: int = 0              # no file may grow (writes are refused by seccomp anyway)
    processes: int = 64                   # threads included: the worker's uid's tasks (see _nproc_limit)
    open_files: int = 64                  # RLIMIT_NOFILE: what pipes and memfds it can pin (memory.py)
    pending_signals: int = 64             # RLIMIT_SIGPENDING: queued signals, and so POSIX timers
    seccomp: bool = True
    texture_mb: int = 24                  # the largest six-face texture window (512 x 512 faces need 18 MiB)


def _enlarge_pipe(fd: int) -> None:
    """Fewer round trips through the kernel for large batches (Linux only;
    the default 64 KiB works too)."""
    try:
        fcntl.fcntl(fd, getattr(fcntl, "F_SETPIPE_SZ", 1031), PIPE_BYTES)
    except OSError:
        pass


def _wait(proc: subprocess.Popen, timeout: float) -> int:
    """proc.wait(timeout), woken by its exit (a pidfd) rather than by
    Popen.wait's polling, which sleeps 0.5, 1, 2 ms...: a worker's close
    took about 2 ms more. Raises subprocess.TimeoutExpired the same way."""
    if proc.returncode is None:
        try:
            fd = os.pidfd_open(proc.pid)
        except (AttributeError, OSError):    # an old kernel, or it is gone
            fd = -1
        if fd >= 0:
            try:
                select.select([fd], [], [], timeout)
            finally:
                os.close(fd)
            timeout = 0.0
    return proc.wait(timeout=timeout)


def _children(pid: int) -> list[int]:
    """pid's child processes: /proc/<pid>/task/<tid>/children, or (a kernel
    without CONFIG_PROC_CHILDREN) every process whose parent is pid."""
    try:
        out = []
        for task in os.listdir(f"/proc/{pid}/task"):
            with open(f"/proc/{pid}/task/{task}/children") as f:
                out += [int(c) for c in f.read().split()]
        return out
    except FileNotFoundError:
        pass
    except OSError:
        return []
    out = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    if int(f.read().rpartition(")")[2].split()[1]) == pid:
                        out.append(int(entry))
            except (OSError, IndexError, ValueError):
                continue
    return out


def _descendants(pid: int) -> list[int]:
    """pid and every process below it (bubblewrap starts the worker as a
    grandchild)."""
    found, queue = [], [pid]
    while queue:
        p = queue.pop()
        found.append(p)
        queue += _children(p)
    return found


def find_worker_pid(top: int, binary: Path) -> int | None:
    """The worker's pid in our namespace, found from outside and verified:
    the one process under `top` whose executable is our worker binary (same
    inode; the sandbox bind-mounts the same file). Looked up right after the
    set-up message, before any student code runs. None where /proc cannot say."""
    try:
        want = os.stat(binary)
    except OSError:
        return None
    found = None
    for pid in _descendants(top):   # parents before children
        try:
            exe = os.stat(f"/proc/{pid}/exe")
        except OSError:
            continue
        if (exe.st_dev, exe.st_ino) == (want.st_dev, want.st_ino):
            found = pid     # the deepest: in its own pid namespace the worker runs under two relays of itself
    return found


def _tasks_of_uid(uid: int) -> int:
    """Threads of every process whose owner is `uid` (what RLIMIT_NPROC counts)."""
    count = 0
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                if os.stat(f"/proc/{entry}").st_uid == uid:
                    count += len(os.listdir(f"/proc/{entry}/task"))
            except OSError:
                continue
    return count


def process_cpu_ns(pid: int) -> int:
    """CPU time (user + system, all threads, living and exited) the kernel
    has charged to process `pid`, in ns: its process CPU-time clock, read
    from outside (clock id MAKE_PROCESS_CPUCLOCK(pid, CPUCLOCK_SCHED))."""
    return time.clock_gettime_ns(((~pid) << 3) | 2)


_TICK_NS = 10**9 // os.sysconf("SC_CLK_TCK")


def tree_cpu_ns(pid: int) -> int:
    """CPU time of `pid` and every process below it, living or reaped by
    one of them (utime + stime + cutime + cstime each): what a build step's
    processes have used, read from outside. 0 once it is gone."""
    total = 0
    for p in _descendants(pid):
        try:
            with open(f"/proc/{p}/stat") as f:
                fields = f.read().rpartition(")")[2].split()
            total += sum(int(x) for x in fields[11:15])
        except (OSError, ValueError, IndexError):
            continue
    return total * _TICK_NS


def tree_run_queue_waits_ns(pid: int) -> dict[int, int]:
    """What each thread of `pid` and of every process below it has waited
    for a core (run_queue_wait_ns), by thread id; threads whose wait cannot
    be read are left out. {} once it is gone."""
    waits = {}
    for p in _descendants(pid):
        try:
            tids = [int(t) for t in os.listdir(f"/proc/{p}/task")]
        except (OSError, ValueError):
            continue
        for tid in tids:
            wait = run_queue_wait_ns(p, tid)
            if wait is not None:
                waits[tid] = wait
    return waits


def _all_stopped(pid: int) -> bool:
    """Every thread of `pid` is stopped (state T or t in /proc)."""
    try:
        for task in os.listdir(f"/proc/{pid}/task"):
            with open(f"/proc/{pid}/task/{task}/stat") as f:
                state = f.read().rpartition(")")[2].split()[0]
            if state not in ("T", "t"):
                return False
    except (OSError, IndexError):
        return True   # gone: nothing runs
    return True


def _stopped_itself(pid: int | None) -> bool:
    """The worker is there and every thread of it is stopped (state T):
    what a SIGSTOP does, which nothing but the worker itself (or freeze())
    sends it, as it runs in a session of its own."""
    if pid is None:
        return False
    try:
        if not os.listdir(f"/proc/{pid}/task"):
            return False
    except OSError:
        return False
    return _all_stopped(pid)


class Worker:
    """A worker process serving one submission. Use as a context manager, or
    call close(). `mode` is "sandbox" (bubblewrap), "privilege-drop" or
    "plain"; `isolation` says the same in the words reports use; `warning`
    is the sentence for the report when no isolation was possible and the
    caller allowed that (allow_unsafe). Raises SandboxUnavailable when no
    isolation is possible and allow_unsafe is False."""

    # Privilege-drop mode: ask for a pid namespace of its own (the worker
    # falls back without one where the container refuses; `pid_namespace`
    # says which held). Tests turn it off to see the uid's wall alone.
    try_pid_namespace = True
    # Between calls the worker is stopped (SIGSTOP): a submission costs CPU
    # only while the grader is asking it something (issue 32). Tests that
    # watch for a stop sent by another worker turn it off.
    stop_between_calls = True
    # Every thread but the main one at SCHED_IDLE (_demote_threads). Tests of
    # the stop itself turn it off: a thread that really runs is the hard case.
    demote_threads = True

    def __init__(self, library: str | os.PathLike, *, sandbox: str = "auto", limits: Limits = Limits(),
                 preload: tuple[str, ...] = (), output_head: int = 8192, output_tail: int = 8192,
                 start_timeout_s: float = 15.0, allow_unsafe: bool = False,
                 texture_shape: tuple[int, int] | None = None, first_input_s: float = FIRST_INPUT_S):
        self.library = Path(library)
        self.first_input_s = first_input_s
        self.limits = limits
        self.mode, self.warning = resolve_mode(sandbox, allow_unsafe)
        self._preload = preload
        self._cap = (output_head, output_tail)
        self._start_timeout_s = start_timeout_s
        self._proc: subprocess.Popen | None = None
        self._output: CappedOutput | None = None
        self._tmp: Path | None = None
        self._request_fd = self._response_fd = -1
        self._gate = -1          # prepared: the write end of the worker's gate (prepare, start)
        self._binary: Path | None = None
        self._worker_pid: int | None = None
        self._progress: mmap.mmap | None = None
        # (progress value, when first seen, the worker's CPU ns then), watched
        # while a reply is awaited; `stuck` is what it showed at a timeout.
        self._watch: tuple[int | None, float, int | None] | None = None
        self.stuck: tuple[int, float, float] | None = None
        self._frozen = False     # stopped by freeze(), not by itself
        self._demoted: set[int] = set()   # its threads put at SCHED_IDLE (_demote_threads)
        self._moved: set[int] = set()     # and moved to the grading's idle cpu cgroup
        self._killed = False     # ended by us (a failure, close()): no call may follow
        self.start_time_s = 0.0
        # The current call's CPU-time limit: (the worker's CPU ns at its start, limit ns).
        self._cpu_limit: tuple[int, int] | None = None
        self._lookups_done = 0   # lookup calls answered: the first one's first input gets first_input_s
        self.spun_first_input = False   # timed out on its first input with the allowance (_timeout)
        # In a worker's first lookup call: None while its first input runs,
        # then the CPU ns forgiven for it (at most FIRST_INPUT_S). 0 in other calls.
        self._first_input_ns: int | None = 0
        self._wall_only = float("inf")   # where the CPU clock cannot be read: the call's limit on the wall clock
        self._waited_ns = 0     # what its main thread had waited for a core, when last read (waited_s)
        self._last_cpu = 0      # ns, the last time it was read
        # The inputs of the last FETCH or READ_TEXTURE that faulted, (index,
        # protocol.CrashReport) each; the worker went on past them.
        self.faults: list[tuple[int, protocol.CrashReport]] = []
        self._uid: uids.WorkerUid | None = None      # privilege-drop: a uid no other process has
        # Where its memory is charged (memory.py), and the OOM kills counted
        # there (or on the machine) before its current call: a SIGKILL that
        # raised the count is the kernel's, for the memory it held.
        self._cgroup: memory.GradingCgroup | None = None
        self._idle_cgroup: memory.GradingCgroup | None = None    # where its demoted threads go (memory.idle_cgroup)
        self._oom_before = 0
        self.pid_namespace = False                  # privilege-drop: whether its own pid namespace held
        self.size_for(texture_shape)                # (H, W) of the faces this worker is for

    def size_for(self, texture_shape: tuple[int, int] | None) -> None:
        """The six-face window for faces of `texture_shape` (H, W), sized to
        them exactly, so a read before the first texel faults in either
        placement; None: the largest window (Limits.texture_mb). Before
        start() only (a prepared worker takes the size it is started for)."""
        if self._proc is not None and not self.prepared:
            raise WorkerHarnessError("a started worker's window keeps its size")
        limits = self.limits
        texture_bytes = (texture_shape[0] * texture_shape[1] * 72 if texture_shape else limits.texture_mb << 20)
        if not 0 < texture_bytes <= limits.texture_mb << 20:
            raise WorkerHarnessError(f"faces of {texture_shape} do not fit the {limits.texture_mb} MiB texture "
                                     "window (Limits.texture_mb)")
        self.texture_bytes = texture_bytes

    @property
    def isolation(self) -> str:
        return ISOLATION[self.mode]

    @property
    def confinement(self) -> str:
        """What kept this worker from other processes, in words (once started)."""
        if self.mode == "sandbox":
            return ("bubblewrap: own pid and network namespaces, "
                    + ("a uid of its own" if self._uid else "its own user namespace"))
        if self.mode == "privilege-drop":
            return ("privilege-drop: a uid of its own, " + ("its own pid namespace" if self.pid_namespace
                                                         else "no pid namespace (not allowed here)"))
        return "unsafe-none: the grader's uid"

    # ---- life cycle -------------------------------------------------------

    def __enter__(self) -> "Worker":
        self.start()
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @property
    def alive(self) -> bool:
        return self._proc is not None and self._proc.poll() is None

    def prepare(self) -> None:
        """Everything of start() that does not depend on the faces' size or
        run student code: the worker's files, pipes and uid, the shell that
        joins the grading's cgroups (memory.charged), the sandbox, and the
        worker's own set-up up to its gate (--texture-bytes-fd), where it
        waits for start() to give the size. A worker prepared ahead
        (SubmissionRunner's spare) has done all that while the grading did
        other work: joining a cgroup alone waits for an RCU grace period when
        none has passed lately (about 10 ms on an idle machine), bubblewrap's
        namespaces and the worker's exec take about 4 ms more."""
        if self._proc is not None:
            raise WorkerHarnessError("worker already prepared")
        binary = worker_binary()
        self._tmp = Path(tempfile.mkdtemp(prefix="envmap-worker-"))
        input_dir, cwd = self._tmp / "input", self._tmp / "cwd"
        input_dir.mkdir()
        cwd.mkdir()
        if self.mode != "plain":
            # The worker's whole world after chroot (or its /sandbox/input):
            # root-owned, read-only to the worker's uid, holding only the
            # submission (and a cross for load_cross).
            input_dir.chmod(0o755)
        shutil.copyfile(self.library, input_dir / LIBRARY_NAME)
        (input_dir / LIBRARY_NAME).chmod(0o644)
        request_r, request_w = os.pipe()
        response_r, response_w = os.pipe()
        output_r, output_w = os.pipe()
        for fd in (request_w, response_w):
            _enlarge_pipe(fd)
        # A page both sides map: the worker writes the index of the input it
        # is about to evaluate, readable here after a crash or a timeout.
        progress_fd = os.memfd_create("envmap-progress", os.MFD_CLOEXEC)
        os.ftruncate(progress_fd, mmap.PAGESIZE)
        self._progress = mmap.mmap(progress_fd, mmap.PAGESIZE)
        gate_r, gate_w = os.pipe()
        args = self._limit_args() + ["--texture-bytes-fd", str(gate_r), "--progress-fd", str(progress_fd),
                                     str(request_r), str(response_w)]
        env = {"PATH": "/usr/bin:/bin", "LANG": "C"}
        if self._preload:
            env["LD_PRELOAD"] = ":".join(self._preload)
        if self.mode in ("sandbox", "privilege-drop") and os.geteuid() == 0:
            # A uid no other process has while this worker lives: no signal
            # reaches another worker, and RLIMIT_NPROC bounds this one's threads.
            try:
                self._uid = uids.acquire()
            except (uids.UidsUnavailable, OSError) as exc:
                raise WorkerHarnessError(f"no uid for the worker: {exc}") from exc
        uid = str(self._uid.uid) if self._uid else ""
        if self.mode == "sandbox":
            own = ["--uid", uid, "--gid", uid] if uid else []
            cmd = bwrap_command(binary, input_dir, own + args + [f"{INPUT_INSIDE}/{LIBRARY_NAME}"], env,
                                as_root=bool(uid))
        elif self.mode == "privilege-drop":
            cmd = [str(binary), "--chroot", str(input_dir), "--uid", uid, "--gid", uid,
                   *(["--pid-namespace"] if self.try_pid_namespace else []), *args, f"/{LIBRARY_NAME}"]
        else:
            cmd = [str(binary), *args, str(input_dir / LIBRARY_NAME)]
        # oom_score_adj 1000 and the grading's memory and cpu cgroups, before anything runs.
        self._cgroup = memory.current()
        self._idle_cgroup = memory.idle_cgroup()
        cmd = memory.charged(cmd)
        try:
            self._proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=output_w, stderr=output_w,
                                          pass_fds=(request_r, response_w, progress_fd, gate_r), start_new_session=True,
                                          env=env, cwd=cwd, close_fds=True)
        except OSError as exc:
            for fd in (request_r, request_w, response_r, response_w, output_r, output_w, progress_fd, gate_r, gate_w):
                os.close(fd)
            raise WorkerHarnessError(f"cannot start the worker: {exc}") from exc
        for fd in (request_r, response_w, output_w, progress_fd, gate_r):
            os.close(fd)
        self._gate = gate_w
        self._binary = binary
        self._request_fd, self._response_fd = request_w, response_r
        os.set_blocking(self._request_fd, False)
        self._output = CappedOutput(output_r, *self._cap)

    @property
    def prepared(self) -> bool:
        """Prepared and not yet started."""
        return self._gate >= 0

    def start(self) -> None:
        """Start the worker (preparing it first where prepare() was not
        called) and load the submission (its static initialisers run now).
        Raises SubmissionFailure when loading fails."""
        if self._proc is None:
            self.prepare()
        elif not self.prepared:
            raise WorkerHarnessError("worker already started")
        began = time.monotonic()
        binary = self._binary
        # Counted from here, not from prepare(): OOM kills of an earlier worker are not this one's.
        self._oom_before = self._oom_kills()
        # Begun before the worker is: all its main thread ever waits for a core is inside it.
        deadline = WallBound(wall_bound(self._start_timeout_s))
        gate, self._gate = self._gate, -1
        try:
            os.write(gate, struct.pack("=Q", self.texture_bytes))
        except OSError:
            pass    # it ended before its gate (killed meanwhile): its set-up report, or its exit, says so below
        finally:
            os.close(gate)
        try:
            self._setup(binary, deadline)
            self._limit_cpu(self._start_timeout_s)    # static initialisers: the submission's work
            status, count, payload = self._receive(None, None, deadline, N_("loading the submission"))
            if status != protocol.READY or count != protocol.ABI_VERSION:
                self._fail(PROTOCOL, f"expected the ready message, got status {protocol.STATUS_NAMES[status]}")
        except BaseException:
            self.close()
            raise
        self._idle()
        self.start_time_s = time.monotonic() - began

    def _setup(self, binary: Path, deadline: WallBound) -> None:
        """The worker's first message, written before any student code ran:
        the only one we trust. A set-up failure is ours, not the student's."""
        head = self._read_exact(protocol.HEADER.size, deadline, "setting up the worker")
        if head is None:
            self._finish()
            raise WorkerHarnessError(f"the worker exited during set-up (exit status {self._proc.returncode}); "
                                     f"it printed: {self.output()[-500:]!r}")
        magic, status, held, size = protocol.HEADER.unpack(head)
        if magic != protocol.RESPONSE_MAGIC or status not in (protocol.SANDBOXED, protocol.SETUP_ERROR) \
                or size > protocol.MAX_TEXT_BYTES:
            self._kill()
            raise WorkerHarnessError(f"the worker's first message is not a set-up report (status {status})")
        payload = self._read_exact(size, deadline, "setting up the worker") if size else b""
        if status == protocol.SETUP_ERROR:
            self._finish()
            raise WorkerHarnessError(protocol.decode_text(payload or b""))
        self.pid_namespace = bool(held & protocol.SANDBOXED_PID_NAMESPACE)
        self._worker_pid = find_worker_pid(self._proc.pid, binary)
        if self._worker_pid is not None:
            deadline.watch_worker(self._worker_pid, born_inside=True)

    def _limit_args(self) -> list[str]:
        lim = self.limits
        args = ["--fsize", str(lim.file_size_bytes)]
        if lim.address_space_mb:
            args += ["--as-mb", str(lim.address_space_mb)]
        if lim.cpu_seconds:
            args += ["--cpu-s", str(lim.cpu_seconds)]
        if lim.processes:
            args += ["--nproc", str(self._nproc_limit())]
        if lim.open_files:
            args += ["--nofile", str(lim.open_files)]
        if lim.pending_signals:
            args += ["--sigpending", str(lim.pending_signals)]
        if not lim.seccomp:
            args.append("--no-seccomp")
        return args

    def _nproc_limit(self) -> int:
        """RLIMIT_NPROC counts every task of the worker's uid, threads
        included, so it bounds a thread bomb. Under bubblewrap and in
        privilege-drop mode that uid is the worker's alone; without isolation
        it is the grader's (root ignores the limit), so the limit is what that
        uid runs now plus the worker's share."""
        if self.mode in ("sandbox", "privilege-drop"):
            return self.limits.processes
        return _tasks_of_uid(os.getuid()) + self.limits.processes

    def close(self) -> None:
        """Stop the worker (politely, then by force) and remove its files."""
        self._note_wait()
        if self.prepared:
            # Never started: it waits at the gate and ends at its end of file.
            os.close(self._gate)
            self._gate = -1
            self._kill()
        if self._proc is not None:
            with self._threads_awake():
                if self._proc.poll() is None:
                    self._resume()
                    try:
                        os.write(self._request_fd, b"".join(protocol.request(protocol.QUIT, 0)))
                    except OSError:
                        pass
                    try:
                        _wait(self._proc, 1.0)
                    except subprocess.TimeoutExpired:
                        pass
                self._kill()
        for fd in (self._request_fd, self._response_fd):
            if fd >= 0:
                try:
                    os.close(fd)
                except OSError:
                    pass
        self._request_fd = self._response_fd = -1
        if self._output is not None:
            self._output.wait_closed(2.0)
        if self._tmp is not None:
            shutil.rmtree(self._tmp, ignore_errors=True)
            self._tmp = None
        if self._uid is not None and (self._proc is None or self._proc.poll() is not None):
            self._uid.release()     # the worker is gone: its uid may serve another
            self._uid = None
        # The progress page stays readable after close (the runner reads it
        # once the worker is gone); it is unmapped with this object.

    def _kill(self) -> None:
        """Kill the worker's whole process group and reap it."""
        if self._proc is None:
            return
        self._note_wait()    # the last reading, while it can be read
        self._killed = True
        with self._threads_awake():
            try:
                os.killpg(self._proc.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
            try:
                _wait(self._proc, 5.0)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait()
            # Under relays (its own pid namespace) the worker itself may still be
            # exiting: wait for it, so its uid is free when released.
            deadline = time.monotonic() + 2.0
            while self._worker_pid is not None and os.path.exists(f"/proc/{self._worker_pid}") \
                    and time.monotonic() < deadline:
                time.sleep(0.0002)

    @property
    def waited_s(self) -> float:
        """How long (s) the worker's main thread has waited for a core in its
        life: its start's and its calls' waits, as it waits for nothing
        between calls (stopped, or blocked reading the next request). What
        the runner's time budget leaves out. 0 where it cannot be read."""
        self._note_wait()
        return self._waited_ns / 1e9

    def _note_wait(self) -> None:
        if self._worker_pid is not None and not self._killed:
            wait = run_queue_wait_ns(self._worker_pid)
            if wait is not None:
                self._waited_ns = max(self._waited_ns, wait)

    def progress(self) -> int | None:
        """The index (within the last FETCH or READ_TEXTURE request) of the
        input the worker was about to evaluate, as the worker's progress page
        says; None when it says nothing. Written inside the worker: a hint,
        which the caller must confirm (the submission can write it too)."""
        if self._progress is None or self._progress.closed:
            return None
        value = struct.unpack_from("=Q", self._progress, 0)[0]
        return None if value == _NO_PROGRESS else value

    def output(self) -> str:
        """Everything the submission printed so far (capped)."""
        return self._output.text() if self._output else ""

    # ---- requests ---------------------------------------------------------

    def set_faces(self, faces: np.ndarray, placement: str = "end", timeout_s: float = 10.0) -> None:
        """Give the submission six faces (6, H, W, 3) float32 (sub_set_faces),
        copied into a guarded buffer whose last byte ends a page ("end") or
        whose first byte starts one ("start")."""
        faces = np.asarray(faces)
        if faces.ndim != 4 or faces.shape[0] != 6 or faces.shape[3] != 3 or 0 in faces.shape:
            raise ValueError(f"faces must have shape (6, H, W, 3), not {faces.shape}")
        if faces.shape[1] * faces.shape[2] * 72 > self.texture_bytes:
            # Checked here, not by the worker: whatever it answers is the submission's.
            raise WorkerHarnessError(f"faces of {faces.shape[2]} x {faces.shape[1]} texels do not fit this "
                                     f"worker's {self.texture_bytes}-byte texture window")
        if placement not in protocol.PLACEMENTS:
            raise ValueError(f"placement must be one of {', '.join(protocol.PLACEMENTS)}, not {placement!r}")
        payload = protocol.set_faces_payload(faces)
        self._call(protocol.SET_FACES, protocol.PLACEMENTS[placement], payload, 0, 0, timeout_s, N_("setting the faces"))

    def fetch(self, dirs: np.ndarray, timeout_s: float = 10.0) -> np.ndarray:
        """fetchColor for each direction (n, 3) -> colours (n, 3) float64."""
        dirs = np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1, 3)
        n = len(dirs)
        _, payload = self._call(protocol.FETCH, n, dirs.tobytes(), n, n * 24, timeout_s, "fetchColor")
        return protocol.decode_doubles(payload, n)

    def record_fetch(self, dirs: np.ndarray, tags: np.ndarray | None, timeout_s: float = 10.0) -> np.ndarray:
        """fetchColor for each direction (n, 3) with its readTexture calls
        recorded and answered with `tags` (None: with the student's
        readTexture) -> rows (n, protocol.RECORD_ROW)."""
        dirs = np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1, 3)
        n = len(dirs)
        _, payload = self._call(protocol.RECORD_FETCH, n, protocol.record_payload(tags, dirs), n,
                                n * 8 * protocol.RECORD_ROW, timeout_s, "fetchColor")
        return protocol.decode_doubles(payload, n, protocol.RECORD_ROW)

    def read_texture(self, face: int, uv: np.ndarray, placement: str = "end",
                     timeout_s: float = 10.0) -> np.ndarray:
        """readTexture(face's own guarded copy, u, v) for each (u, v) (n, 2) -> (n, 3)."""
        if not 0 <= face < 6:
            raise ValueError(f"face must be 0..5, not {face}")
        if placement not in protocol.PLACEMENTS:
            raise ValueError(f"placement must be one of {', '.join(protocol.PLACEMENTS)}, not {placement!r}")
        uv = np.ascontiguousarray(uv, dtype=np.float64).reshape(-1, 2)
        n = len(uv)
        head = struct.pack("=ii", face, protocol.PLACEMENTS[placement])
        _, payload = self._call(protocol.READ_TEXTURE, n, head + uv.tobytes(), n, n * 24, timeout_s,
                                "readTexture")
        return protocol.decode_doubles(payload, n)

    def fetch_timed(self, dirs: np.ndarray, timeout_s: float = 10.0) -> tuple[np.ndarray, int]:
        """fetch(dirs) and the CPU time (ns) the kernel charged to the worker
        process for it, read from outside: nothing the submission controls
        (its clock, its replies) enters the figure. It includes reading the
        request and writing the reply, the same for every library timed."""
        if self._worker_pid is None:
            raise WorkerHarnessError("the worker's CPU time cannot be read here (/proc did not show its pid)")
        try:
            before = process_cpu_ns(self._worker_pid)
        except OSError:      # it ended between calls (a thread of its own crashed, say)
            before = None
        dirs = np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1, 3)
        n = len(dirs)
        # Blocks of 4096 inputs per submission call, as before per-input progress.
        _, payload = self._call(protocol.FETCH_WHOLE, n, dirs.tobytes(), n, n * 24, timeout_s, "fetchColor")
        rgb = protocol.decode_doubles(payload, n)
        try:
            if before is None:
                raise OSError
            used = process_cpu_ns(self._worker_pid) - before
        except OSError:
            self._fail(EXITED, "the worker ended while it was being timed")
        return rgb, used

    def fetch_repeated(self, dirs: np.ndarray, repeats: int, timeout_s: float = 10.0) -> int:
        """fetchColor over `dirs`, `repeats` times in one request (TIME_FETCH:
        only the worker's own times come back, and they are dropped), and the
        CPU time (ns) the kernel charged to the worker for it, read from
        outside as in fetch_timed: calls whose answers nobody reads (the speed
        check's warm-up) without the reply of each."""
        if self._worker_pid is None:
            raise WorkerHarnessError("the worker's CPU time cannot be read here (/proc did not show its pid)")
        try:
            before = process_cpu_ns(self._worker_pid)
        except OSError:
            before = None
        dirs = np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1, 3)
        head = struct.pack("=II", repeats, 0)
        self._call(protocol.TIME_FETCH, len(dirs), head + dirs.tobytes(), repeats, repeats * 8, timeout_s, "fetchColor")
        try:
            if before is None:
                raise OSError
            return process_cpu_ns(self._worker_pid) - before
        except OSError:
            self._fail(EXITED, "the worker ended while it was being timed")

    def freeze(self) -> None:
        """Stop every thread of the worker (SIGSTOP, from outside) and wait
        until they are, while other libraries are timed: a thread left
        spinning on memory would slow them down and flatter its own ratio."""
        if self._worker_pid is not None and self.alive:
            try:
                os.kill(self._worker_pid, signal.SIGSTOP)
            except ProcessLookupError:
                return
            self._frozen = True
            # The stop lands asynchronously: wait (briefly) until every
            # thread is stopped, so nothing of it runs in what follows.
            with self._threads_awake():
                deadline = time.monotonic() + 1.0
                while time.monotonic() < deadline and not _all_stopped(self._worker_pid):
                    time.sleep(0.001)

    def thaw(self) -> None:
        """Undo freeze(); a worker stopped between calls stays stopped until its next call."""
        if not self.stop_between_calls:
            self._resume()

    def _idle(self) -> None:
        """Between calls: stopped, so threads it left running cost no one
        CPU (the per-call limit only watches calls); and every thread it
        started at the lowest priority for the calls to come."""
        if self._worker_pid is None or not self.alive:
            return
        if self.stop_between_calls:
            try:
                os.kill(self._worker_pid, signal.SIGSTOP)
            except ProcessLookupError:
                return
            self._frozen = True
        self._demote_threads(move=True)

    @contextlib.contextmanager
    def _threads_awake(self):
        """Its idle cgroup at an ordinary weight meanwhile, so that its
        threads there get a core to stop or to end on."""
        group = self._idle_cgroup
        if group is None or not self._moved:
            yield
            return
        try:
            group.set_idle(False)
        except OSError:
            pass
        try:
            yield
        finally:
            try:
                group.set_idle(True)
            except OSError:
                pass

    def _demote_threads(self, move: bool = False) -> None:
        """Every thread of the worker but its main one, which serves the calls,
        at SCHED_IDLE: a thread the submission left spinning runs in a call
        only on CPU nothing else wants, so it neither slows the call down
        (the main thread preempts it) nor a classmate's grading; in a grading
        it also moves to the grading's idle cpu cgroup (memory.idle_cgroup),
        as SCHED_IDLE alone weighs it only against its own cgroup. A thread
        cannot leave SCHED_IDLE (RLIMIT_NICE 0, worker.c), nor its cgroup.
        Threads started in a call (a static initialiser's, in loading) are
        demoted while it runs, at each look at its progress, or once it
        ends; moved once the call has ended (`move`: a move takes a lock
        every thread creation takes too, and would hold up a static initialiser
        starting threads) and the thread has run (at once where the kernel does not
        say): in the idle cgroup a thread that has not run yet may not run
        while its worker lives, and what it starts with would never happen
        (issue 32: at load 30 test_speed_trust.py's stop_everyone, whose
        thread's first call is forbidden, passed the speed check in one run
        of two). Until then it has the grading cgroup's share when the main
        thread does not run."""
        if self._worker_pid is None or not self.demote_threads:
            return
        try:
            tids = [int(t) for t in os.listdir(f"/proc/{self._worker_pid}/task")]
        except OSError:
            return
        for tid in tids:
            if tid != self._worker_pid and tid not in self._demoted:
                try:
                    os.sched_setscheduler(tid, os.SCHED_IDLE, os.sched_param(0))
                except OSError:      # it has just ended
                    continue
                self._demoted.add(tid)
        if move and self._idle_cgroup is not None:
            for tid in self._demoted - self._moved:
                if thread_run_ns(self._worker_pid, tid) == 0:
                    continue
                try:
                    self._idle_cgroup.take_thread(tid)
                except OSError:     # ended meanwhile, or the cgroup refuses: SCHED_IDLE where it is
                    pass
                self._moved.add(tid)

    def _resume(self) -> None:
        if self._frozen and self._worker_pid is not None and self.alive:
            try:
                os.kill(self._worker_pid, signal.SIGCONT)
            except ProcessLookupError:
                pass
        self._frozen = False

    def cpu_ns(self) -> int:
        """CPU time the worker process has used so far (see fetch_timed)."""
        if self._worker_pid is None:
            raise WorkerHarnessError("the worker's CPU time cannot be read here (/proc did not show its pid)")
        return process_cpu_ns(self._worker_pid)

    def time_fetch_ns(self, dirs: np.ndarray, repeats: int = 5, timeout_s: float = 30.0) -> np.ndarray:
        """Nanoseconds each of `repeats` sub_fetch_batch calls over `dirs` took,
        measured INSIDE the worker by its own clock_gettime: the submission
        can forge these, so grading does not use them (fetch_timed and
        fetch_repeated time from outside); kept for bench/bench_isolation.py's
        comparison with the old way."""
        dirs = np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1, 3)
        if not 1 <= repeats <= 100_000:
            raise ValueError(f"repeats must be 1..100000, not {repeats}")
        head = struct.pack("=II", repeats, 0)
        _, payload = self._call(protocol.TIME_FETCH, len(dirs), head + dirs.tobytes(), repeats, repeats * 8,
                                timeout_s, "fetchColor")
        return np.frombuffer(payload, dtype=np.uint64).astype(np.int64)

    def time_fetch(self, dirs: np.ndarray, repeats: int = 5, timeout_s: float = 30.0) -> float:
        """Median nanoseconds per lookup over `repeats` timed batches."""
        times = self.time_fetch_ns(dirs, repeats, timeout_s)
        return float(np.median(times)) / max(1, len(np.reshape(dirs, (-1, 3))))

    def load_cross(self, path: str | os.PathLike, timeout_s: float = 30.0) -> tuple[bool, str]:
        """loadFromCrossHDR on a copy of `path` visible to the worker:
        (loaded, message). Afterwards fetch uses the submission's own texels."""
        name = "cross.hdr"
        shutil.copyfile(path, self._tmp / "input" / name)
        (self._tmp / "input" / name).chmod(0o644)
        inside = {"sandbox": f"{INPUT_INSIDE}/{name}", "privilege-drop": f"/{name}"}.get(
            self.mode, str(self._tmp / "input" / name))
        count, payload = self._call(protocol.LOAD_CROSS, 0, inside.encode(), None, None, timeout_s,
                                    "loadFromCrossHDR")
        if count not in (0, 1):
            self._fail(PROTOCOL, f"loadFromCrossHDR reply with count {count}")
        return bool(count), protocol.decode_text(payload)

    # ---- the exchange -----------------------------------------------------

    def _call(self, op: int, count: int, payload: bytes, expected_count: int | None,
              expected_bytes: int | None, timeout_s: float, what: str) -> tuple[int, bytes]:
        if self._proc is None or self._request_fd < 0 or self._killed:
            raise WorkerHarnessError("the worker is not running (start it, or start a new one after a failure)")
        if not self.alive:
            # It ended since its last call (a thread of its own crashed, it
            # exited, the kernel killed it): the submission's doing, whichever
            # check asked next. Its reply pipe holds what it said, if anything.
            status, count, reply = self._receive(None, None, WallBound(2.0), what)
            self._fail(PROTOCOL, f"the worker had ended before {what} was asked, after a reply "
                                 f"({protocol.STATUS_NAMES.get(status, status)})")
        self._resume()
        try:
            return self._exchange(op, count, payload, expected_count, expected_bytes, timeout_s, what)
        finally:
            self._idle()

    def _exchange(self, op: int, count: int, payload: bytes, expected_count: int | None,
                  expected_bytes: int | None, timeout_s: float, what: str) -> tuple[int, bytes]:
        if self._cgroup is not None:
            # The grading's own count, cheap to read. Without one the machine's
            # (/proc/vmstat: a tenth of a millisecond of kernel time and a
            # wake-up of the other core, each call) is read once, at start: a
            # SIGKILL the worker did not get from us is then put down to memory
            # if any OOM kill happened on the machine since it started.
            self._oom_before = self._oom_kills()
        first = op in _LOOKUPS and self._lookups_done == 0 and self.first_input_s > 0
        self._first_input_ns = None if first else 0
        deadline = WallBound(wall_bound(timeout_s + (self.first_input_s if first else 0.0)), self._worker_pid)
        if self._progress is not None:
            struct.pack_into("=Q", self._progress, 0, _NO_PROGRESS)
        self._watch, self.stuck = (None, time.monotonic(), self._cpu_or_none()), None
        self._limit_cpu(timeout_s)
        self._send(protocol.request(op, count, payload), deadline, what)
        status, count, reply = self._receive(expected_count, expected_bytes, deadline, what)
        self.faults = []
        if status == protocol.FAULTS:
            # Inputs that faulted while the worker went on: claims against the
            # submission only (those inputs count as failed).
            if op not in (protocol.FETCH, protocol.FETCH_WHOLE, protocol.READ_TEXTURE, protocol.RECORD_FETCH):
                self._fail(PROTOCOL, f"a faults reply to {what}")
            try:
                self.faults = protocol.decode_faults(reply, count, expected_count)
            except protocol.ProtocolViolation as exc:
                self._fail(PROTOCOL, str(exc))
            status, count, reply = self._receive(expected_count, expected_bytes, deadline, what)
            if status == protocol.FAULTS:
                self._fail(PROTOCOL, "two faults replies to one request")
        if status == protocol.OK:
            self._lookups_done += op in _LOOKUPS
            return count, reply
        if status == protocol.EXCEPTION:
            text = protocol.decode_text(reply)
            raise SubmissionFailure(EXCEPTION, _("uncaught exception: %(text)s") % {"text": text} if text else _("uncaught exception"),
                                    fatal=False, output=self.output(),
                                    detail="bad_alloc" if "bad_alloc" in text else "")
        # Every byte on the reply pipe may have been written by the submission
        # (it shares the worker's address space and file descriptors), so even
        # "the request was bad" is its responsibility: our requests are
        # validated before they are sent (_check_request, set_faces).
        if status in (protocol.ARGUMENT, protocol.BAD_REQUEST):
            self._fail(PROTOCOL, f"{what}: the worker answered {protocol.STATUS_NAMES[status]} "
                                 f"({protocol.decode_text(reply)[:200]!r}) to a request the grader had checked")
        self._fail(PROTOCOL, f"unexpected reply status {protocol.STATUS_NAMES[status]} to {what}")

    def _limit_cpu(self, timeout_s: float) -> None:
        """From now on the call may use `timeout_s` of the worker's CPU time.
        Where its CPU clock cannot be read, the wall clock limits it instead."""
        cpu = self._cpu_or_none()
        self._cpu_limit = (cpu, int(timeout_s * 1e9)) if cpu is not None else None
        if cpu is None:
            first = self.first_input_s if self._first_input_ns is None else 0.0
            self._wall_only = time.monotonic() + timeout_s + first

    def _over_limit(self, deadline: WallBound) -> str | None:
        """Why the current call must stop now, if it must: "cpu" (its CPU
        time used up: the submission's work) or "wall" (the outer bound)."""
        now = time.monotonic()
        if self._cpu_limit is not None:
            cpu = self._cpu_or_none()
            if cpu is not None and cpu - self._cpu_limit[0] > self._cpu_limit[1] + self._first_input_allowance(cpu):
                return "cpu"
        elif now >= self._wall_only:
            return "wall"
        return "wall" if now >= deadline.end() - _WATCH_S else None

    def _first_input_allowance(self, cpu: int) -> int:
        """CPU ns the current call may use beyond its limit: in a worker's
        first lookup call, what its first input took, up to first_input_s
        (the whole of it while the progress page still shows that input, or
        shows nothing: FETCH_WHOLE and TIME_FETCH note no progress). The
        submission can write that page: it gains at most FIRST_INPUT_S of
        CPU time once per worker, and no mark."""
        if self._first_input_ns is None and self._cpu_limit is not None:
            if self.progress() not in (None, 0):
                self._first_input_ns = min(int(self.first_input_s * 1e9), cpu - self._cpu_limit[0])
            else:
                return int(self.first_input_s * 1e9)
        return self._first_input_ns or 0

    def _send(self, buffers: list, deadline: WallBound, what: str) -> None:
        poller = select.poll()
        poller.register(self._request_fd, select.POLLOUT)
        for buf in buffers:
            view = memoryview(buf).cast("B")
            while len(view):
                if not poller.poll(min(deadline.left(), _WATCH_S) * 1000):
                    why = self._over_limit(deadline)
                    if why:
                        self._timeout(what, why)
                    continue
                try:
                    n = os.write(self._request_fd, view[:1 << 20])
                except BlockingIOError:
                    continue
                except BrokenPipeError:
                    return      # the worker is gone: its reply (or EOF) says why
                view = view[n:]

    def _read_exact(self, size: int, deadline: WallBound, what: str) -> bytearray | None:
        """`size` bytes, or None at end of file (the worker exited), read
        straight into one buffer (a reply of tens of MB is copied once)."""
        buffer = bytearray(size)
        view, got = memoryview(buffer), 0
        while got < size:
            left = deadline.left()
            # Short waits while a call runs, to watch which input it is on.
            ready, _, _ = select.select([self._response_fd], [], [], min(left, _WATCH_S))
            if not ready:
                why = self._over_limit(deadline)
                if why:
                    self._timeout(what, why)
                self._observe()
                self._demote_threads()
                continue
            n = os.readv(self._response_fd, [view[got:]])
            if not n:
                if got:
                    self._fail(PROTOCOL, f"reply cut off after {got} of {size} bytes")
                return None
            got += n
        return buffer

    def _receive(self, expected_count, expected_bytes, deadline, what) -> tuple[int, int, bytes]:
        head = self._read_exact(protocol.HEADER.size, deadline, what)
        if head is None:
            self._exited(what)
        try:
            status, count, size = protocol.decode_header(head)
            protocol.check_reply_size(status, count, size, expected_count, expected_bytes)
        except protocol.ProtocolViolation as exc:
            self._fail(PROTOCOL, str(exc))
        payload = self._read_exact(size, deadline, what) if size else b""
        if payload is None:
            self._fail(PROTOCOL, "reply cut off before its payload")
        if status == protocol.CRASH:
            try:
                report = protocol.decode_crash(payload)
            except protocol.ProtocolViolation as exc:
                self._fail(PROTOCOL, str(exc))
            self._finish()
            raise from_crash(report, self.output(), self.limits.cpu_seconds)
        if status == protocol.LOAD_ERROR:
            self._finish()
            raise SubmissionFailure(LOAD_ERROR, _("the submission could not be loaded: %(text)s") % {"text": protocol.decode_text(payload)},
                                    output=self.output())
        if status == protocol.EXCEPTION and expected_count is None and what == "loading the submission":
            self._finish()
            raise SubmissionFailure(EXCEPTION, _("the EnvironmentMap constructor threw: %(text)s") % {"text": protocol.decode_text(payload)},
                                    output=self.output())
        return status, count, payload

    # ---- endings ----------------------------------------------------------

    def _finish(self) -> None:
        """The worker is ending: make sure it is gone and its output read."""
        try:
            self._proc.wait(timeout=2.0)
        except subprocess.TimeoutExpired:
            pass
        self._kill()
        self._output.wait_closed(2.0)

    def _cpu_or_none(self) -> int | None:
        try:
            cpu = process_cpu_ns(self._worker_pid) if self._worker_pid is not None else None
        except OSError:
            return None
        if cpu is not None:
            self._last_cpu = cpu
        return cpu

    def _observe(self) -> None:
        """Note when the progress page first showed its current value."""
        if self._watch is None:
            return
        value = self.progress()
        if value != self._watch[0]:
            self._watch = (value, time.monotonic(), self._cpu_or_none())

    def _timeout(self, what: str, why: str):
        # Before the kill: how long (wall and CPU seconds, seen from here)
        # the worker has been on the input its progress page names.
        self._observe()
        if self._watch is not None and self._watch[0] is not None:
            value, since, cpu0 = self._watch
            cpu1 = self._cpu_or_none()
            cpu = (cpu1 - cpu0) / 1e9 if cpu0 is not None and cpu1 is not None else 0.0
            self.stuck = (value, time.monotonic() - since, cpu)
        # Its first input spun through the allowance (runner: no more for it).
        self.spun_first_input = why == "cpu" and self._first_input_ns is None
        # A worker that stopped itself reached the wall bound by its own doing,
        # not the machine's: a second try would only wait as long again.
        stopped = why == "wall" and not self._frozen and _stopped_itself(self._worker_pid)
        self._kill()
        self._output.wait_closed(2.0)
        # "wall": the outer bound, which a busy machine can reach too: the
        # runner tries once more before it is a verdict (grader_limit).
        raise SubmissionFailure(TIMEOUT, _("%(what)s did not finish in time (killed)") % {"what": _(what)}, output=self.output(),
                                detail=why, grader_limit=why == "wall" and not stopped)

    def _exited(self, what: str):
        self._finish()
        status = self._proc.returncode
        # bubblewrap reports a child killed by signal n as exit status 128 + n.
        relayed = self.mode == "sandbox" or self.pid_namespace
        if status is not None and (status < 0 or (relayed and status > 128)):
            signo = -status if status < 0 else status - 128
            name = signal_name(signo)
            if signo == signal.SIGSYS:
                # The filter's trap with signals blocked (system() and
                # posix_spawn block them while starting a process) kills
                # before our handler can say which call it was.
                raise SubmissionFailure(FORBIDDEN_SYSCALL, _("made a forbidden system call with signals blocked "
                                        "(SIGSYS; system(), popen() and posix_spawn do this to start a process)"),
                                        signal_name=name, output=self.output(), exit_status=status)
            if signo == signal.SIGKILL and self._oom_kills() > self._oom_before:
                # The kernel's OOM killer (oom_score_adj 1000 makes the worker
                # its first choice): memory the submission held, counting
                # kernel memory outside RLIMIT_AS such as pipe buffers.
                raise SubmissionFailure(EXITED, _("the kernel ended the worker for using too much memory "
                                        "(counting kernel memory such as pipe buffers) while %(what)s ran")
                                        % {"what": _(what)}, signal_name=name, output=self.output(),
                                        exit_status=status, detail="memory")
            if signo == signal.SIGKILL and self.limits.cpu_seconds:
                # The kernel's SIGKILL at the hard CPU limit, or a kill from
                # outside (the machine's, or the submission's own): tried once
                # more by the runner unless the CPU limit explains it.
                at_limit = self._last_cpu >= (self.limits.cpu_seconds - 2) * 1e9
                raise SubmissionFailure(TIMEOUT, _("the worker was killed (%(name)s) while %(what)s ran, "
                                        "probably at its CPU-time limit") % {"name": name, "what": _(what)}, signal_name=name,
                                        output=self.output(), exit_status=status, detail="cpu",
                                        grader_limit=not at_limit)
            raise SubmissionFailure(EXITED, _("the worker was killed by %(name)s while %(what)s ran") % {"name": name, "what": _(what)},
                                    signal_name=name, output=self.output(), exit_status=status)
        if status == protocol.EXIT_PROTOCOL:
            raise SubmissionFailure(PROTOCOL, _("the worker lost its request channel while %(what)s ran") % {"what": _(what)},
                                    output=self.output(), exit_status=status)
        raise SubmissionFailure(EXITED, _("the program ended itself (exit status %(status)s) while %(what)s ran") % {"status": status, "what": _(what)},
                                output=self.output(), exit_status=status)

    def _oom_kills(self) -> int:
        return self._cgroup.oom_kills() if self._cgroup is not None else memory.oom_kills_on_machine()

    def _fail(self, kind: str, message: str):
        self._kill()
        self._output.wait_closed(2.0)
        raise SubmissionFailure(kind, message, output=self.output())
