"""The runner finds the input that fails from the worker's progress page (the
index of the input being evaluated, shared with the grader) instead of
bisecting, in a couple of worker starts; the page is the submission's to
write, so a forged index must never gain it a value. A fault the worker can
go on past (SIGSEGV, SIGBUS, SIGFPE, SIGILL inside one lookup) costs that
input alone and no worker start (issue 19); an abort still ends the worker
and is narrowed down."""
from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from grader import PROJECT_ROOT
from grader.worker import SubmissionRunner, sandbox

ABI_DIR = PROJECT_ROOT / "grader" / "build" / "shim"
SANDBOX_PROBLEM = sandbox.sandbox_problem()
MODES = ["plain", pytest.param("sandbox", marks=pytest.mark.skipif(
    SANDBOX_PROBLEM is not None, reason=f"no sandbox here: {SANDBOX_PROBLEM}"))]

# fetchColor answers (x, y, z) for direction (x, y, z), except:
#   x == 1: aborts (ends the worker); x == 2: faults (NULL write: the worker goes on);
#   x == 3: spins forever; x == 4: overflows its stack (the worker goes on);
#   x == 5: switches its alternate signal stack off, then faults;
#   x == 7: writes y into the grader's progress page (found in /proc/self/maps), then aborts;
#   x == 8: aborts on the process's z-th call (state: only a fresh worker forgets it);
#   x == 9: sleeps 0.3 s (no CPU time); x == 10: spins for y seconds of CPU time, then answers;
#   x == 6: writes a forged reply ("bad argument") onto the reply pipe, then y into the
#           progress page when y > 0 (how far a worker that went on may have got), and goes on.
STAND_IN = r"""
#define _GNU_SOURCE
#include "submission_abi.h"
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <signal.h>
#include <string.h>
#include <time.h>
#include <fcntl.h>
#include <unistd.h>

static int deeper(volatile int n) { volatile char pad[4096]; pad[0] = (char)n; return deeper(n + 1) + pad[0]; }

int sub_abi_version(void) { return SUB_ABI_VERSION; }
void *sub_create(char *m, size_t s) { (void)m; (void)s; return calloc(1, 16); }
void sub_destroy(void *map) { free(map); }
int sub_set_faces(void *map, const float *t, int w, int h, char *m, size_t s)
{ (void)map; (void)t; (void)w; (void)h; (void)m; (void)s; return SUB_OK; }
static void forge(uint64_t value)
{
    FILE *maps = fopen("/proc/self/maps", "r");
    char line[512];
    while (maps && fgets(line, sizeof line, maps))
        if (strstr(line, "envmap-progress")) {
            unsigned long start = strtoul(line, NULL, 16);
            *(volatile uint64_t *)start = value;
        }
}
static void forge_reply(void)
{
    struct { uint32_t magic, status; uint64_t count, size; } h = { 0x524b4d45u, 2, 0, 5 };
    for (int fd = 3; fd < 64; fd++)
        if (fcntl(fd, F_GETFL) >= 0 && (fcntl(fd, F_GETFL) & O_ACCMODE) == O_WRONLY) {
            if (write(fd, &h, sizeof h) < 0 || write(fd, "yours", 5) < 0) continue;
        }
}
static double cpu_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}
static long calls;
int sub_fetch_batch(void *map, const double *d, size_t n, double *rgb, char *m, size_t s)
{
    (void)map; (void)m; (void)s;
    for (size_t i = 0; i < n; i++) {
        double x = d[3*i], y = d[3*i+1], z = d[3*i+2];
        calls++;
        if (x == 1) abort();
        if (x == 2) *(volatile int *)0 = 1;
        if (x == 3) for (volatile int spin = 1; spin;) {}
        if (x == 4) rgb[3*i] = deeper(0);
        if (x == 5) { stack_t off = { .ss_flags = SS_DISABLE }; sigaltstack(&off, NULL); *(volatile int *)0 = 1; }
        if (x == 7) { forge((uint64_t)y); abort(); }
        if (x == 8 && calls == (long)z) abort();
        if (x == 6) { forge_reply(); if (y > 0) forge((uint64_t)y); }
        if (x == 9) { struct timespec t = { 0, 300000000 }; nanosleep(&t, NULL); }
        if (x == 10) for (double t0 = cpu_s(); cpu_s() - t0 < y;) {}
        rgb[3*i] = x; rgb[3*i+1] = y; rgb[3*i+2] = z;
    }
    return SUB_OK;
}
int sub_read_texture_batch(void *map, const float *addr, const double *uv, size_t n, double *rgb,
                           char *m, size_t s)
{
    (void)map; (void)addr; (void)m; (void)s;
    for (size_t i = 0; i < n; i++) {
        if (uv[2*i] == 1) abort();
        if (uv[2*i] == 2) *(volatile int *)0 = 1;
        rgb[3*i] = uv[2*i]; rgb[3*i+1] = uv[2*i+1]; rgb[3*i+2] = 0;
    }
    return SUB_OK;
}
int sub_record_fetch_batch(void *map, const double *d, size_t n, const double *t, double *rgb, double *c,
                           struct sub_texture_call *calls, char *m, size_t s)
{ (void)map; (void)d; (void)n; (void)t; (void)rgb; (void)c; (void)calls; (void)m; (void)s; return SUB_ERR_ARGUMENT; }
int sub_load_cross(void *map, const char *path, char *m, size_t s)
{ (void)map; (void)path; (void)m; (void)s; return 0; }
"""


