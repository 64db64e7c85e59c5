"""The compiler, confined: every command of a student's build runs here,
under bubblewrap where it works, else as the unprivileged BUILD_UID
("privilege-drop"), else as ourselves ("none"); always with stdin /dev/null,
a scrubbed environment, CPU, memory, descriptor and output limits,
oom_score_adj 1000 in the grading's memory and cpu cgroups (grader/worker/memory.py),
and a deadline in CPU time of the compiler's processes with the wall clock
only as an outer bound (Deadline). The flags every build uses are here too.

Privilege-drop mode: the compiler's uid can read nothing of ours.

Where bubblewrap cannot run (Gradescope, PrairieLearn: containers without
user namespaces; mount namespaces need CAP_SYS_ADMIN), the student's
preprocessor, compiler, assembler and linker run as BUILD_UID in a scratch
folder of their own (grader/build/__init__.py). What keeps the grader's and the
course's files from them is the file permissions: before the first such
build, a probe running as BUILD_UID tries each sentinel (the rubric, the
reference's lookup.c and library, the fixtures, the upload, the build
cache, Gradescope's /autograder and PrairieLearn's /grade and what they
hold). The folders the grader owns are fixed (`chmod o-rwx`: root, which
grades, keeps every access; nothing else the grader runs needs them: the
worker enters its chroot as root). If the probe still reads anything,
building raises BuildConfinementError and nothing of the student's is
compiled.

What BUILD_UID can read then is what any uid can: the system (/usr, /etc's
public files), world-readable folders such as /tmp (where only the scratch
folder, mode 0700 and its own, holds anything of ours) and its scratch
folder's copies of the source, the API headers and our objects.
"""
from __future__ import annotations

import functools
import os
import select
import signal
import stat
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

from .. import PROJECT_ROOT
from .messages import MAX_COMPILER_OUTPUT_BYTES, MEMORY_LIMIT_BYTES, OUTPUT_STOPPED

CXX, CC = "g++", "gcc"
# No LTO anywhere: an object carrying LTO bytecode would have code the
# student never showed us compiled at link time, outside any check.
CXXFLAGS = ["-std=c++17", "-O2", "-Wall", "-Wextra", "-fPIC", "-fno-lto"]
CFLAGS = ["-std=c11", "-O2", "-Wall", "-Wextra", "-fPIC", "-fno-lto", "-D_POSIX_C_SOURCE=200809L"]
SANITIZE_FLAGS = ["-fsanitize=address,undefined", "-fno-omit-frame-pointer", "-g"]
# Plain messages: no colour, no line wrapping, a bounded number of errors.
DIAGNOSTIC_FLAGS = ["-fdiagnostics-color=never", "-fmessage-length=0", "-fmax-errors=10"]
LINK_FLAGS = ["-fno-lto", "-fno-use-linker-plugin", "-Wl,--no-undefined", "-Wl,-z,noexecstack",
              "-Wl,-z,relro", "-Wl,-z,now"]

# The uid/gid compilers run as without bubblewrap (root only). Not nobody
# (65534): a privilege-dropped worker runs student code as nobody, and must
# not reach another student's build folder. 65533 is reserved and unused on
# Debian and Ubuntu (policy: 65000-65533 reserved).
BUILD_UID = BUILD_GID = 65533
MAX_OUTPUT_FILE_BYTES = 256 << 20   # any file a compiler step writes (ulimit -f)


class HarnessBuildError(RuntimeError):
    """Our own sources (template, shim, reference) did not compile, or (BuildConfinementError) the
    compiler could not be confined: not the student's fault."""


@functools.lru_cache(maxsize=None)
def compiler_versions() -> str:
    lines = []
    for compiler in (CXX, CC):
        out = subprocess.run([compiler, "--version"], capture_output=True, text=True, check=True,
                             stdin=subprocess.DEVNULL)
        lines.append(out.stdout.splitlines()[0])
    return "\n".join(lines)


def compile_flags(sanitize: bool) -> tuple[list[str], list[str]]:
    extra = SANITIZE_FLAGS if sanitize else []
    return CXXFLAGS + extra + DIAGNOSTIC_FLAGS, CFLAGS + extra + DIAGNOSTIC_FLAGS


# ---- running the compiler: sandboxed, limited, stdin /dev/null ------------------

@dataclass
class CompilerStep:
    returncode: int
    output: str
    timed_out: bool = False
    stopped_by: str = ""     # a step that timed out: "cpu" (its CPU time used up) or "wall" (the outer bound)


