"""runner.SubmissionRunner's time budget leaves out the time its workers
waited for a core (issue 32: a loaded machine must not narrow fewer failures
down), within the same cap as a call's wall bound. No worker runs: a
stand-in says what it waited."""
from __future__ import annotations

import time

import numpy as np
import pytest

from grader.worker.runner import SubmissionRunner


class WaitingWorker:
    """What the runner reads of a Worker here: how long its main thread waited."""

    def __init__(self, waited_s: float):
        self.waited_s = waited_s
        self.spun_first_input = False

    def close(self) -> None:
        pass

    def output(self) -> str:
        return ""


@pytest.fixture
def runner():
    runner = SubmissionRunner("never-loaded.so", np.zeros((6, 1, 1, 3), np.float32), sandbox="plain", budget_s=10)
    yield runner
    runner._worker = None


def test_the_wait_for_a_core_is_left_out_of_the_budget(runner):
    runner._worker = WaitingWorker(3.0)
    began, waited = time.monotonic() - 30, runner.waited_s()     # a batch begun 30 s ago
    runner._worker.waited_s = 28.0                               # 25 s of them waiting for a core
    assert runner.budget_used(began, waited) == pytest.approx(5, abs=0.5)


def test_a_worker_dropped_keeps_its_wait_counted(runner):
    runner._worker = WaitingWorker(0.0)
    began, waited = time.monotonic() - 30, runner.waited_s()
    runner._worker.waited_s = 20.0
    runner._drop_worker()
    runner._worker = WaitingWorker(5.0)                          # the next worker, 5 s of waiting so far
    assert runner.budget_used(began, waited) == pytest.approx(5, abs=0.5)


def test_the_wait_left_out_is_capped_at_eight_budgets(runner):
    """As a call's wall bound is (process.WALL_STRETCH_MAX): a main thread
    at SCHED_IDLE on a busy machine waits without end."""
    runner._worker = WaitingWorker(0.0)
    began, waited = time.monotonic() - 200, runner.waited_s()
    runner._worker.waited_s = 1000.0
    assert runner.budget_used(began, waited) == pytest.approx(200 - 8 * 10, abs=0.5)
