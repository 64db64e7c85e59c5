"""A build step's deadline is CPU time of its whole process tree; the wall
clock is only an outer bound (issue 32: a loaded machine, or a classmate's
spinning threads, stretched wall-clock builds past their limit)."""
from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from grader import i18n
from grader.build import BuildResult
from grader.build.compiler import Deadline, run_compiler
from grader.build.messages import describe
from grader.worker.process import run_queue_wait_ns, wall_bound
from loaded import busy_on


def test_waiting_costs_no_cpu_time(tmp_path):
    deadline = Deadline(cpu_s=0.3, wall_end=time.monotonic() + 20)
    step = run_compiler(["/bin/sh", "-c", "sleep 0.8; echo done"], tmp_path, deadline)
    assert not step.timed_out and step.output.strip() == "done"
    assert deadline.cpu_s > 0.15          # what it used is spent: almost nothing


def test_cpu_time_of_every_process_below_counts(tmp_path):
    # The spinning happens in a grandchild, as cc1plus under g++.
    began = time.monotonic()
    step = run_compiler(["/bin/sh", "-c", "sh -c 'while :; do :; done'; echo never"], tmp_path,
                Deadline(cpu_s=0.3, wall_end=time.monotonic() + 60))
    assert step.timed_out and step.stopped_by == "cpu" and "never" not in step.output
    assert time.monotonic() - began < 30   # stopped by its CPU time, not at the wall bound


def test_the_wall_clock_is_the_outer_bound(tmp_path):
    began = time.monotonic()
    step = run_compiler(["/bin/sh", "-c", "sleep 30"], tmp_path, Deadline(cpu_s=60, wall_end=time.monotonic() + 1))
    assert step.timed_out and step.stopped_by == "wall" and time.monotonic() - began < 10


@pytest.mark.skipif(run_queue_wait_ns(os.getpid()) is None, reason="this kernel does not say how long a thread "
                    "waited for a core (/proc/<pid>/task/<tid>/schedstat)")
def test_a_step_kept_waiting_for_a_core_past_its_wall_bound_is_stopped_by_its_cpu_time(tmp_path):
    """The step shares one core with 39 spinning processes: spinning to its
    0.05 s of CPU time takes it about 2 s, past its 1.2 s wall bound, which
    stretches by what its processes waited for that core."""
    core, ours = max(os.sched_getaffinity(0)), os.sched_getaffinity(0)
    with busy_on(core, 39):
        os.sched_setaffinity(0, {core})      # the step's processes inherit it
        try:
            began = time.monotonic()
            step = run_compiler(["/bin/sh", "-c", "while :; do :; done"], tmp_path, Deadline.of(0.05))
            took = time.monotonic() - began
        finally:
            os.sched_setaffinity(0, ours)
    assert took > wall_bound(0.05), f"{took:.2f} s: it was not kept waiting"
    assert step.timed_out and step.stopped_by == "cpu", (step.stopped_by, took)


def test_a_deadline_is_spent_step_by_step(tmp_path):
    deadline = Deadline(cpu_s=0.3, wall_end=time.monotonic() + 60)
    first = run_compiler(["/bin/sh", "-c", "while :; do :; done"], tmp_path, deadline)
    assert first.timed_out and deadline.cpu_s <= 0
    assert run_compiler(["/bin/true"], tmp_path, deadline).stopped_by == "cpu"     # nothing left for the next step


@pytest.mark.parametrize("lang", ["en", "ja"])
@pytest.mark.parametrize("stopped_by, number, not_yours", [("cpu", "60", False), ("wall", "241", True)])
def test_the_student_reads_which_bound_stopped_the_build_and_its_number(stopped_by, number, not_yours, lang):
    """The CPU time is the source's doing (simplify it); the wall-clock bound
    (4 x 60 + 1 s) only a busy machine reaches (submit again)."""
    before = i18n.language()
    i18n.set_language(lang)
    try:
        result = BuildResult(ok=False, library=None, source=Path("EnvironmentMap.cpp"), timed_out=True,
                             stopped_by=stopped_by)
        describe(result, "", 60)
    finally:
        i18n.set_language(before)
    headline = result.log.splitlines()[0]
    assert f"{number} " in headline and result.errors[0]["message"] == headline
    if lang == "en":
        assert ("not your code's doing" in headline) == not_yours, headline
        assert ("make it simpler" in headline) == (not not_yours), headline
    else:
        assert ("あなたのコードのせいではありません" in headline) == not_yours, headline