@pytest.fixture(scope="module")
def stand_in(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("localise")
    (folder / "stand_in.c").write_text(STAND_IN)
    library = folder / "stand_in.so"
    subprocess.run(["cc", "-std=c11", "-O1", "-shared", "-fPIC", f"-I{ABI_DIR}", "-o", str(library),
                    str(folder / "stand_in.c")], check=True)
    return library


def faces() -> np.ndarray:
    return np.zeros((6, 4, 4, 3), np.float32)


def directions(n: int, special: dict[int, tuple[float, float, float]]) -> np.ndarray:
    dirs = np.column_stack([np.full(n, 0.5), np.arange(n, dtype=float), np.ones(n)])
    for i, d in special.items():
        dirs[i] = d
    return dirs


def honest_rows_only(outcome, dirs) -> None:
    """Every value the runner kept is the stand-in's honest answer."""
    ev = outcome.evaluated
    np.testing.assert_array_equal(outcome.values[ev], dirs[ev])
    assert np.isnan(outcome.values[~ev]).all()


@pytest.mark.parametrize("mode", MODES)
def test_a_crash_is_found_from_the_progress_page_in_two_worker_starts(stand_in, mode):
    dirs = directions(2000, {37: (1, 0, 0)})
    with SubmissionRunner(stand_in, faces(), sandbox=mode, timeout_s=2) as runner:
        outcome = runner.fetch(dirs)
        # The failing batch, then the inputs before 37 (the worker goes on with the rest);
        # bisection needed about log2(2000) = 11.
        assert runner.worker_starts == 2
    assert [(f.index, f.kind) for f in outcome.failures] == [(37, "crash")]
    assert outcome.evaluated.sum() == 1999 and not outcome.evaluated[37]
    honest_rows_only(outcome, dirs)


def test_several_crashes_each_cost_about_one_start(stand_in):
    dirs = directions(1000, {10: (1, 0, 0), 11: (1, 0, 0), 500: (1, 0, 0)})
    with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2) as runner:
        outcome = runner.fetch(dirs)
        assert runner.worker_starts <= 5
    assert [f.index for f in outcome.failures] == [10, 11, 500]
    honest_rows_only(outcome, dirs)


def test_read_texture_crash_is_found_the_same_way(stand_in):
    uv = np.column_stack([np.full(300, 0.25), np.linspace(0, 1, 300)])
    uv[123] = (1, 0.5)
    with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2) as runner:
        outcome = runner.read_texture(2, uv)
        assert runner.worker_starts == 2
    assert [f.index for f in outcome.failures] == [123]
    assert outcome.evaluated.sum() == 299


