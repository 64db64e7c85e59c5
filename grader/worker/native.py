"""Build the worker executable (worker.c, faults.c, seccomp.c, privileges.c)
once per machine, into build/worker.

Rebuilt when the content hash of its sources and flags changes (recorded in
build/worker.sha256), under a file lock so parallel test processes build it
once; the new binary is renamed into place, so no process runs a half-written
one.
"""
from __future__ import annotations

import fcntl
import hashlib
import os
import subprocess
import threading
from pathlib import Path

from .. import PROJECT_ROOT

ABI_DIR = PROJECT_ROOT / "grader" / "build" / "shim"
# The C files first (compiled), then the headers they include (hashed only).
C_FILES = [Path(__file__).with_name(name) for name in ("worker.c", "faults.c", "seccomp.c", "privileges.c")]
SOURCES = [*C_FILES, *(Path(__file__).with_name(name) for name in ("protocol.h", "faults.h", "seccomp.h", "privileges.h")),
           ABI_DIR / "submission_abi.h"]
BINARY = PROJECT_ROOT / "build" / "worker"
CC = os.environ.get("CC", "cc")
CFLAGS = ["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror"]
# Full RELRO: the worker's GOT is read-only before the submission is loaded,
# and the seccomp filter keeps it so (a submission once redirected the
# worker's clock_gettime through it).
LIBS = ["-Wl,-z,relro,-z,now", "-ldl"]

_lock = threading.Lock()
_checked: Path | None = None


class WorkerBuildError(RuntimeError):
    """The worker did not compile: a harness problem, never the student's."""


def _content_hash() -> str:
    h = hashlib.sha256()
    for path in SOURCES:
        h.update(path.name.encode() + b"\0" + path.read_bytes())
    h.update(" ".join([CC, *CFLAGS, *LIBS]).encode())
    return h.hexdigest()


NULL_SOURCE = Path(__file__).with_name("null_submission.c")
NULL_LIBRARY = PROJECT_ROOT / "build" / "null_submission.so"
_null_checked: Path | None = None


def null_library() -> Path:
    """build/null_submission.so (null_submission.c: lookups that do nothing),
    built like the worker: content hash, lock, atomic rename."""
    global _null_checked
    with _lock:
        if _null_checked is not None:
            return _null_checked
        h = hashlib.sha256()
        for path in (NULL_SOURCE, SOURCES[-1]):
            h.update(path.name.encode() + b"\0" + path.read_bytes())
        h.update(CC.encode())
        digest = h.hexdigest()
        stamp = NULL_LIBRARY.with_name("null_submission.sha256")
        NULL_LIBRARY.parent.mkdir(parents=True, exist_ok=True)
        with open(NULL_LIBRARY.with_name(".worker.lock"), "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            if not (NULL_LIBRARY.is_file() and stamp.is_file() and stamp.read_text().strip() == digest):
                tmp = NULL_LIBRARY.with_name(f".null_submission.{os.getpid()}.so")
                cmd = [CC, "-std=c11", "-O2", "-shared", "-fPIC", "-Wall", "-Werror", "-o", str(tmp), str(NULL_SOURCE)]
                done = subprocess.run(cmd, capture_output=True, text=True)
                if done.returncode != 0:
                    raise WorkerBuildError(f"{' '.join(cmd)} failed:\n{done.stderr}")
                os.chmod(tmp, 0o755)
                os.replace(tmp, NULL_LIBRARY)
                stamp.write_text(digest + "\n")
        _null_checked = NULL_LIBRARY
        return NULL_LIBRARY


def worker_binary() -> Path:
    """The path of an up-to-date worker executable, building it if needed."""
    global _checked
    with _lock:
        if _checked is not None:
            return _checked
        digest = _content_hash()
        stamp = BINARY.with_name("worker.sha256")
        BINARY.parent.mkdir(parents=True, exist_ok=True)
        with open(BINARY.with_name(".worker.lock"), "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            if not (BINARY.is_file() and stamp.is_file() and stamp.read_text().strip() == digest):
                tmp = BINARY.with_name(f".worker.{os.getpid()}")
                cmd = [CC, *CFLAGS, "-o", str(tmp), *map(str, C_FILES), *LIBS]
                done = subprocess.run(cmd, capture_output=True, text=True)
                if done.returncode != 0:
                    raise WorkerBuildError(f"{' '.join(cmd)} failed:\n{done.stderr}")
                os.replace(tmp, BINARY)
                stamp.write_text(digest + "\n")
        _checked = BINARY
        return BINARY