# The compiler sees no secrets of ours (no GRADER_SECRET in
# /proc/self/environ for a student's #include to print).
_COMPILER_ENVIRONMENT = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "LC_ALL": "C",
                         **{k: os.environ[k] for k in ("TMPDIR",) if k in os.environ}}


def build_isolation() -> str:
    """How the student's compile and link run here: "bubblewrap",
    "privilege-drop" (no bubblewrap, but we are root: uid/gid BUILD_UID) or
    "none" (no bubblewrap, not root: as ourselves, limits only)."""
    from ..worker.sandbox import sandbox_problem
    if sandbox_problem() is None:
        return "bubblewrap"
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        return "privilege-drop"
    return "none"


def limited(cmd: list[str], cpu_seconds: int) -> list[str]:
    """cmd under an address-space, a CPU-time and a descriptor limit. The
    limits are set by the shell's ulimit rather than setrlimit in a
    preexec_fn, which is unsafe when threads run (the common objects are
    compiled in parallel)."""
    # ulimit -f counts 512-byte blocks in dash (Debian's sh), 1 KiB in bash: at most 2x the cap.
    script = (f'ulimit -v {MEMORY_LIMIT_BYTES >> 10} && ulimit -t {cpu_seconds} && '
              f'ulimit -f {MAX_OUTPUT_FILE_BYTES >> 9} && ulimit -n {COMPILER_OPEN_FILES} && exec "$@"')
    return ["/bin/sh", "-c", script, "sh", *cmd]


# Descriptors a compiler step may hold (ld opens each object and library
# once; each pipe pins kernel memory outside ulimit -v).
COMPILER_OPEN_FILES = 256


@dataclass
class Deadline:
    """A build's time: `cpu_s` seconds of CPU time of the compiler's
    processes (what the source asks of the compiler; a loaded machine
    stretches wall time, never CPU time), spent step by step, and the wall
    clock only as an outer bound (process.wall_bound's factor), stretched as
    a worker's call's is (process.WallBound) by the time the compiler's
    processes waited for a core, at most `stretch_cap_s` (WALL_STRETCH_MAX
    bounds: a build is not hostile code, but its wait is the machine's
    load, which has no end of its own). Their waits are summed, each
    thread's last reading kept once it has ended: the steps run one after
    another, and in a step the driver sleeps while cc1plus, as or ld runs."""
    cpu_s: float
    wall_end: float
    stretch_cap_s: float = 0.0
    waits_ns: dict[int, int] = field(default_factory=dict)    # thread id -> its wait for a core

    @classmethod
    def of(cls, seconds: float) -> "Deadline":
        from ..worker.process import WALL_STRETCH_MAX, wall_bound
        bound = wall_bound(seconds)
        return cls(float(seconds), time.monotonic() + bound, WALL_STRETCH_MAX * bound)

    def note_waits(self, pid: int) -> None:
        """Read what the processes of a step (`pid` and below) have waited for a core so far."""
        from ..worker.process import tree_run_queue_waits_ns
        for tid, wait in tree_run_queue_waits_ns(pid).items():
            self.waits_ns[tid] = max(wait, self.waits_ns.get(tid, 0))

    @property
    def stretch_s(self) -> float:
        return min(self.stretch_cap_s, sum(self.waits_ns.values()) / 1e9)

    def wall_left(self) -> float:
        return self.wall_end + self.stretch_s - time.monotonic()


