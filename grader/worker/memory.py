"""What a submission's memory and CPU are charged to, so that running out of
memory ends the submission and never the grader, and its threads take no
more of the machine than one process of a classmate's does (issue 32).

Pipe buffers, memfds and other kernel memory are outside a worker's
RLIMIT_AS and its RSS, but a container's memory cgroup counts them: a
static initialiser that filled pipes once made the kernel's OOM killer take
the grader. Three defences, each where the machine allows it:

- every process that runs or compiles student code starts with
  oom_score_adj 1000 (any process may raise its own), so an OOM takes it
  first (`charged`);
- the grader's own process asks for GRADER_OOM_SCORE_ADJ (lowering needs
  CAP_SYS_RESOURCE: `protect_grader` says why not where it is refused);
- one memory cgroup per grading (`grading_cgroup`), cgroup v1's memory
  controller or a delegated v2 subtree: the worker and the compiler join it
  before they run anything, so their kernel memory is charged there and an
  OOM kills inside it only; `oom_kills()` tells a death by OOM apart.

Its CPU: one cpu cgroup per grading beside it (cgroup v1's cpu controller, or
the same v2 folder where `cpu` is delegated too) of the default weight
(cpu.shares 1024, cpu.weight 100: what one ordinary process gets). The
scheduler shares the machine between cgroups first, so a worker's 63 spinning
threads together weigh what a classmate's single-threaded worker weighs.
And an idle one beside it (`idle_cgroup`, cgroup v1: cpu.idle 1, or
cpu.shares 2 before Linux 5.15) for the threads the submission starts,
which the worker moves there as it puts them at SCHED_IDLE
(Worker._demote_threads): SCHED_IDLE is weighed only against a thread's
siblings in its cgroup, so in the grading's cgroup, whenever the main
thread was not running, the idle threads had that cgroup's whole share,
one ordinary process's, against a classmate. In the idle cgroup they run
only on a core nothing else wants. cgroup v2 keeps a process's threads in
one domain: there they stay in the grading's cgroup.

The descriptors themselves are bounded where they are made: RLIMIT_NOFILE in
worker.c (Limits.open_files) and in the compiler's shell (grader/build.py).
"""
from __future__ import annotations

import contextlib
import itertools
import os
import shlex
import time
from pathlib import Path

STUDENT_OOM_SCORE_ADJ = 1000
GRADER_OOM_SCORE_ADJ = -900
# A grading runs one worker at a time (2 GiB of address space, Limits) or
# one compile (1.5 GiB): this leaves room for kernel memory and page cache.
GRADING_MEMORY_MB = 2560
# Never less: a compile (cc1plus) and a correct worker fit in it.
MINIMUM_MB = 256

_CGROUP_ROOT = Path("/sys/fs/cgroup")
_counter = itertools.count()


class GradingCgroup:
    """A cgroup of its own (v1 or v2) for one controller ("memory" or "cpu";
    in v2 the two share one folder), made by `grading_cgroup`."""

    def __init__(self, path: Path, version: int, controller: str = "memory"):
        self.path, self.version, self.controller = path, version, controller

    @property
    def procs(self) -> Path:
        return self.path / "cgroup.procs"

    def oom_kills(self) -> int:
        """How many processes the kernel's OOM killer took in this cgroup."""
        name = "memory.events" if self.version == 2 else "memory.oom_control"
        return _field(self.path / name, "oom_kill")

    def peak_bytes(self) -> int | None:
        name = "memory.peak" if self.version == 2 else "memory.max_usage_in_bytes"
        try:
            return int((self.path / name).read_text().split()[0])
        except (OSError, ValueError, IndexError):
            return None

    def take_thread(self, tid: int) -> None:
        """Move thread `tid` (alone) here: cgroup v1's `tasks` file."""
        (self.path / "tasks").write_text(str(tid))

    def set_idle(self, idle: bool) -> None:
        """An idle cgroup (_make_idle) at its lowest weight, or at an
        ordinary process's for a moment: its threads must run to stop or to
        end, and at the lowest weight a loaded machine gives them no core
        (a grading's every worker took a second to close). Raises OSError."""
        if (self.path / "cpu.idle").exists():
            (self.path / "cpu.idle").write_text("1" if idle else "0")
        else:
            (self.path / "cpu.shares").write_text("2" if idle else "1024")

    def allow_uid(self, uid: int) -> None:
        """Let processes of `uid` move themselves in (the compiler's shell in
        privilege-drop mode). cgroup v1 only: v2 would need write access to
        the parent's cgroup.procs too, which is not given away."""
        if self.version == 1:
            for name in ("cgroup.procs", "tasks"):
                os.chown(self.path / name, uid, -1)

    def remove(self) -> None:
        # The last worker may take a moment to be reaped after its kill.
        for _ in range(50):
            try:
                self.path.rmdir()
                return
            except FileNotFoundError:
                return
            except OSError:
                time.sleep(0.02)


