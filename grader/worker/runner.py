"""Run batches of lookups on a submission and attribute every failure to the
input that causes it.

SubmissionRunner keeps one Worker with the faces loaded. An input that faults
(SIGSEGV, SIGBUS, SIGFPE, SIGILL inside its lookup) costs only itself: the
worker goes on past it and names it (Outcome.recovered_rows, the first few
also as failures). A batch that fails otherwise
(abort, timeout, exception, forbidden call, the program ending itself,
corrupted replies) is narrowed down to its first failing input. The worker
evaluates one input per submission call and notes the index of the input it
is on in a page the grader reads (Worker.progress): that index is a hint
(the submission can write the page), taken once the inputs before it
evaluate in a fresh worker (and, for a timeout, once the input was seen
spinning on, or hangs alone; never after a corrupted reply, as the worker
went on); a hint that does not hold falls back to
bisection. The inputs before it keep their values, and the rest of the
batch continues in that worker. The result is
an Outcome: values (n, 3), NaN rows where nothing could be evaluated, and the
failures, each with the input in words and a hint. The search is the same
every time for the same submission, so the report is too. After
`max_failures` failures in one call, `max_timeouts` timeouts, or when the
batch has used `budget_s` seconds (not counting the time its workers waited
for a core: budget_used), the rest of the batch is given up cleanly
(NaN, `gave_up`); after `max_failed_runs` failed worker runs since the
runner began (or since reset_failure_budget(): the checks call it each), a
failing batch is no longer narrowed down (_give_up).
"""
from __future__ import annotations

import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ..i18n import _
from .failures import FACE_NAMES, PROTOCOL, TIMEOUT, SubmissionFailure, from_crash, hint
from .process import FIRST_INPUT_S, WALL_STRETCH_MAX, Limits, Worker, WorkerHarnessError
from .protocol import RECORD_ROW
from .sandbox import ISOLATION, resolve_mode


# Worker runs that may fail in one check of a submission's grading
# (SubmissionRunner.reset_failure_budget) before failing batches are no longer
# narrowed down (SubmissionRunner._give_up):
# each costs a worker start (20-50 ms), and a submission that fails all over
# would otherwise cost seconds per check. Faults the worker goes on past
# (issue 19) are no failed runs: a missing clamp no longer reaches this. Partial credit: past the budget, the
# inputs after a batch's first failure count as failed without being tried
# (tests/submissions/wrong: crash-null 55.84 -> 55.17 points, stability only;
# out-of-bounds-x1 42.84 -> 42.17; same diagnoses).
MAX_FAILED_RUNS = 24


@dataclass(frozen=True)
class Failure:
    kind: str               # failures.KINDS: crash, timeout, exception, forbidden-syscall, ...
    function: str           # "fetchColor", "readTexture", or "loading" (static initialisers)
    index: int | None       # the input's position in the batch; None when loading failed
    input: str              # e.g. "readTexture(face +X, u = 1.0, v = 0.5)"
    message: str            # what happened, e.g. "out-of-bounds read (SIGSEGV): right after ..."
    hint: str               # what usually causes it
    signal: str | None = None
    output: str = ""        # the tail of what the submission printed
    # A timeout stopped only by the grader's wall-clock bound (on the retry
    # too): a busy machine reaches it as well, so it is not shown to be the code's.
    grader_limit: bool = False

    def describe(self) -> str:
        """One sentence for a report."""
        return _("%(input)s: %(message)s. %(hint)s") % {"input": self.input, "message": self.message, "hint": self.hint}


@dataclass
class Outcome:
    values: np.ndarray                  # (n, 3) float64; NaN rows where not evaluated
    evaluated: np.ndarray               # (n,) bool: rows the submission answered
    failures: list[Failure] = field(default_factory=list)
    gave_up: bool = False               # stopped early (failure cap or time budget)
    warnings: list[str] = field(default_factory=list)
    # Inputs that faulted while the worker went on past them (each one, also
    # beyond the failures described above).
    recovered_rows: list[int] = field(default_factory=list)

    @property
    def fault_rows(self) -> np.ndarray:
        """Every input that failed: those the worker went on past and those
        narrowed down after a failed run."""
        rows = set(self.recovered_rows) | {f.index for f in self.failures if f.index is not None}
        return np.array(sorted(rows), np.int64)

    @property
    def ok(self) -> bool:
        return not self.failures and not self.gave_up


