"""The worker as the checks see it (grader.checks.context.SubmissionLookups)."""
from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

import numpy as np

import time

from ..i18n import _
from .failures import TIMEOUT
from .process import Limits
from .protocol import RECORD_ROW
from .runner import Failure, Outcome, SubmissionRunner, TimedPasses

# All the lookups of one grading together (wall clock, less the time the
# workers waited for a core: SubmissionRunner.budget_used). Past it, every call
# gives up at once with one timeout failure saying why. A lookup that is
# slow everywhere (asleep 0.3 ms per call: every large batch timed out and
# was narrowed down, each call up to the runner's 120 s budget) kept one
# grading busy for more than 10 minutes, past Gradescope's limit. A correct
# submission's lookups take about 3 s of it.
GRADING_BUDGET_S = 150.0

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


class BudgetedRunner(SubmissionRunner):
    """A SubmissionRunner whose calls share one wall-clock budget
    (`total_budget_s`, counted as budget_used counts it: the workers' wait
    for a core left out): each call's own budget is cut to what is left, and
    once nothing is left a call evaluates nothing and reports one timeout."""

    def __init__(self, *args, total_budget_s: float = GRADING_BUDGET_S, **kwargs):
        super().__init__(*args, **kwargs)
        self.total_budget_s, self.spent_s = total_budget_s, 0.0
        self._call_budget_s = self.budget_s

    def _left(self) -> float:
        return self.total_budget_s - self.spent_s

    def _budgeted(self, call):
        self.budget_s = min(self._call_budget_s, self._left())
        began, waited = time.monotonic(), self.waited_s()
        try:
            return call()
        finally:
            self.spent_s += self.budget_used(began, waited)
            self.budget_s = self._call_budget_s

    def _used_up(self, function: str) -> Failure:
        return Failure(kind=TIMEOUT, function=function, index=None, input=f"{function} (the rest of the grading)",
                       message=_("the lookups used up the %(budget)s s that all checks have together, "
                                 "so this call was not run") % {"budget": f"{self.total_budget_s:g}"},
                       hint=_("every call took about as long as its time limit allows: make each lookup fast "
                              "(no sleeping, allocation or searching per call)"),
                       grader_limit=True)   # the whole grading's wall-clock budget: load spends it too

    def _nothing(self, n: int, function: str) -> Outcome:
        return Outcome(values=np.full((n, 3), np.nan), evaluated=np.zeros(n, bool),
                       failures=[self._used_up(function)], gave_up=True, warnings=self.warnings)

    def fetch(self, dirs: np.ndarray, placement: str = "end") -> Outcome:
        if self._left() <= 0:
            return self._nothing(len(np.reshape(dirs, (-1, 3))), "fetchColor")
        return self._budgeted(lambda: SubmissionRunner.fetch(self, dirs, placement))

    def record_fetch(self, dirs: np.ndarray, tags: np.ndarray | None) -> Outcome:
        if self._left() <= 0:
            n = len(np.reshape(dirs, (-1, 3)))
            nothing = self._nothing(n, "fetchColor")
            nothing.values = np.full((n, RECORD_ROW), np.nan)
            return nothing
        return self._budgeted(lambda: SubmissionRunner.record_fetch(self, dirs, tags))

    def read_texture(self, face: int, uv: np.ndarray, placement: str = "end") -> Outcome:
        if self._left() <= 0:
            return self._nothing(len(np.reshape(uv, (-1, 2))), "readTexture")
        return self._budgeted(lambda: SubmissionRunner.read_texture(self, face, uv, placement))

    def time_fetch(self, passes: list[np.ndarray], repeats: int = 1) -> TimedPasses:
        if self._left() <= 0:
            return TimedPasses(failure=self._used_up("fetchColor"))
        return self._budgeted(lambda: SubmissionRunner.time_fetch(self, passes, repeats))


@contextmanager
def open_lookups(library: Path, sandbox: bool | None = None, timeout_s: float = 0.5, sanitize: bool = False,
                 allow_unsafe: bool = False):
    """A SubmissionRunner with no faces yet (checks set their own). Raises
    grader.worker.sandbox.SandboxUnavailable (before anything runs) when no
    isolation is possible here and allow_unsafe is False; the runner's
    `isolation` and `warnings` say what was used.

    timeout_s: the base time limit of one call, plus 0.1 ms per input, in
    the worker's CPU time (a busy machine stretches only the wall clock,
    whose outer bound is 4 times that plus 1 s: process.wall_bound). A
    correct submission answers 100,000 directions in about 10 ms (10.5 s
    allowed), so the limit only bites on a hang, where narrowing it down costs
    about log2(n) limits: the base stays short.
    Grading needs the first few failures of a call, not all of them: after 4
    (or one timeout) the rest of the batch counts as failed.
    """
    # AddressSanitizer reserves terabytes of address space: no RLIMIT_AS then.
    limits = Limits(address_space_mb=None) if sanitize else Limits()
    runner = BudgetedRunner(library, np.zeros((6, 1, 1, 3), np.float32), sandbox=MODES[sandbox],
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