def _field(path: Path, name: str) -> int:
    try:
        for line in path.read_text().splitlines():
            key, _, value = line.partition(" ")
            if key == name:
                return int(value)
    except (OSError, ValueError):
        pass
    return 0


def oom_kills_on_machine() -> int:
    """The kernel's count of OOM kills since boot (/proc/vmstat): where no
    cgroup of ours watches, a worker's SIGKILL that raised it is an OOM kill."""
    return _field(Path("/proc/vmstat"), "oom_kill")


def _own_cgroup(controller: str = "memory") -> tuple[Path | None, int, str]:
    """Where a child cgroup with `controller` ("memory", "cpu") can be made:
    (folder, version, why not)."""
    try:
        lines = Path("/proc/self/cgroup").read_text().splitlines()
    except OSError as exc:
        return None, 0, f"cannot read /proc/self/cgroup ({exc})"
    for line in lines:
        _, controllers, path = line.split(":", 2)
        if controller in controllers.split(","):
            # A v1 hierarchy is mounted under its controllers' names ("cpu,cpuacct").
            mount = _CGROUP_ROOT / controllers
            folder = (mount if mount.is_dir() else _CGROUP_ROOT / controller) / path.lstrip("/")
            if folder.is_dir() and os.access(folder, os.W_OK):
                return folder, 1, ""
            return None, 1, f"the {controller} cgroup {folder} is not writable here"
    for line in lines:
        if line.startswith("0::"):
            unified = _CGROUP_ROOT if (_CGROUP_ROOT / "cgroup.controllers").exists() else _CGROUP_ROOT / "unified"
            folder = unified / line[3:].lstrip("/")
            try:
                enabled = (folder / "cgroup.subtree_control").read_text().split()
            except OSError:
                enabled = []
            if controller in enabled and os.access(folder, os.W_OK):
                return folder, 2, ""
            return None, 2, (f"cgroup v2 at {folder} does not delegate the {controller} controller to its children "
                             f"(cgroup.subtree_control lacks {controller}, or the folder is not writable)")
    return None, 0, f"no {controller} controller is mounted"


def cgroup_problem(controller: str = "memory") -> str | None:
    """Why no grading cgroup for `controller` can be made here (None: one can)."""
    folder, _, why = _own_cgroup(controller)
    return why if folder is None else None


def _ancestors_limit(folder: Path, version: int) -> int | None:
    """The smallest memory limit (bytes) set on `folder` or above it (a
    container's), None where none is set."""
    name = "memory.max" if version == 2 else "memory.limit_in_bytes"
    found = None
    while (folder / name).exists():
        try:
            value = (folder / name).read_text().strip()
        except OSError:
            break
        if value.isdigit() and int(value) < (1 << 60):
            found = int(value) if found is None else min(found, int(value))
        folder = folder.parent
    return found