@pytest.mark.parametrize("forged", [5, 0])
def test_an_index_forged_too_early_only_costs_the_submission(stand_in, forged):
    # It crashes at 40 but names an earlier input: that one is charged, and
    # nothing from 40 on is ever counted as answered.
    dirs = directions(100, {40: (7, forged, 0)})
    with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2) as runner:
        outcome = runner.fetch(dirs)
    assert outcome.failures[0].index == forged      # the page was written: the forged input is charged
    assert not outcome.evaluated[40]
    honest_rows_only(outcome, dirs)


@pytest.mark.parametrize("forged", [70, 99, 10**12])
def test_an_index_forged_later_or_out_of_range_falls_back_to_bisection(stand_in, forged):
    # The hint is relative to the batch: 70 and 99 name inputs after the crash
    # (the inputs before them fail again), 10**12 no input at all.
    dirs = directions(100, {40: (7, forged, 0)})
    with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2) as runner:
        outcome = runner.fetch(dirs)
    assert [(f.index, f.kind) for f in outcome.failures] == [(40, "crash")]
    assert outcome.evaluated.sum() == 99
    honest_rows_only(outcome, dirs)


def test_a_forged_reply_is_narrowed_down_the_same_whatever_the_progress_page_says(stand_in):
    # The worker goes on after a reply it did not send, so its page says how far
    # it got before the grader looked: the machine's load decides that (issue 30:
    # forged_reply.cpp scored 1.28 on renders in the kit, 0 in the grader).
    # Simulated by the stand-in writing the page: the search, its cost and what it
    # keeps must not follow it, within the failure budget or past it.
    seen = set()
    for page in (0, 41, 70, 99):
        dirs = directions(100, {40: (6, page, 0), 80: (6, page, 0)})
        with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2) as runner:
            outcome = runner.fetch(dirs)
            starts = runner.worker_starts
        with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2, max_failed_runs=3) as runner:
            budgeted = runner.fetch(dirs)
        assert [(f.index, f.kind) for f in outcome.failures] == [(40, "protocol"), (80, "protocol")], page
        assert outcome.evaluated.sum() == 98
        honest_rows_only(outcome, dirs)
        honest_rows_only(budgeted, dirs)
        seen.add((starts, tuple(budgeted.evaluated), tuple(f.index for f in budgeted.failures)))
    assert len(seen) == 1, seen


def test_each_check_narrows_failures_down_on_its_own_budget(stand_in):
    dirs = directions(50, {10: (1, 0, 0), 20: (1, 0, 0)})
    with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2, max_failed_runs=2) as runner:
        first = runner.fetch(dirs)          # the budget spent (an earlier check's failures)
        spent = runner.fetch(dirs)
        runner.reset_failure_budget()       # grader.checks.run_checks, before the next check
        fresh = runner.fetch(dirs)
    assert [f.index for f in first.failures] == [10, 20] and first.evaluated.sum() == 48
    assert [f.index for f in spent.failures] == [10] and spent.gave_up and spent.evaluated.sum() == 10
    assert [f.index for f in fresh.failures] == [10, 20] and fresh.evaluated.sum() == 48


def test_a_crash_that_depends_on_state_is_reported_the_same_every_time(stand_in):
    # Crashes on the worker's 30th call, whatever the input: no input fails
    # alone, and the report must still be the same on every run.
    dirs = directions(100, {i: (8, i, 30) for i in range(100)})
    reports = []
    for _ in range(2):
        with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2) as runner:
            outcome = runner.fetch(dirs)
        honest_rows_only(outcome, dirs)
        reports.append(([f.index for f in outcome.failures], outcome.evaluated.tolist(), outcome.gave_up))
    assert reports[0] == reports[1]


@pytest.mark.parametrize("mode", MODES)
def test_a_hang_is_found_without_waiting_for_a_second_time_limit(stand_in, mode):
    dirs = directions(50, {20: (3, 0, 0)})
    with SubmissionRunner(stand_in, faces(), sandbox=mode, timeout_s=0.5, max_timeouts=1) as runner:
        outcome = runner.fetch(dirs)
        starts = runner.worker_starts
    assert [(f.index, f.kind) for f in outcome.failures] == [(20, "timeout")]
    assert outcome.evaluated[:20].all() and not outcome.evaluated[20:].any()
    assert outcome.gave_up
    # The batch, then the inputs before 20 (no third start unless the hang
    # was not seen spinning, e.g. on a very busy machine).
    assert starts in (2, 3)
    honest_rows_only(outcome, dirs)