def run_compiler(cmd: list[str], cwd: Path, deadline: Deadline, isolation: str = "trusted") -> CompilerStep:
    """Run one compiler command in its own process group, killed when it has
    used the deadline's CPU time (all its processes) or reached its wall
    bound. isolation: "trusted" (our own sources), or how a student's
    file is built (build_isolation(); the scratch folder `cwd` is all of
    ours it may see)."""
    from ..worker import memory
    if deadline.cpu_s <= 0 or deadline.wall_left() <= 0:
        return CompilerStep(-1, "", timed_out=True, stopped_by="cpu" if deadline.cpu_s <= 0 else "wall")
    cpu = max(1, int(deadline.cpu_s) + 1)     # each process's own backstop
    env = dict(_COMPILER_ENVIRONMENT)
    drop: dict = {}
    if isolation == "bubblewrap":
        from ..worker.sandbox import compiler_command
        cmd = compiler_command(cmd, [], cwd)
    elif isolation == "privilege-drop":
        # No bubblewrap, but root: the compiler runs as BUILD_UID, in a scratch
        # folder only it (and root) can enter; its temporary files go there too.
        drop = {"user": BUILD_UID, "group": BUILD_GID, "extra_groups": []}
        env = {"PATH": "/usr/bin:/bin", "LC_ALL": "C", "TMPDIR": str(cwd / "tmp"), "HOME": str(cwd)}
        memory.allow_uid(BUILD_UID)     # its shell joins the grading's cgroups itself
    elif isolation == "none":
        env["TMPDIR"] = str(cwd / "tmp")
    proc = subprocess.Popen(memory.charged(limited(cmd, cpu)), cwd=cwd, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            start_new_session=True, env=env, **drop)
    out, ended, used_s = _read_capped(proc, deadline)
    deadline.cpu_s -= used_s
    if ended != "exited":
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        proc.stdout.close()
        text = out.decode("utf-8", "replace")
        if ended in ("cpu", "wall"):
            return CompilerStep(-1, text, timed_out=True, stopped_by=ended)
        return CompilerStep(-1, f"{text}\n{OUTPUT_STOPPED}\n")
    # cc1plus stopped by its own CPU-time limit (ulimit -t): "Killed signal terminated program cc1plus".
    text = out.decode("utf-8", "replace")
    if proc.returncode != 0 and "signal terminated program" in text:
        return CompilerStep(proc.returncode, text, timed_out=True, stopped_by="cpu")
    return CompilerStep(proc.returncode, text)


def _read_capped(proc: subprocess.Popen, deadline: Deadline) -> tuple[bytes, str, float]:
    """proc's output (at most MAX_COMPILER_OUTPUT_BYTES), how reading ended
    ("exited"; "cpu" or "wall": the deadline's CPU time or its outer bound
    reached; "overflow": it printed more; the caller kills it) and the CPU
    seconds its processes used. communicate() would hold all of it in our
    memory."""
    from ..worker.process import tree_cpu_ns
    fd = proc.stdout.fileno()
    chunks, size, used_ns = [], 0, 0

    def out_of_time() -> str | None:
        nonlocal used_ns
        used_ns = max(used_ns, tree_cpu_ns(proc.pid))
        if used_ns > deadline.cpu_s * 1e9:
            return "cpu"
        if deadline.stretch_cap_s:
            deadline.note_waits(proc.pid)
        return "wall" if deadline.wall_left() <= 0 else None

    while True:
        ready, _, _ = select.select([fd], [], [], max(0.0, min(0.1, deadline.wall_left())))
        if not ready:
            why = out_of_time()
            if why:
                return b"".join(chunks), why, used_ns / 1e9
            continue
        chunk = os.read(fd, 1 << 16)
        if not chunk:
            break
        chunks.append(chunk)
        size += len(chunk)
        if size > MAX_COMPILER_OUTPUT_BYTES:
            return b"".join(chunks)[:MAX_COMPILER_OUTPUT_BYTES], "overflow", used_ns / 1e9
    proc.stdout.close()
    while proc.poll() is None:
        why = out_of_time()
        if why:
            return b"".join(chunks), why, used_ns / 1e9
        time.sleep(0.01)
    return b"".join(chunks), "exited", used_ns / 1e9


# ---- privilege-drop: what the build uid may read ----------------------------------------

# Gradescope's and PrairieLearn's roots (tests lay them out elsewhere and
# say so in the variables run_autograder and prairielearn.sh read).
PLATFORM_ROOTS = ("/autograder", "/grade")
PLATFORM_ROOT_VARIABLES = ("AUTOGRADER_ROOT", "PL_GRADE_ROOT")
# What each platform root holds that is not the student's to read.
PLATFORM_SENTINELS = ("source", "submission", "submission_metadata.json", "results",
                      "tests", "serverFilesCourse", "student", "data")
PROJECT_SENTINELS = ("grader/grading/rubric.toml", "reference/src/lookup.c", "build/libenvmap.so",
                     "fixtures/manifest.json", "grader", "reference", "build")

# Prints each argument the calling uid can read, or enter if a folder.
_PROBE = ('for p do if [ -r "$p" ] || { [ -d "$p" ] && [ -x "$p" ]; }; then printf "%s\\n" "$p"; fi; done')


class BuildConfinementError(HarnessBuildError):
    """The build uid can read the grader's or the course's files: grading
    would let a submission's compiler quote them. For the instructor."""


