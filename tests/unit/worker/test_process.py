"""process.WallBound: a call's wall-clock outer bound stretches by the time
the call waited for a core (issue 32), within a cap, and not at all where
that wait cannot be read. The waits are faked here: the real ones are
tests/sandbox/test_worker_limits.py's."""
from __future__ import annotations

import os
import threading

import pytest

from grader.worker import process
from grader.worker.process import WallBound, run_queue_wait_ns

WORKER = 4242      # a made-up worker pid


@pytest.fixture
def waits(monkeypatch):
    """What each thread has waited for a core (ns), as run_queue_wait_ns
    will say: the worker's main thread under "worker", any other thread (the
    grader's) under "grader"; None: it cannot be read."""
    now = {"worker": 0, "grader": 0}

    def fake(pid, tid=None):
        return now["worker"] if pid == WORKER and tid is None else now["grader"]

    monkeypatch.setattr(process, "run_queue_wait_ns", fake)
    return now


def stretched(bound: WallBound) -> float:
    bound.refresh()
    return bound.end() - bound.began - bound.seconds


def test_the_bound_stretches_by_the_workers_wait_for_a_core(waits):
    bound = WallBound(2.0, WORKER)
    waits["worker"] = 3 * 10**9
    assert stretched(bound) == pytest.approx(3.0)


def test_what_it_had_waited_before_the_call_is_not_counted(waits):
    waits["worker"] = 50 * 10**9
    bound = WallBound(2.0, WORKER)
    waits["worker"] += 10**9
    assert stretched(bound) == pytest.approx(1.0)


def test_a_worker_born_inside_the_bound_counts_all_it_waited(waits):
    waits["worker"] = 10**9
    bound = WallBound(2.0)
    bound.watch_worker(WORKER, born_inside=True)
    assert stretched(bound) == pytest.approx(1.0)


def test_the_graders_own_wait_does_not_stretch_it(waits):
    """The grader's thread wakes every 20 ms to watch the call; on a loaded
    machine it waits at each wake, also while the submission only sleeps."""
    bound = WallBound(2.0, WORKER)
    waits["grader"] = 5 * 10**9
    assert stretched(bound) == 0.0


def test_a_thread_that_waits_without_end_stretches_it_at_most_eight_bounds(waits):
    """A main thread at SCHED_IDLE on a busy machine waits as long as the
    call lasts: the call still ends within 9 bounds of its start."""
    bound = WallBound(2.0, WORKER)
    waits["worker"] = 10**15
    assert stretched(bound) == pytest.approx(8 * 2.0)


def test_where_the_wait_cannot_be_read_the_bound_is_unstretched(waits):
    waits["worker"] = waits["grader"] = None
    bound = WallBound(2.0, WORKER)
    waits["worker"] = waits["grader"] = 10**12
    assert stretched(bound) == 0.0


def test_the_stretch_never_shrinks(waits):
    bound = WallBound(2.0, WORKER)
    waits["worker"] = 10**9
    assert stretched(bound) == pytest.approx(1.0)
    waits["worker"] = None      # the worker has just ended
    assert stretched(bound) == pytest.approx(1.0)


def test_this_kernel_says_how_long_our_own_thread_waited():
    """Where it says "0 0 0" or has no file, the bound is today's (None)."""
    wait = run_queue_wait_ns(os.getpid(), threading.get_native_id())
    if wait is None:
        pytest.skip("no /proc/<pid>/task/<tid>/schedstat here, or sched_info accounting is off")
    assert isinstance(wait, int) and wait >= 0
    assert run_queue_wait_ns(os.getpid(), 2**22 + 1) is None      # no such thread