def _number(x: float) -> str:
    x = float(x)
    return str(int(x)) if x.is_integer() and abs(x) < 1e15 and str(x) != "-0.0" else repr(x)


def describe_fetch(direction) -> str:
    x, y, z = (_number(c) for c in direction)
    return f"fetchColor(Vector3({x}, {y}, {z}))"


def describe_read_texture(face: int, u: float, v: float) -> str:
    return f"readTexture(face {FACE_NAMES[face]}, u = {float(u)!r}, v = {float(v)!r})"


@dataclass
class TimedPasses:
    """fetchColor timed from outside: one entry per pass, each over its own
    directions. cpu_ns is the CPU time the kernel charged to the worker
    process for the pass (request and reply included)."""
    cpu_ns: list[int] = field(default_factory=list)
    lookups: list[int] = field(default_factory=list)
    values: list[np.ndarray] = field(default_factory=list)
    failure: Failure | None = None

    def ns_per_lookup(self) -> float | None:
        """The fastest pass, per lookup: on a shared machine noise only adds time."""
        rates = [ns / n for ns, n in zip(self.cpu_ns, self.lookups) if n]
        return min(rates) if rates else None


class SubmissionRunner:
    """Lookups on one submission's library with the faces (6, H, W, 3) given.

    timeout_s + per_input_s * n is the CPU-time limit of one call over n
    inputs (its wall-clock outer bound: process.wall_bound). A run stopped by
    a limit a busy machine can reach too (the wall bound, a kill from
    outside, a worker that did not start) is tried once more before it
    counts (`retries`). The isolation mode is settled here, once (sandbox.resolve_mode:
    SandboxUnavailable when none is possible and allow_unsafe is False);
    `isolation` names it for reports and `warnings` carries what a report
    must say about it. Other keyword arguments go to Worker."""

    def __init__(self, library: str | Path, faces: np.ndarray, *, sandbox: str = "auto",
                 limits: Limits = Limits(), timeout_s: float = 5.0, per_input_s: float = 1e-4,
                 max_failures: int = 16, budget_s: float = 120.0, preload: tuple[str, ...] = (),
                 max_timeouts: int = 2, allow_unsafe: bool = False, max_failed_runs: int | None = MAX_FAILED_RUNS,
                 first_input_s: float = FIRST_INPUT_S):
        self.library = Path(library)
        self.faces = np.ascontiguousarray(faces, dtype=np.float32)
        self.mode, warning = resolve_mode(sandbox, allow_unsafe)
        self.sandbox, self.limits, self.preload = self.mode, limits, preload
        self.timeout_s, self.per_input_s = timeout_s, per_input_s
        # Each worker's first input's extra CPU time (process.FIRST_INPUT_S),
        # until one first input spins through it: a lookup that hangs costs
        # that once, not in every fresh worker (wrong/timeout-loop.cpp,
        # which hangs on the axes: 5.6 s a grading without the allowance,
        # 15.6 s with it in every worker).
        self.first_input_s = first_input_s
        self.max_failures, self.budget_s = max_failures, budget_s
        # Each timeout costs a whole time limit (and more to narrow it down):
        # after this many in one call, the rest of the batch is given up.
        self.max_timeouts = max_timeouts
        # Over this runner's (one submission's grading's) life: past this many
        # worker runs that failed, a failing batch is no longer narrowed down
        # (_give_up). None: no limit.
        self.max_failed_runs = max_failed_runs
        self.warnings: list[str] = [warning] if warning else []
        self.worker_starts = 0
        self.failed_runs = 0     # worker runs that ended in a failure, over this runner's life
        self.retries = 0         # runs tried again after a grader's limit stopped them (grader_limit)
        self._worker: Worker | None = None
        # A worker prepared (Worker.prepare) for the next fresh one, of any
        # size: set up as far as its gate while the grading did other work.
        self._spare: Worker | None = None
        self._placement: str | None = None
        self._load_failure: Failure | None = None
        self._last_output = ""
        self._waited_before_s = 0.0     # what the workers it closed had waited for a core (Worker.waited_s)

    def __enter__(self) -> "SubmissionRunner":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        try:
            self._drop_worker()
        finally:
            self._drop_spare()      # even when the worker's close was interrupted (Ctrl-C)

    @property
    def isolation(self) -> str:
        """"bubblewrap", "privilege-drop" or "unsafe-none"."""
        return ISOLATION[self.mode]

    def output(self) -> str:
        """What the submission printed in the current (or, after close(),
        the last) worker, capped. Complete only once that worker has ended."""
        return self._worker.output() if self._worker else self._last_output

    # ---- public lookups ---------------------------------------------------

    def set_faces(self, faces: np.ndarray, same_process: bool = False) -> None:
        """Use new faces (6, H, W, 3) from the next call on; a running worker
        gets them now. same_process: faces no larger than the running
        worker's go to that worker (state it keeps between calls shows);
        otherwise a new size starts a new worker."""
        self.faces = np.ascontiguousarray(faces, dtype=np.float32)
        fits = same_process and self._worker is not None and self.faces.nbytes <= self._worker.texture_bytes
        if self._worker is not None and self._worker.texture_bytes != self.faces.nbytes and not fits:
            # Each worker's window fits one face size exactly: a new size, a new worker.
            self._drop_worker()
        if self._worker is not None and self._worker.alive:
            try:
                self._worker.set_faces(self.faces, self._placement or "end", timeout_s=self._timeout(0))
            except SubmissionFailure:
                self._drop_worker()   # the next call starts a fresh worker with these faces

    def reset_failure_budget(self) -> None:
        """Failed runs count towards `max_failed_runs` from zero again: each
        check has its own budget, so one check's random inputs never decide
        how far another's are narrowed down (issue 30: the kit's and the
        grader's draws differ)."""
        self.failed_runs = 0

    def restart(self) -> None:
        """The next call runs in a fresh worker with the current faces: no
        state the submission kept (a cache of answers) carries over."""
        self._drop_worker()

    def fetch(self, dirs: np.ndarray, placement: str = "end") -> Outcome:
        """fetchColor for each direction (n, 3), the six faces placed against
        a guard page at their end (or start)."""
        dirs = np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1, 3)

        def run(worker: Worker, lo: int, hi: int) -> np.ndarray:
            return worker.fetch(dirs[lo:hi], timeout_s=self._timeout(hi - lo))

        return self._run_batch(len(dirs), run, placement, "fetchColor", lambda i: describe_fetch(dirs[i]))

    def record_fetch(self, dirs: np.ndarray, tags: np.ndarray | None) -> Outcome:
        """fetchColor for each direction (n, 3) with its readTexture calls
        recorded and answered with `tags` (None: with the student's
        readTexture) (protocol.RECORD_FETCH):
        values are rows (n, protocol.RECORD_ROW), NaN where nothing ran."""
        dirs = np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1, 3)

        def run(worker: Worker, lo: int, hi: int) -> np.ndarray:
            return worker.record_fetch(dirs[lo:hi], tags, timeout_s=self._timeout(hi - lo))

        return self._run_batch(len(dirs), run, "end", "fetchColor", lambda i: describe_fetch(dirs[i]),
                               width=RECORD_ROW)

    def read_texture(self, face: int, uv: np.ndarray, placement: str = "end") -> Outcome:
        """readTexture on face `face` (its own guarded copy) for each (u, v) (n, 2)."""
        uv = np.ascontiguousarray(uv, dtype=np.float64).reshape(-1, 2)

        def run(worker: Worker, lo: int, hi: int) -> np.ndarray:
            return worker.read_texture(face, uv[lo:hi], placement, timeout_s=self._timeout(hi - lo))

        return self._run_batch(len(uv), run, None, "readTexture",
                               lambda i: describe_read_texture(face, *uv[i]))

    def time_fetch(self, passes: list[np.ndarray], repeats: int = 1) -> TimedPasses:
        """fetchColor over each batch of directions in `passes` (give every
        pass fresh ones, so nothing can be cached between passes), each timed
        by the worker process's CPU time read from outside, with the colours
        returned for checking. Stops at the first failure (TimedPasses.failure).
        repeats > 1: each pass is its directions `repeats` times over, in one
        request, and no colours come back (the speed check's warm-up)."""
        timed = TimedPasses()
        for dirs in passes:
            dirs = np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1, 3)

            def run(worker: Worker):
                if repeats == 1:
                    return worker.fetch_timed(dirs, timeout_s=self._timeout(len(dirs)))
                return None, worker.fetch_repeated(dirs, repeats, timeout_s=self._timeout(len(dirs) * repeats))
            try:
                try:
                    worker = self._ready_worker("end")
                    rgb, ns = run(worker)
                except SubmissionFailure as failure:
                    self._drop_worker()
                    if not failure.grader_limit:
                        raise
                    self.retries += 1      # once more: see attempt() in _run_batch
                    worker = self._ready_worker("end")
                    rgb, ns = run(worker)
            except SubmissionFailure as failure:
                self._drop_worker()
                timed.failure = self._failure(failure, "fetchColor", None, _("timing fetchColor over a batch"))
                break
            except _LoadFailed:
                timed.failure = self._load_failure
                break
            if worker.faults:
                # The pass finished, but a fault's cost (the kernel's signal
                # delivery, the handler) is in its time: it times nothing.
                index, report = worker.faults[0]
                timed.failure = self._failure(from_crash(report, "", self.limits.cpu_seconds), "fetchColor", None,
                                              _("timing fetchColor over a batch (%(call)s and %(more)d more crashed)")
                                              % {"call": describe_fetch(dirs[index]), "more": len(worker.faults) - 1})
                break
            timed.cpu_ns.append(ns)
            timed.lookups.append(len(dirs) * repeats)
            if rgb is not None:
                timed.values.append(rgb)
        return timed

    @contextmanager
    def frozen(self):
        """The current worker stopped (SIGSTOP) for the duration, e.g. while
        the reference is timed, so none of its threads can run meanwhile."""
        worker = self._worker
        if worker is not None:
            worker.freeze()
        try:
            yield
        finally:
            if worker is not None:
                worker.thaw()

    # ---- the search -------------------------------------------------------

    def _timeout(self, n: int) -> float:
        return self.timeout_s + self.per_input_s * n

    def waited_s(self) -> float:
        """How long this runner's workers have waited for a core, in s (Worker.waited_s)."""
        return self._waited_before_s + (self._worker.waited_s if self._worker is not None else 0.0)

    def budget_used(self, began: float, waited_s: float) -> float:
        """Seconds of the time budget used since `began`, when the workers had
        waited `waited_s` for a core: the wall time less what they have waited
        since (issue 32: a loaded machine must not narrow fewer failures
        down), that wait counting at most WALL_STRETCH_MAX budgets, as a
        call's wall bound does (process.WALL_STRETCH_MAX says why)."""
        waited = min(self.waited_s() - waited_s, WALL_STRETCH_MAX * self.budget_s)
        return time.monotonic() - began - waited

    def _run_batch(self, n: int, run: Callable[[Worker, int, int], np.ndarray], placement: str | None,
                   function: str, describe: Callable[[int], str], width: int = 3) -> Outcome:
        outcome = Outcome(values=np.full((n, width), np.nan), evaluated=np.zeros(n, bool),
                          warnings=self.warnings)
        began, waited = time.monotonic(), self.waited_s()

        hint: list[int | None] = [None]
        stuck: list[tuple | None] = [None]

        def attempt(lo: int, hi: int) -> SubmissionFailure | None:
            for tries in (1, 2):
                hint[0] = stuck[0] = None
                try:
                    worker = self._ready_worker(placement)
                    outcome.values[lo:hi] = run(worker, lo, hi)
                    outcome.evaluated[lo:hi] = True
                    self._take_faults(outcome, worker, lo, function, describe)
                    return None
                except SubmissionFailure as failure:
                    # Which input was running, as the worker's progress page says. Not
                    # after a reply the worker did not send (protocol): it went on, and
                    # its page says how far it got before the grader looked, which the
                    # machine's load decides; bisection does not (issue 30: forged_reply).
                    hint[0] = (self._worker.progress() if self._worker is not None and failure.kind != PROTOCOL
                               else None)
                    stuck[0] = self._worker.stuck if self._worker is not None else None
                    self._drop_worker()     # a fresh worker after any failure: no state carries over
                    if failure.grader_limit and tries == 1:
                        self.retries += 1   # the machine's limit, maybe not the code's: once more
                        continue
                    self.failed_runs += 1
                    return failure

        lo = 0
        while lo < n:
            timeouts = sum(f.kind == "timeout" for f in outcome.failures)
            # Faults the worker went past cost no time: only failed runs count here.
            narrowed = len(outcome.failures) - min(len(outcome.recovered_rows), self.max_failures)
            if (narrowed >= self.max_failures or timeouts >= self.max_timeouts
                    or self.budget_used(began, waited) > self.budget_s):
                outcome.gave_up = True
                break
            try:
                failure = attempt(lo, n)
                if failure is None:
                    break
                # Invariant: [lo, hi) holds the first failing input.
                hi = n
                # The worker names the input it was evaluating (lo + hint): a
                # hint only, as the submission can write that page. Taken when
                # the inputs before it evaluate in a fresh worker (which then
                # goes on with the rest): it is then the first failing input,
                # as bisection would find, for ~1 worker start instead of
                # ~log2(n). A timeout's input must also hang alone (a slow
                # batch times out anywhere). A wrong hint can only cost the
                # submission (that input counts as failed, or bisection runs),
                # never gain it a value.
                guess = hint[0]
                if self.max_failed_runs is not None and self.failed_runs > self.max_failed_runs:
                    self._give_up(outcome, failure, lo, n, guess, attempt, function, describe)
                    break
                if guess is not None and 0 <= guess < n - lo:
                    f = lo + guess
                    confirmed = failure
                    if failure.kind == TIMEOUT and not (stuck[0] and stuck[0][0] == guess
                                                        and stuck[0][1] >= 0.5 * self.timeout_s
                                                        and stuck[0][2] >= 0.25 * self.timeout_s):
                        # Not seen spinning on that input for long (watched
                        # from here): it must also time out alone.
                        confirmed = attempt(f, f + 1)
                    if confirmed is not None:
                        if f == lo or attempt(lo, f) is None:
                            outcome.failures.append(self._failure(confirmed, function, f, describe(f)))
                            lo = f + 1
                            continue
                        hi = f      # something before it fails: the first failure is there
                while hi - lo > 1 and self.budget_used(began, waited) <= self.budget_s:
                    mid = (lo + hi) // 2
                    if attempt(lo, mid) is None:
                        lo = mid
                    else:
                        hi = mid
                if hi - lo > 1:
                    outcome.gave_up = True
                    break
                # Run the input alone: its own failure, its own output.
                single = attempt(lo, lo + 1)
                if single is not None:
                    outcome.failures.append(self._failure(single, function, lo, describe(lo)))
                lo += 1
            except _LoadFailed:
                outcome.failures.append(self._load_failure)
                break
        return outcome

    def _take_faults(self, outcome: Outcome, worker: Worker, lo: int, function: str,
                     describe: Callable[[int], str]) -> None:
        """The inputs that faulted in a run that went on past them: failed,
        each one named in recovered_rows, the first few described."""
        for index, report in worker.faults:
            row = lo + index
            outcome.values[row] = np.nan
            outcome.evaluated[row] = False
            if len(outcome.recovered_rows) < self.max_failures:
                failure = from_crash(report, "", self.limits.cpu_seconds)
                outcome.failures.append(self._failure(failure, function, row, describe(row)))
            outcome.recovered_rows.append(row)

    def _give_up(self, outcome: Outcome, failure: SubmissionFailure, lo: int, n: int, guess: int | None,
                 attempt, function: str, describe: Callable[[int], str]) -> None:
        """The submission's failed runs are over budget: no more narrowing
        down. The inputs before the one the progress page names are run once
        more (their values kept: they evaluate in a fresh worker), and that
        input and the rest of the batch count as failed, with one failure
        saying so. Without a usable index the whole rest of the batch fails."""
        f = lo + guess if guess is not None and 0 <= guess < n - lo else lo
        if f > lo and attempt(lo, f) is not None:
            f = lo          # the inputs before it fail too: keep nothing (never trust the index more)
        reason = _("%(message)s (after %(runs)d failed runs of this submission the grader "
                   "stopped narrowing failures down: this input and the %(rest)d after it in the batch "
                   "count as failed)") % {"message": failure.message, "runs": self.max_failed_runs, "rest": n - f - 1}
        told = SubmissionFailure(failure.kind, reason, signal_name=failure.signal_name, crash=failure.crash,
                                 fatal=failure.fatal, output=failure.output, exit_status=failure.exit_status,
                                 detail=failure.detail)
        outcome.failures.append(self._failure(told, function, f, describe(f)))
        outcome.gave_up = True

    def _failure(self, failure: SubmissionFailure, function: str, index: int | None, text: str) -> Failure:
        return Failure(kind=failure.kind, function=function, index=index, input=text, message=failure.message,
                       hint=hint(failure, function, timeout_s=self.timeout_s,
                                 memory_mb=self.limits.address_space_mb),
                       signal=failure.signal_name, output=failure.output[-2000:],
                       grader_limit=failure.grader_limit)

    # ---- workers ----------------------------------------------------------

    def _ready_worker(self, placement: str | None) -> Worker:
        """A running worker with the faces set (in `placement`, when given)."""
        if self._load_failure is not None:
            raise _LoadFailed()
        if self._worker is None or not self._worker.alive:
            self._drop_worker()
            # The mode was settled (and allowed) in __init__.
            for tries in (1, 2):
                worker = self._take_spare() if tries == 1 else None
                if worker is None:
                    worker = self._new_worker()
                self.worker_starts += 1
                try:
                    worker.start()
                    worker.set_faces(self.faces, placement or "end", timeout_s=self._timeout(0))
                    break
                except WorkerHarnessError:
                    worker.close()
                    self._waited_before_s += worker.waited_s
                    if tries == 2:
                        raise
                    self.retries += 1       # a worker that did not start: once more before it is ours
                except SubmissionFailure as failure:
                    worker.close()
                    self._waited_before_s += worker.waited_s
                    if failure.grader_limit and tries == 1:
                        self.retries += 1   # stopped by the machine's limit, maybe: once more
                        continue
                    # Loading is the same every time: remember it rather than retry.
                    self._load_failure = self._failure(
                        failure, "loading", None, "loading the submission (static initialisers and the constructor)")
                    raise _LoadFailed() from None
            self._worker, self._placement = worker, placement or "end"
            if self.worker_starts > 1:      # a runner that starts workers again will again
                self._prepare_spare()
        elif placement is not None and placement != self._placement:
            self._worker.set_faces(self.faces, placement, timeout_s=self._timeout(0))
            self._placement = placement
        return self._worker

    def prepare_next(self) -> None:
        """Prepare the next fresh worker now, where none is prepared: for a
        runner that will start its first worker after other, untimed work
        (the speed check's reference and null libraries, prepared while the
        student's worker warms up)."""
        if self._spare is None and self._load_failure is None:
            self._prepare_spare()

    def _new_worker(self) -> Worker:
        return Worker(self.library, sandbox=self.mode, limits=self.limits, preload=self.preload,
                      texture_shape=self.faces.shape[1:3], first_input_s=self.first_input_s)

    def _prepare_spare(self) -> None:
        """A worker prepared for the next fresh start (a check's restart, a
        probe's fresh process, faces of another size). Where it cannot be
        prepared, the next start prepares its own."""
        self._drop_spare()
        spare = self._new_worker()
        try:
            spare.prepare()
        except (WorkerHarnessError, OSError):
            spare.close()
            return
        self._spare = spare

    def _take_spare(self) -> Worker | None:
        """The spare, sized for the current faces; None where there is none
        or it has ended (then closed)."""
        spare, self._spare = self._spare, None
        if spare is None:
            return None
        if not spare.alive:
            spare.close()
            return None
        try:
            spare.size_for(self.faces.shape[1:3])
        except WorkerHarnessError:
            spare.close()       # no longer the runner's: close() would not find it
            raise
        spare.first_input_s = self.first_input_s     # 0 once a first input spun through its allowance
        return spare

    def _drop_spare(self) -> None:
        if self._spare is not None:
            self._spare.close()
            self._spare = None

    def _drop_worker(self) -> None:
        if self._worker is not None:
            if self._worker.spun_first_input:
                self.first_input_s = 0.0
            self._worker.close()
            self._waited_before_s += self._worker.waited_s
            self._last_output = self._worker.output()
            self._worker = None


class _LoadFailed(Exception):
    """The submission cannot be loaded; SubmissionRunner._load_failure says why."""