def platform_roots() -> list[Path]:
    roots = [Path(p) for p in PLATFORM_ROOTS]
    roots += [Path(os.environ[v]) for v in PLATFORM_ROOT_VARIABLES if os.environ.get(v)]
    return [r for r in dict.fromkeys(roots) if os.path.lexists(r)]


def confined_roots(upload: Path | None, cache_dir: Path | None) -> list[Path]:
    """The folders (and upload) the build uid must not enter, that exist."""
    roots = [PROJECT_ROOT, *platform_roots()]
    roots += [p for p in (cache_dir, upload) if p is not None]
    return [Path(os.path.realpath(r)) for r in dict.fromkeys(roots) if os.path.lexists(r)]


def sentinels(upload: Path | None, cache_dir: Path | None) -> list[Path]:
    """Files and folders the build uid must not read: the roots, and inside
    them what a compiler could quote."""
    found = confined_roots(upload, cache_dir)
    found += [PROJECT_ROOT / name for name in PROJECT_SENTINELS]
    found += [root / name for root in platform_roots() for name in PLATFORM_SENTINELS]
    if upload is not None and os.path.isdir(upload) and not os.path.islink(upload):
        found += [Path(upload) / name for name in sorted(os.listdir(upload))[:100]]
    return [p for p in dict.fromkeys(found) if os.path.lexists(p)]


def readable_by(uid: int, gid: int, paths: list[Path]) -> list[Path]:
    """Which of `paths` a process of uid/gid (no supplementary groups) can
    read or, for a folder, enter: asked of the kernel by a shell running as
    that uid."""
    if not paths:
        return []
    done = subprocess.run(["/bin/sh", "-c", _PROBE, "sh", *map(str, paths)], capture_output=True,
                          stdin=subprocess.DEVNULL, user=uid, group=gid, extra_groups=[],
                          env={"PATH": "/usr/bin:/bin"}, cwd="/", timeout=60)
    return [Path(line) for line in done.stdout.decode("utf-8", "surrogateescape").splitlines() if line]


def _close(root: Path) -> None:
    """chmod o-rwx (and g-rwx when the group is the build gid) on one of our folders or the upload."""
    info = os.lstat(root)
    if stat.S_ISLNK(info.st_mode):
        return
    mode = stat.S_IMODE(info.st_mode) & ~0o007
    if info.st_gid == BUILD_GID:
        mode &= ~0o070
    try:
        os.chmod(root, mode)
    except OSError:
        pass  # e.g. a read-only file system: the second probe says what is still readable


@functools.lru_cache(maxsize=None)
def _ensured(roots: tuple[Path, ...], probes: tuple[Path, ...]) -> None:
    open_ = readable_by(BUILD_UID, BUILD_GID, list(probes))
    if not open_:
        return
    for root in roots:
        _close(root)
    still = readable_by(BUILD_UID, BUILD_GID, list(probes))
    if still:
        shown = ", ".join(str(p) for p in still[:5]) + (f" and {len(still) - 5} more" if len(still) > 5 else "")
        raise BuildConfinementError(
            f"privilege-drop mode: the compiler's uid {BUILD_UID} can still read {shown} after "
            f"chmod o-rwx on {', '.join(map(str, roots))}. A submission's compiler could quote these files "
            "to the student, so nothing is built. Make them unreadable to other users (for example "
            "chmod o-rwx on the folder that holds them, or a parent), or grade where bubblewrap runs "
            "(docs/security.md, Build).")


def ensure_confined(upload: Path | None, cache_dir: Path | None) -> None:
    """Before a privilege-drop build: make the build uid unable to read the
    grader's, the course's and the uploads' files, or raise
    BuildConfinementError. Checked once per set of paths and process."""
    _ensured(tuple(confined_roots(upload, cache_dir)), tuple(sentinels(upload, cache_dir)))


def readable_tree(uid: int, gid: int, roots: list[Path]) -> list[Path]:
    """Every file and folder under `roots` a process of uid/gid can read or
    enter (find as that uid): what it can see, listed."""
    done = subprocess.run(["find", *map(str, roots), "(", "-readable", "-o", "-type", "d", "-executable", ")",
                           "-print"], capture_output=True, stdin=subprocess.DEVNULL, user=uid, group=gid,
                          extra_groups=[], env={"PATH": "/usr/bin:/bin"}, cwd="/", timeout=300)
    return [Path(line) for line in done.stdout.decode("utf-8", "surrogateescape").splitlines() if line]
