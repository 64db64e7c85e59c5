"""Work done once per test session for every xdist worker: `once(name, make)`
runs make(folder) in the first worker to ask, under a file lock, and hands
every caller (that worker and the others) its own unpickled copy of what it
returned. FOLDER is set by tests/conftest.py (a folder all workers of the
session share); unset, make runs at every call, in a new temporary folder.
"""
from __future__ import annotations

import fcntl
import pickle
import tempfile
from pathlib import Path
from typing import Callable, TypeVar

T = TypeVar("T")
FOLDER: Path | None = None
VALUE = "value.pickle"


def once(name: str, make: Callable[[Path], T]) -> T:
    if FOLDER is None:
        return make(Path(tempfile.mkdtemp(prefix=f"{name}-")))
    folder = FOLDER / name
    FOLDER.mkdir(parents=True, exist_ok=True)
    with open(FOLDER / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)    # another worker waits for this one's make, then reads it
        if not (folder / VALUE).exists():
            folder.mkdir(exist_ok=True)
            value = make(folder)
            (folder / f"{VALUE}.tmp").write_bytes(pickle.dumps(value))
            (folder / f"{VALUE}.tmp").replace(folder / VALUE)
    return pickle.loads((folder / VALUE).read_bytes())