def test_past_the_failure_budget_the_rest_of_a_failing_batch_counts_as_failed(stand_in):
    dirs = directions(100, {i: (1, 0, 0) for i in (10, 20, 30, 40, 50)})
    with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2, max_failed_runs=3) as runner:
        outcome = runner.fetch(dirs)
        # Three failures narrowed down (one start each), the fourth given up:
        # the inputs before it run once more, nothing after it is tried.
        assert runner.worker_starts == 5
        again = runner.fetch(dirs[:25])
    assert [f.index for f in outcome.failures] == [10, 20, 30, 40]
    assert "stopped narrowing failures down" in outcome.failures[-1].message
    assert "59 after it" in outcome.failures[-1].message
    assert outcome.gave_up
    assert outcome.evaluated[:40].sum() == 37 and not outcome.evaluated[40:].any()
    honest_rows_only(outcome, dirs)
    # Still over budget in the next call: its first failure ends it.
    assert [f.index for f in again.failures] == [10] and again.evaluated.sum() == 10
    honest_rows_only(again, dirs[:25])


def test_the_failure_budget_is_off_when_none(stand_in):
    dirs = directions(60, {i: (1, 0, 0) for i in (10, 20, 30, 40, 50)})
    with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2, max_failed_runs=None) as runner:
        outcome = runner.fetch(dirs)
    assert [f.index for f in outcome.failures] == [10, 20, 30, 40, 50]
    assert outcome.evaluated.sum() == 55 and not outcome.gave_up


# ---- faults the worker goes on past -------------------------------------------------

@pytest.mark.parametrize("mode", MODES)
def test_a_fault_costs_only_its_input_and_no_worker_start(stand_in, mode):
    faulty = (3, 4, 5, 300, 301, 1999)
    dirs = directions(2000, {i: (2, 0, 0) for i in faulty} | {100: (4, 0, 0), 200: (5, 0, 0)})
    with SubmissionRunner(stand_in, faces(), sandbox=mode, timeout_s=2, max_failures=4) as runner:
        outcome = runner.fetch(dirs)
        assert runner.worker_starts == 1
        # The signal mask and the alternate stack are ours again after each
        # one: the worker still answers, and faults again where it should.
        again = runner.fetch(dirs[:10])
        assert runner.worker_starts == 1
    crashed = sorted(faulty + (100, 200))
    assert outcome.recovered_rows == crashed and outcome.fault_rows.tolist() == crashed
    assert not outcome.gave_up and outcome.evaluated.sum() == 2000 - len(crashed)
    # The first few described, with their kind; every one named in recovered_rows.
    assert [(f.index, f.kind) for f in outcome.failures] == [(i, "crash") for i in crashed[:4]]
    assert "null pointer" in outcome.failures[0].message
    honest_rows_only(outcome, dirs)
    assert again.recovered_rows == [3, 4, 5] and again.evaluated.sum() == 7


def test_a_stack_overflow_and_a_fault_without_our_alternate_stack_are_gone_past(stand_in):
    dirs = directions(50, {10: (4, 0, 0), 20: (5, 0, 0), 30: (4, 0, 0)})
    with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2) as runner:
        outcome = runner.fetch(dirs)
        assert runner.worker_starts == 1
    assert outcome.recovered_rows == [10, 20, 30]
    assert "stack overflow" in outcome.failures[0].message
    honest_rows_only(outcome, dirs)


def test_a_read_texture_fault_costs_only_its_input(stand_in):
    uv = np.column_stack([np.full(300, 0.25), np.linspace(0, 1, 300)])
    uv[[0, 123, 299]] = (2, 0.5)
    with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2) as runner:
        outcome = runner.read_texture(2, uv)
        assert runner.worker_starts == 1
    assert outcome.recovered_rows == [0, 123, 299] and outcome.evaluated.sum() == 297


