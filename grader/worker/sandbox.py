"""The bubblewrap sandbox around the worker, and whether this machine has one.

Inside: /usr (and the /lib* links) read-only, the worker binary and one
folder holding the submission's library, read-only, under /sandbox; a fresh
/tmp (the working directory), /proc and a minimal /dev. No network, no other
namespace shared, no capabilities, an unprivileged uid, no environment. The
project tree, fixtures/, build/libenvmap.so, other submissions and the
results directory are simply not there.

Where bubblewrap is missing or cannot create namespaces (a container without
user namespaces, another OS), `sandbox_problem()` says why. Then, when the
grader runs as root (Gradescope, most Docker images), the worker runs in
privilege-drop mode: it chroots into a fresh folder holding only the
submission and becomes a uid/gid of its own (uids.py) before loading it,
in a pid namespace of its own where the container allows one. Where neither is
possible, `resolve_mode` raises SandboxUnavailable unless the caller allowed
running without isolation ("unsafe-none", with a warning for the report).
Never silently: every runner says which isolation it used.
"""
from __future__ import annotations

import functools
import os
import shutil
import subprocess
import sys
from pathlib import Path

SANDBOX_ROOT = "/sandbox"
WORKER_INSIDE = f"{SANDBOX_ROOT}/worker"
INPUT_INSIDE = f"{SANDBOX_ROOT}/input"
NOBODY = "65534"
# Modes a Worker can be asked for: "auto" picks the safest that works here;
# "sandbox" is bubblewrap, "privilege-drop" the root-only chroot + setuid,
# "plain" no isolation beyond limits and seccomp.
MODES = ("auto", "sandbox", "privilege-drop", "plain")
# What reports call each mode (GradeResult.isolation).
ISOLATION = {"sandbox": "bubblewrap", "privilege-drop": "privilege-drop", "plain": "unsafe-none"}


class SandboxUnavailable(Exception):
    """No isolation is possible here and the caller did not allow grading
    without it (--unsafe-no-sandbox). The message says why and what to do."""


def system_binds() -> list[str]:
    """Read-only views of what a dynamically linked program needs."""
    args = ["--ro-bind", "/usr", "/usr"]
    for name in ("bin", "sbin", "lib", "lib32", "lib64", "libx32"):
        path = Path("/") / name
        if path.is_symlink():
            args += ["--symlink", os.readlink(path), f"/{name}"]
        elif path.is_dir():
            args += ["--ro-bind", str(path), f"/{name}"]
    return args


def isolation(unprivileged: bool) -> list[str]:
    """bwrap and the options every sandboxed process gets: no namespace
    shared (so no network), no capabilities, no environment, the system
    read-only, a fresh /tmp, /proc and a minimal /dev. `unprivileged` also
    runs it as nobody (the worker); the compiler keeps our uid to write its output."""
    user = ["--unshare-user", "--uid", NOBODY, "--gid", NOBODY] if unprivileged else []
    return [shutil.which("bwrap") or "bwrap", "--unshare-all", *user, "--cap-drop", "ALL",
            "--die-with-parent", "--new-session", "--clearenv", *system_binds(),
            "--proc", "/proc", "--dev", "/dev", "--tmpfs", "/tmp"]


def isolation_as_root() -> list[str]:
    """bwrap for a worker when the grader is root: the same namespaces but the
    user's, and only the capabilities to become another uid, which the worker
    uses at once (--uid: a uid of its own, uids.py). With a user namespace,
    root's bwrap maps the sandbox's nobody to root itself, whom the kernel
    exempts from RLIMIT_NPROC: a thread bomb was unbounded."""
    return [shutil.which("bwrap") or "bwrap", "--unshare-ipc", "--unshare-pid", "--unshare-net", "--unshare-uts",
            "--unshare-cgroup-try", "--cap-drop", "ALL", "--cap-add", "CAP_SETUID", "--cap-add", "CAP_SETGID",
            "--die-with-parent", "--new-session", "--clearenv", *system_binds(),
            "--proc", "/proc", "--dev", "/dev", "--tmpfs", "/tmp"]


def bwrap_command(worker: Path, input_dir: Path, worker_args: list[str], env: dict[str, str],
                  as_root: bool = False) -> list[str]:
    """The command running `worker` inside the sandbox; `worker_args` refer to
    files of `input_dir` as INPUT_INSIDE/<name>. `as_root`: the grader is
    root and `worker_args` carry the uid the worker switches to."""
    # As root, bwrap makes /sandbox 0700: the worker's uid must be able to enter it.
    cmd = [*(isolation_as_root() + ["--perms", "0755", "--dir", SANDBOX_ROOT] if as_root
             else isolation(unprivileged=True)),
           "--ro-bind", str(worker), WORKER_INSIDE,
           "--ro-bind", str(input_dir), INPUT_INSIDE,
           "--chdir", "/tmp"]
    for key, value in env.items():
        cmd += ["--setenv", key, value]
    return cmd + ["--", WORKER_INSIDE, *worker_args]


