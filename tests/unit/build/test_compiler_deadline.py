"""A build step's deadline is CPU time of its whole process tree; the wall
clock is only an outer bound (issue 32: a loaded machine, or a classmate's
spinning threads, stretched wall-clock builds past their limit)."""
from __future__ import annotations

import time

from grader.build.compiler import Deadline, run_compiler


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
    assert step.timed_out and "never" not in step.output
    assert time.monotonic() - began < 30   # stopped by its CPU time, not at the wall bound


def test_the_wall_clock_is_the_outer_bound(tmp_path):
    began = time.monotonic()
    step = run_compiler(["/bin/sh", "-c", "sleep 30"], tmp_path, Deadline(cpu_s=60, wall_end=time.monotonic() + 1))
    assert step.timed_out and time.monotonic() - began < 10


def test_a_deadline_is_spent_step_by_step(tmp_path):
    deadline = Deadline(cpu_s=0.3, wall_end=time.monotonic() + 60)
    first = run_compiler(["/bin/sh", "-c", "while :; do :; done"], tmp_path, deadline)
    assert first.timed_out and deadline.cpu_s <= 0
    assert run_compiler(["/bin/true"], tmp_path, deadline).timed_out     # nothing left for the next step
