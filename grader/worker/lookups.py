"""The worker as the checks see it (grader.checks.context.SubmissionLookups)."""
from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

import numpy as np

from .process import Limits
from .runner import SubmissionRunner

# GradeOptions.sandbox -> SubmissionRunner's mode. False (--no-sandbox) means
# "not bubblewrap": privilege-drop where possible, otherwise unsafe only when
# allowed (sandbox.resolve_mode).
MODES = {None: "auto", True: "sandbox", False: "no-bwrap"}


def sanitizer_preload() -> tuple[str, ...]:
    """The AddressSanitizer runtime, which must be loaded before anything else
    in a worker that loads a --sanitize build."""
    import subprocess
    path = subprocess.run(["cc", "-print-file-name=libasan.so"], capture_output=True, text=True).stdout.strip()
    return (path,) if Path(path).is_absolute() else ()


@contextmanager
def open_lookups(library: Path, sandbox: bool | None = None, timeout_s: float = 0.5, sanitize: bool = False,
                 allow_unsafe: bool = False):
    """A SubmissionRunner with no faces yet (checks set their own). Raises
    grader.worker.sandbox.SandboxUnavailable (before anything runs) when no
    isolation is possible here and allow_unsafe is False; the runner's
    `isolation` and `warnings` say what was used.

    timeout_s: the base time limit of one call, plus 0.1 ms per input. A
    correct submission answers 100,000 directions in about 10 ms (10.5 s
    allowed), so the limit only bites on a hang, where narrowing it down costs
    about log2(n) limits: the base stays short.
    Grading needs the first few failures of a call, not all of them: after 4
    (or one timeout) the rest of the batch counts as failed.
    """
    # AddressSanitizer reserves terabytes of address space: no RLIMIT_AS then.
    limits = Limits(address_space_mb=None) if sanitize else Limits()
    runner = SubmissionRunner(library, np.zeros((6, 1, 1, 3), np.float32), sandbox=MODES[sandbox],
                              limits=limits, timeout_s=timeout_s, max_failures=4, max_timeouts=1,
                              preload=sanitizer_preload() if sanitize else (), allow_unsafe=allow_unsafe)
    # For a second runner in the same mode (the speed check's reference).
    runner.sandboxed, runner.allow_unsafe = sandbox, allow_unsafe
    try:
        yield runner
    finally:
        runner.close()


def bind_submission(build, faces: np.ndarray, sandbox: bool | None = None, allow_unsafe: bool = False):
    """A built submission's fetchColor as a batch lookup over `faces` (for the
    study): directions (n, 3) -> colours (n, 3), NaN where it failed. The
    worker lives as long as the returned function."""
    runner = SubmissionRunner(build.library, faces, sandbox=MODES[sandbox], timeout_s=0.5,
                              max_failures=4, max_timeouts=1, allow_unsafe=allow_unsafe)

    def lookup(dirs: np.ndarray) -> np.ndarray:
        return runner.fetch(dirs).values

    lookup.runner = runner   # keeps the worker alive with the function
    return lookup
