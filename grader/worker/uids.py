"""A uid of its own for every privilege-drop worker.

Without bubblewrap there is no user or pid namespace around a worker, and
the kernel lets a process signal any other process of its uid: when every
worker was uid nobody, one submission could stop or kill a classmate's
worker, or the speed check's reference, through paths the seccomp filter
did not know (fcntl(F_SETOWN) + O_ASYNC, issue 18), and RLIMIT_NPROC (which
counts the uid's tasks) bounded nothing. So each worker, the reference's and
the null library's included, runs as a uid nobody else uses while it lives:
one of a reserved range, held by an exclusive lock on a file of that uid in
a root-only folder (flock: across processes, released by the kernel when the
holder dies). The range is far from real accounts, nobody (65534) and the
build uid (grader/build/compiler.py BUILD_UID 65533).
"""
from __future__ import annotations

import fcntl
import itertools
import os
import stat
from pathlib import Path

FIRST_UID = 2_000_000_000      # uid and gid; above every account a system creates
COUNT = 4096                   # concurrent workers on one machine, at most
# Root-only: another local user must not be able to hold (or plant) the locks.
LOCK_DIRS = (Path("/run/envmap-worker-uids"), Path("/tmp/envmap-worker-uids-0"))

_next = itertools.count(os.getpid() * 7919)   # where this process starts looking (spreads processes)


class UidsUnavailable(RuntimeError):
    """No reserved uid can be taken here (a folder not root's, all in use, a
    uid map without the range)."""


def mapped(first: int, count: int, map_file: str) -> bool:
    """Whether [first, first + count) is inside this user namespace's map
    (a container with a narrow map cannot switch to uids outside it)."""
    try:
        lines = Path(map_file).read_text().split("\n")
    except OSError:
        return True
    for line in lines:
        parts = line.split()
        if len(parts) == 3 and int(parts[0]) <= first and first + count <= int(parts[0]) + int(parts[2]):
            return True
    return False


def lock_dir() -> Path:
    """The root-only folder of lock files, created if needed, checked always."""
    problems = []
    for folder in LOCK_DIRS:
        try:
            folder.mkdir(mode=0o700, exist_ok=True)
            info = os.lstat(folder)
        except OSError as exc:
            problems.append(f"{folder}: {exc.strerror}")
            continue
        if not stat.S_ISDIR(info.st_mode) or info.st_uid != 0 or info.st_mode & 0o077:
            problems.append(f"{folder} is not a folder only root can use")
            continue
        return folder
    raise UidsUnavailable("no folder for the worker uid locks: " + "; ".join(problems))


class WorkerUid:
    """One reserved uid (= gid), held until release() (or this process ends)."""

    def __init__(self, uid: int, fd: int):
        self.uid, self._fd = uid, fd

    def release(self) -> None:
        if self._fd >= 0:
            os.close(self._fd)     # closing drops the flock
            self._fd = -1

    def __del__(self):
        self.release()


def acquire() -> WorkerUid:
    """A uid of the reserved range that no living worker holds. Call only
    as root. Raises UidsUnavailable."""
    if not (mapped(FIRST_UID, COUNT, "/proc/self/uid_map") and mapped(FIRST_UID, COUNT, "/proc/self/gid_map")):
        raise UidsUnavailable(f"uids {FIRST_UID}..{FIRST_UID + COUNT - 1} are not mapped in this container")
    folder = lock_dir()
    start = next(_next)
    for k in range(COUNT):
        uid = FIRST_UID + (start + k) % COUNT
        fd = os.open(folder / f"{uid}.lock", os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o600)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            continue
        return WorkerUid(uid, fd)
    raise UidsUnavailable(f"all {COUNT} worker uids are in use")
