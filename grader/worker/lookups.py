"""The worker as the checks see it (grader.checks.context.SubmissionLookups)."""
from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

import numpy as np

from .runner import SubmissionRunner

# GradeOptions.sandbox -> SubmissionRunner's mode.
MODES = {None: "auto", True: "sandbox", False: "plain"}


@contextmanager
def open_lookups(library: Path, sandbox: bool | None = None, timeout_s: float = 2.0, preload: tuple[str, ...] = ()):
    """A SubmissionRunner with no faces yet (checks set their own).

    timeout_s: the base time limit of one call; a correct submission answers
    a 100,000-direction batch in about 10 ms, so 2 s plus 0.1 ms per input
    is generous on a loaded machine and keeps a hanging submission cheap.
    """
    runner = SubmissionRunner(library, np.zeros((6, 1, 1, 3), np.float32), sandbox=MODES[sandbox],
                              timeout_s=timeout_s, preload=preload)
    runner.sandboxed = sandbox
    try:
        yield runner
    finally:
        runner.close()