@functools.lru_cache(maxsize=1)
def sandbox_problem() -> str | None:
    """None when bubblewrap works here; otherwise why not (once per process)."""
    if not sys.platform.startswith("linux"):
        return f"bubblewrap needs Linux (this is {sys.platform})"
    bwrap = shutil.which("bwrap")
    if bwrap is None:
        return "bwrap (Debian package bubblewrap) is not installed"
    true = shutil.which("true") or "/usr/bin/true"
    cmd = [*isolation(unprivileged=True), "--", true]
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=20)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return f"bwrap could not run: {exc}"
    if done.returncode != 0:
        reason = done.stderr.strip().splitlines()
        return f"bwrap failed: {reason[-1] if reason else f'exit status {done.returncode}'}"
    return None


def fallback_warning(reason: str) -> str:
    return (f"sandbox unavailable: {reason}; ran with resource limits and the seccomp filter only "
            "(isolation unsafe-none: the submission could read and write what the grader's user can)")


@functools.lru_cache(maxsize=1)
def privilege_drop_problem() -> str | None:
    """None when the worker can chroot and become nobody here (we are root);
    otherwise why not (once per process)."""
    if not sys.platform.startswith("linux"):
        return f"privilege-drop needs Linux (this is {sys.platform})"
    if os.geteuid() != 0:
        return "the grader does not run as root, so it cannot switch the worker to another user"
    import tempfile
    from . import uids
    from .native import worker_binary
    try:
        held = uids.acquire()
    except (uids.UidsUnavailable, OSError) as exc:
        return f"no uid of its own for the worker: {exc}"
    uid = str(held.uid)
    with tempfile.TemporaryDirectory(prefix="envmap-drop-") as root:
        try:
            done = subprocess.run([str(worker_binary()), "--check-drop", "--chroot", root, "--uid", uid,
                                   "--gid", uid], capture_output=True, timeout=20)
        except (OSError, subprocess.TimeoutExpired) as exc:
            return f"the worker could not drop its privileges: {exc}"
        finally:
            held.release()
    if done.returncode != 0:
        return f"the worker could not drop its privileges (exit status {done.returncode})"
    return None


def unavailable_message(problem: str) -> str:
    return (f"No isolation is possible for student code on this machine: {problem}; and without root the "
            "worker cannot drop its privileges either. Install bubblewrap with user namespaces enabled, or run "
            "the grader as root (privilege-drop mode), or pass --unsafe-no-sandbox to grade anyway (the "
            "submission could then read the grader's environment and write its files).")


def resolve_mode(requested: str = "auto", allow_unsafe: bool = False) -> tuple[str, str | None]:
    """(mode, warning) for a worker asked for `requested`: "auto" takes
    bubblewrap, else privilege-drop, else plain only with `allow_unsafe`
    (else SandboxUnavailable). "no-bwrap" is "auto" without bubblewrap
    (--no-sandbox). Forced modes that cannot run here raise SandboxUnavailable."""
    if requested not in (*MODES, "no-bwrap"):
        raise ValueError(f"sandbox mode must be one of {', '.join(MODES)}, not {requested!r}")
    if requested == "plain":
        return "plain", None
    if requested == "sandbox":
        problem = sandbox_problem()
        if problem:
            raise SandboxUnavailable(f"bubblewrap requested but unavailable: {problem}")
        return "sandbox", None
    if requested == "privilege-drop":
        problem = privilege_drop_problem()
        if problem:
            raise SandboxUnavailable(f"privilege-drop mode requested but unavailable: {problem}")
        return "privilege-drop", None
    bwrap = sandbox_problem() if requested == "auto" else "bubblewrap not wanted (--no-sandbox)"
    if bwrap is None:
        return "sandbox", None
    if privilege_drop_problem() is None:
        return "privilege-drop", None
    if allow_unsafe:
        return "plain", fallback_warning(bwrap)
    raise SandboxUnavailable(unavailable_message(bwrap))


def compiler_command(cmd: list[str], read_only: list[Path], writable: Path) -> list[str]:
    """`cmd` (a compiler run on a student's file) inside bubblewrap: the
    system, our headers (`read_only`) and the build folder (`writable`, also
    the working directory) are all it sees; no network, no capabilities, no
    environment but PATH and LC_ALL. Same uid as ours, so it can write its
    output; paths keep their names, so messages read the same."""
    args = [*isolation(unprivileged=False), "--setenv", "PATH", "/usr/bin:/bin", "--setenv", "LC_ALL", "C"]
    for path in read_only:
        args += ["--ro-bind", str(path), str(path)]
    args += ["--bind", str(writable), str(writable), "--chdir", str(writable)]
    return args + ["--", *cmd]
