"""Attacks on the worker's lifetime and scheduling (the first red-team round,
tests/submissions/redteam/): each must be charged to the submission, never
blamed on the grader, and must not hang it.

- asleep_everywhere: correct but asleep 0.3 ms per lookup (no CPU time):
  every large batch timed out and was narrowed down, each call up to the
  runner's 120 s, and one grading ran for more than 11 minutes. Now all the
  lookups of one grading share a wall-clock budget (grader/worker/lookups.py
  BudgetedRunner, GRADING_BUDGET_S); past it a call fails at once.
- starve_other_worker: in privilege-drop mode every worker is uid nobody
  with no pid namespace, so a submission could put another process of that
  uid (another student's worker in grade-all, the speed check's reference)
  into SCHED_IDLE at nice 19 on one CPU, to starve it into timeouts. Now the
  seccomp filter refuses (EPERM) scheduling, priority and page placement of
  any process but the worker itself (grader/worker/seccomp.c on_other_pid).
Attacks the grader already handled, kept as regression tests at the worker:
exit status 73 from a static initialiser, a destructor that never returns,
an interval timer interrupting the worker, SIGSTOP to itself.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from grader.build import build_submission
from grader.envmap.library import CubeMap
from grader.worker import Limits, SubmissionRunner, WorkerHarnessError, sandbox, sandbox_problem
from red_team import REDTEAM

RED_TEAM = {"redteam": {"exit_as_setup_error", "hang_at_exit", "interval_timer", "stop_itself", "asleep_everywhere",
                        "starve_other_worker"}}
PROBLEM = sandbox_problem()
MODE = "sandbox" if PROBLEM is None else "plain"

FACES = np.random.default_rng(9).random((6, 8, 8, 3), dtype=np.float32)
DIRS = np.array([[0.2, 0.3, -1], [0, 1, 0.1], [-1, 0.2, 0.3], [0.1, -1, 0.5],
                 [0.3, 0.3, 1], [1, 0, 0], [0.5, -0.2, -1], [-0.3, 0.9, 0.1]])
TRIGGER = 5     # DIRS[TRIGGER] is +x, where the hostile acts fire


@pytest.fixture(scope="module")
def libraries() -> dict[str, Path]:
    out = {}
    for name in ("exit_as_setup_error", "hang_at_exit", "interval_timer", "stop_itself", "asleep_everywhere"):
        built = build_submission(REDTEAM / f"{name}.cpp")
        assert built.ok, built.log
        out[name] = built.library
    return out


def runner(library: Path) -> SubmissionRunner:
    return SubmissionRunner(library, FACES, sandbox=MODE, limits=Limits(address_space_mb=1024), timeout_s=1.0)


@pytest.mark.sandbox
def test_exit_status_73_while_loading_is_the_submissions_failure(libraries):
    with runner(libraries["exit_as_setup_error"]) as r:
        try:
            outcome = r.fetch(DIRS)
        except WorkerHarnessError as e:   # the grader's own failure: the attack worked
            pytest.fail(f"blamed on the grader: {e}")
    assert [(f.kind, f.function, f.index) for f in outcome.failures] == [("exited", "loading", None)]
    assert "exit status 73" in outcome.failures[0].message
    assert not outcome.evaluated.any()


@pytest.mark.sandbox
@pytest.mark.parametrize("name", ["hang_at_exit", "interval_timer"])
def test_a_worker_that_hangs_at_exit_or_is_interrupted_gives_correct_values(libraries, name):
    with runner(libraries[name]) as r:
        outcome = r.fetch(DIRS)
        again = r.read_texture(2, np.array([[0.5, 0.5], [1.0, 1.0], [0.0, 0.25]]))
    assert outcome.ok and again.ok, [f.describe() for f in outcome.failures + again.failures]
    np.testing.assert_allclose(outcome.values, CubeMap(FACES).fetch(DIRS), rtol=1e-12, atol=1e-12)


# slow: waits out wall-clock bounds on purpose (7-10 s)
@pytest.mark.slow
@pytest.mark.sandbox
def test_a_worker_that_stops_itself_times_out_at_that_input(libraries):
    with runner(libraries["stop_itself"]) as r:
        outcome = r.fetch(DIRS)
    assert [(f.kind, f.index) for f in outcome.failures] == [("timeout", TRIGGER)]
    keep = [i for i in range(len(DIRS)) if i != TRIGGER]
    assert outcome.evaluated[keep].all()
    np.testing.assert_allclose(outcome.values[keep], CubeMap(FACES).fetch(DIRS)[keep], rtol=1e-12, atol=1e-12)


# slow: waits out wall-clock bounds on purpose (7-10 s)
@pytest.mark.slow
@pytest.mark.sandbox
def test_a_lookup_asleep_everywhere_uses_up_the_gradings_budget_and_stops(libraries):
    from grader.worker.lookups import BudgetedRunner
    # About 1 s asleep (1,000 lookups of 0.3 ms sleeps, which take up to 1 ms in the sandbox; 4,000
    # of them outlasted the bound here, and passed only on the retry): within the wall-clock outer
    # bound (4 x 0.6 s + 1 s, issue 21) with 2.4 s to spare for a loaded machine, using no CPU
    # time; the grading's budget is what stops it.
    dirs = np.random.default_rng(4).normal(size=(1000, 3))
    with BudgetedRunner(libraries["asleep_everywhere"], FACES, sandbox=MODE, timeout_s=0.5, per_input_s=1e-4,
                        max_failures=4, max_timeouts=1, total_budget_s=3.0) as r:
        first = r.fetch(dirs)
        while r.spent_s < r.total_budget_s:   # each call spends at least one time limit
            r.fetch(dirs)
        starts = r.worker_starts
        later = [r.fetch(dirs), r.read_texture(0, np.full((10, 2), 0.5)), r.time_fetch([dirs])]
    assert first.ok
    for outcome in later[:2]:
        assert outcome.gave_up and not outcome.evaluated.any()
        assert [(f.kind, f.index) for f in outcome.failures] == [("timeout", None)]
        assert "used up the 3 s" in outcome.failures[0].message
    assert later[2].failure.kind == "timeout" and not later[2].cpu_ns
    assert r.worker_starts == starts          # nothing more was started


@pytest.mark.sandbox
@pytest.mark.parametrize("mode", ["plain", pytest.param("privilege-drop", marks=pytest.mark.skipif(
    sandbox.privilege_drop_problem() is not None, reason="no privilege drop here"))])
def test_a_worker_cannot_starve_another_worker(mode):
    import os
    from grader.worker import Worker
    attacker = build_submission(REDTEAM / "starve_other_worker.cpp")
    victim = build_submission(sorted((REDTEAM.parent / "correct").glob("*.cpp"))[0])
    assert attacker.ok and victim.ok, attacker.log + victim.log
    with Worker(victim.library, sandbox=mode) as v, Worker(attacker.library, sandbox=mode) as a:
        v.set_faces(FACES)
        a.set_faces(FACES)
        pid = v._worker_pid
        before = (os.sched_getscheduler(pid), os.getpriority(os.PRIO_PROCESS, pid), os.sched_getaffinity(pid))
        np.testing.assert_array_equal(a.fetch([[pid, 0, 12345]]), [[0, 0, 0]])   # it ran, and lived
        after = (os.sched_getscheduler(pid), os.getpriority(os.PRIO_PROCESS, pid), os.sched_getaffinity(pid))
        np.testing.assert_allclose(v.fetch(DIRS), CubeMap(FACES).fetch(DIRS), rtol=1e-12, atol=1e-12)
    assert after == before and before[0] != os.SCHED_IDLE