def _make(limit_mb: int) -> GradingCgroup | None:
    parent, version, _ = _own_cgroup()
    if parent is None:
        return None
    # Inside a container with a limit, a third of it: the grading's own OOM
    # then comes before the container's, which could take anything in it.
    container = _ancestors_limit(parent, version)
    if container is not None:
        limit_mb = max(MINIMUM_MB, min(limit_mb, (container // 3) >> 20))
    path = parent / f"envmap-grading-{os.getpid()}-{next(_counter)}"
    try:
        path.mkdir()
    except OSError:
        return None
    group = GradingCgroup(path, version)
    limit = str(limit_mb << 20)
    try:
        (path / ("memory.max" if version == 2 else "memory.limit_in_bytes")).write_text(limit)
    except OSError:
        group.remove()
        return None
    return group


def _make_cpu(beside: GradingCgroup | None) -> GradingCgroup | None:
    """A cpu cgroup of the default weight, or the folder of `beside` where
    that is the same v2 parent (a process belongs to one v2 cgroup)."""
    parent, version, _ = _own_cgroup("cpu")
    if parent is None:
        return None
    if beside is not None and version == beside.version == 2 and beside.path.parent == parent:
        return GradingCgroup(beside.path, 2, "cpu")
    path = parent / f"envmap-grading-{os.getpid()}-{next(_counter)}"
    try:
        path.mkdir()
    except OSError:
        return None
    return GradingCgroup(path, version, "cpu")


def _make_idle(cpu: GradingCgroup | None) -> GradingCgroup | None:
    """A v1 cpu cgroup beside `cpu` at the lowest weight: cpu.idle 1 (the
    whole cgroup runs at SCHED_IDLE against its siblings), or cpu.shares 2
    where the kernel has no cpu.idle."""
    if cpu is None or cpu.version != 1:
        return None
    path = cpu.path.with_name(cpu.path.name + "-idle")
    try:
        path.mkdir()
    except OSError:
        return None
    group = GradingCgroup(path, 1, "cpu")
    try:
        group.set_idle(True)
    except OSError:
        group.remove()
        return None
    return group


_current: GradingCgroup | None = None
_current_cpu: GradingCgroup | None = None
_current_idle: GradingCgroup | None = None


def current() -> GradingCgroup | None:
    """The memory cgroup of the grading in progress (None: none, or not available)."""
    return _current


def current_cpu() -> GradingCgroup | None:
    """The cpu cgroup of the grading in progress (None: none, or not available)."""
    return _current_cpu


def idle_cgroup() -> GradingCgroup | None:
    """The idle cpu cgroup of the grading in progress, for the threads a
    worker starts (None: none, cgroup v2, or not available)."""
    return _current_idle


def _groups() -> list[GradingCgroup]:
    return [g for g in (_current, _current_cpu) if g is not None]


@contextlib.contextmanager
def grading_cgroup(limit_mb: int | None = None):
    """Everything started for student code inside the block (workers,
    compilers) is charged to one new memory cgroup of `limit_mb` MiB and one
    new cpu cgroup, where the machine offers them; yields the memory one, or
    None (cgroup_problem() says why)."""
    global _current, _current_cpu, _current_idle
    outer = _current, _current_cpu, _current_idle
    group = _make(limit_mb or GRADING_MEMORY_MB)
    cpu = _make_cpu(group)
    idle = _make_idle(cpu)
    _current, _current_cpu, _current_idle = group or outer[0], cpu or outer[1], idle or outer[2]
    try:
        yield group
    finally:
        _current, _current_cpu, _current_idle = outer
        for made in (idle, cpu, group):
            if made is not None:
                made.remove()


def allow_uid(uid: int) -> None:
    """Let processes of `uid` join the current grading's cgroups themselves
    (GradingCgroup.allow_uid: cgroup v1 only)."""
    for group in _groups():
        group.allow_uid(uid)


def charged(cmd: list[str]) -> list[str]:
    """`cmd` started by a shell that first gives itself oom_score_adj 1000
    and joins the current grading's cgroups; exec keeps both for everything
    it starts. Failing to join is not fatal: the cgroups are a defence where
    available, never a reason not to grade."""
    procs = " ".join(dict.fromkeys(shlex.quote(str(g.procs)) for g in _groups()))
    join = f'for g in {procs}; do echo $$ >"$g" 2>/dev/null; done; ' if procs else ""
    return ["/bin/sh", "-c", f'echo {STUDENT_OOM_SCORE_ADJ} >/proc/self/oom_score_adj 2>/dev/null; {join}exec "$@"',
            "sh", *cmd]


def protect_grader() -> str | None:
    """Make the grader's own process unattractive to the OOM killer; None
    when done, else why not (lowering oom_score_adj needs CAP_SYS_RESOURCE)."""
    try:
        Path("/proc/self/oom_score_adj").write_text(str(GRADER_OOM_SCORE_ADJ))
        return None
    except OSError as exc:
        return f"cannot lower the grader's oom_score_adj to {GRADER_OOM_SCORE_ADJ} ({exc.strerror})"