EDGE_CRASH = """// Test submission (tests/sandbox/test_crash_localisation.py): the handout's bilinear readTexture, except that
// it crashes (a read through a null pointer) when u == 1 or v == 1, and nowhere else.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cstddef>

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    (void)direction;
    return readTexture(faceAddress(FACE_POS_X), 0.5, 0.5);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    if (u == 1.0 || v == 1.0)
        addr = *static_cast<const float* volatile*>(nullptr);
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int ix = static_cast<int>(px), iy = static_cast<int>(py);
    const double alpha = px - ix, beta = py - iy;
    const auto texel = [&](int x, int y) -> Color {
        x = std::clamp(x, 0, m_FaceWidth - 1);
        y = std::clamp(y, 0, m_FaceHeight - 1);
        const float* t = addr + 3 * (static_cast<std::ptrdiff_t>(y) * m_FaceWidth + x);
        return {t[0], t[1], t[2]};
    };
    const Color c0 = (1.0 - alpha) * texel(ix, iy) + alpha * texel(ix + 1, iy);
    const Color c1 = (1.0 - alpha) * texel(ix, iy + 1) + alpha * texel(ix + 1, iy + 1);
    return (1.0 - beta) * c0 + beta * c1;
}
"""


# slow: narrowed down per input outside the sandbox (10 s); the sandbox case stays fast
@pytest.mark.parametrize("mode", [pytest.param("plain", marks=pytest.mark.slow), *MODES[1:]])
def test_a_submission_crashing_only_at_u_or_v_one_loses_only_those_inputs(tmp_path, mode):
    """Issue 19: a crash at the face's edge cost a worker start per input and,
    past the failed-run budget, the rest of each batch (20,000 inputs)."""
    from grader.build import build_submission
    from grader.envmap.library import CubeMap
    source = tmp_path / "EnvironmentMap.cpp"
    source.write_text(EDGE_CRASH)
    built = build_submission(source, cache_dir=tmp_path / "cache")
    assert built.ok, built.log
    cube = np.random.default_rng(19).random((6, 16, 16, 3), dtype=np.float32)
    grid = np.linspace(0, 1, 41)
    uv = np.concatenate([np.stack(np.meshgrid(grid, grid), -1).reshape(-1, 2),
                         np.random.default_rng(7).random((5000, 2))])
    edge = np.flatnonzero((uv == 1).any(axis=1))
    with SubmissionRunner(built.library, cube, sandbox=mode, timeout_s=2, max_failures=4) as runner:
        outcome = runner.read_texture(3, uv)
        assert runner.worker_starts == 1
    assert outcome.recovered_rows == edge.tolist() and len(edge) == 81
    assert {f.kind for f in outcome.failures} == {"crash"} and not outcome.gave_up
    inside = np.setdiff1d(np.arange(len(uv)), edge)
    assert outcome.evaluated[inside].all() and not outcome.evaluated[edge].any()
    np.testing.assert_allclose(outcome.values[inside], CubeMap(cube).read_texture(3, uv[inside]), atol=1e-6)


def test_a_fault_while_timed_is_found_without_a_worker_start(stand_in):
    # FETCH_WHOLE: blocks of inputs per call; a block with a fault is evaluated again input by input.
    dirs = directions(10000, {5: (2, 0, 0), 9000: (2, 0, 0), 9001: (4, 0, 0)})
    with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2) as runner:
        timed = runner.time_fetch([dirs])
        assert runner.worker_starts == 1
        assert [i for i, _ in runner._worker.faults] == [5, 9000, 9001]
        # The pass times nothing (a fault's cost is in it): a failure naming the first, the worker alive.
        assert timed.failure.kind == "crash" and "Vector3(2, 0, 0)" in timed.failure.input
        assert "2 more crashed" in timed.failure.input and runner._worker.alive
        again = runner.time_fetch([dirs[:5]])
        assert again.failure is None and runner.worker_starts == 1
        np.testing.assert_array_equal(again.values[0], dirs[:5])
