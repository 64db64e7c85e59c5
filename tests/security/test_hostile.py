"""The hostile zoo (tests/submissions/hostile/*.cpp): each submission gets the
verdict its header comment promises, attributed to the input that causes it,
and a correct submission run right after it still gets correct values.

Most hostile acts fire only for directions near +x, which sit at index 5 of
the batch, so the runner must find that input among the others.
"""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

from grader.build import build_submission
from grader.envmap.library import CubeMap
from grader.worker import Limits, SubmissionRunner, sandbox_problem
from project_paths import SUBMISSIONS

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]   # grades whole submissions

HOSTILE = SUBMISSIONS / "hostile"
CORRECT = SUBMISSIONS / "correct" / "axis_table.cpp"
PROBLEM = sandbox_problem()
needs_sandbox = pytest.mark.skipif(PROBLEM is not None, reason=f"no sandbox here: {PROBLEM}")

FACES = np.random.default_rng(3).random((6, 8, 8, 3), dtype=np.float32)
DIRS = np.array([[0.2, 0.3, -1], [0, 1, 0.1], [-1, 0.2, 0.3], [0.1, -1, 0.5],
                 [0.3, 0.3, 1], [1, 0, 0], [0.5, -0.2, -1], [-0.3, 0.9, 0.1]])
TRIGGER = 5
UV = np.array([[0.5, 0.5], [1.0, 0.5], [0.25, 0.75], [1.0, 1.0], [0.0, 0.0], [0.1, 0.9]])
LIMITS = Limits(address_space_mb=1024)
TIMEOUT_S = 1.0

# name -> (kind, signal, words in the message) for acts inside fetchColor at DIRS[TRIGGER].
FETCH_VERDICTS = {
    "fork": ("forbidden-syscall", "SIGSYS", "tried to start a new process"),
    "system_call": ("forbidden-syscall", "SIGSYS", "forbidden system call"),
    "write_results": ("forbidden-syscall", "SIGSYS", "tried to open 'results.json' for writing"),
    "socket": ("forbidden-syscall", "SIGSYS", "tried to use the network (socket)"),
    "kill_parent": ("forbidden-syscall", "SIGSYS", "tried to send a signal to another process"),
    "exit_mid_check": ("exited", None, "the program ended itself (exit status 0)"),
    "abort": ("crash", "SIGABRT", "abort() was called"),
    "throw": ("exception", None, "direction too close to +x"),
    "alloc_forever": ("exception", None, "std::bad_alloc"),
    "recursion": ("crash", "SIGSEGV", "stack overflow"),
    "spin": ("timeout", None, "did not finish in time"),
    "null_deref": ("crash", "SIGSEGV", "null pointer"),
    "divide_by_zero": ("crash", "SIGFPE", "integer division by zero"),
}


@pytest.fixture(scope="module")
def libraries() -> dict[str, Path]:
    sources = sorted(HOSTILE.glob("*.cpp")) + [CORRECT]
    with ThreadPoolExecutor(2) as pool:
        built = dict(zip(sources, pool.map(build_submission, sources)))
    for source, result in built.items():
        assert result.ok, f"{source.name}: {result.log}"
    return {("correct" if s == CORRECT else s.stem): r.library for s, r in built.items()}


def runner(library: Path, mode: str = "sandbox") -> SubmissionRunner:
    return SubmissionRunner(library, FACES, sandbox=mode, limits=LIMITS, timeout_s=TIMEOUT_S)


def assert_correct_values(outcome, expected, skip=()):
    keep = [i for i in range(len(expected)) if i not in skip]
    assert outcome.evaluated[keep].all()
    np.testing.assert_allclose(outcome.values[keep], expected[keep], rtol=1e-12, atol=1e-12)


def assert_correct_submission_still_works(libraries, mode="sandbox"):
    with runner(libraries["correct"], mode) as correct:
        outcome = correct.fetch(DIRS)
    assert outcome.ok
    assert_correct_values(outcome, CubeMap(FACES).fetch(DIRS))


def test_zoo_covers_every_case():
    names = {p.stem for p in HOSTILE.glob("*.cpp")}
    assert set(FETCH_VERDICTS) | {"read_secrets", "fake_score", "static_init_write", "off_by_one_x",
                                  "minus_one_x"} == names


@pytest.mark.representative
@needs_sandbox
@pytest.mark.parametrize("name", sorted(FETCH_VERDICTS))
def test_hostile_act_in_fetch_color_gets_its_verdict_at_its_input(libraries, name):
    kind, signal, words = FETCH_VERDICTS[name]
    with runner(libraries[name]) as hostile:
        outcome = hostile.fetch(DIRS)
    assert len(outcome.failures) == 1, [f.describe() for f in outcome.failures]
    failure = outcome.failures[0]
    assert (failure.kind, failure.signal, failure.index) == (kind, signal, TRIGGER)
    assert failure.input == "fetchColor(Vector3(1, 0, 0))"
    assert words in failure.message and failure.hint
    assert not outcome.gave_up
    assert_correct_values(outcome, CubeMap(FACES).fetch(DIRS), skip=(TRIGGER,))
    assert np.isnan(outcome.values[TRIGGER]).all()
    assert_correct_submission_still_works(libraries)


@needs_sandbox
def test_off_by_one_read_texture_is_caught_as_out_of_bounds_read_with_its_input(libraries):
    with runner(libraries["off_by_one_x"]) as hostile:
        outcome = hostile.read_texture(0, UV, placement="end")
    assert [(f.kind, f.index, f.signal) for f in outcome.failures] == [("out-of-bounds-read", 3, "SIGSEGV")]
    failure = outcome.failures[0]
    assert failure.input == "readTexture(face +X, u = 1.0, v = 1.0)"
    assert "right after the last texel of face +X" in failure.message
    assert failure.hint.startswith("reading x = W")
    assert_correct_values(outcome, CubeMap(FACES).read_texture(np.zeros(len(UV), int), UV), skip=(3,))


@needs_sandbox
def test_reading_x_minus_one_is_caught_before_a_face_placed_at_a_page_start(libraries):
    with runner(libraries["minus_one_x"]) as hostile:
        outcome = hostile.read_texture(4, UV, placement="start")
    assert [(f.kind, f.index) for f in outcome.failures] == [("out-of-bounds-read", 4)]
    assert outcome.failures[0].input == "readTexture(face +Z, u = 0.0, v = 0.0)"
    assert "12 bytes before the first texel of face +Z" in outcome.failures[0].message
    assert outcome.failures[0].hint.startswith("reading x = -1")


@pytest.mark.representative
@needs_sandbox
def test_files_outside_the_sandbox_are_not_visible(libraries):
    # The same submission prints "LEAK <path>" for every file it can read.
    with runner(libraries["read_secrets"]) as hostile:
        outcome = hostile.fetch(DIRS)
    printed = hostile.output()
    assert outcome.ok
    assert_correct_values(outcome, CubeMap(FACES).fetch(DIRS))
    assert "LEAK" not in printed
    # Outside the sandbox the same code does read them: the check above can fail.
    with runner(libraries["read_secrets"], "plain") as plain:
        plain.fetch(DIRS[TRIGGER:TRIGGER + 1])
    assert "LEAK /etc/passwd" in plain.output()


@needs_sandbox
def test_fake_score_and_megabytes_of_output_change_nothing(libraries):
    with runner(libraries["fake_score"]) as hostile:
        outcome = hostile.fetch(DIRS)
    printed = hostile.output()        # complete: the worker has ended
    assert outcome.ok
    assert_correct_values(outcome, CubeMap(FACES).fetch(DIRS))
    assert printed.startswith('{"score": 100.0}')
    assert "bytes of output elided" in printed and len(printed) < 20000
    assert printed.rstrip().endswith("FINAL SCORE: 100/100")


@needs_sandbox
def test_a_static_initialiser_fails_the_load_and_nothing_is_evaluated(libraries):
    with runner(libraries["static_init_write"]) as hostile:
        outcome = hostile.fetch(DIRS)
        again = hostile.read_texture(0, UV)
    assert [(f.kind, f.index, f.function) for f in outcome.failures] == [("forbidden-syscall", None, "loading")]
    assert "tried to open 'results.json' for writing" in outcome.failures[0].message
    assert "Score: 100/100" in outcome.failures[0].output
    assert not outcome.evaluated.any()
    assert again.failures == outcome.failures
    assert_correct_submission_still_works(libraries)


@pytest.mark.parametrize("name", ["fork", "write_results", "null_deref", "off_by_one_x"])
def test_plain_worker_gives_the_same_verdicts(libraries, name):
    with runner(libraries[name], "plain") as hostile:
        outcome = hostile.read_texture(0, UV) if name == "off_by_one_x" else hostile.fetch(DIRS)
    expected = ("out-of-bounds-read", 3) if name == "off_by_one_x" else (FETCH_VERDICTS[name][0], TRIGGER)
    assert [(f.kind, f.index) for f in outcome.failures] == [expected]
    assert_correct_submission_still_works(libraries, "plain")


def test_the_same_crashing_submission_gets_the_same_failures_ten_times(libraries):
    mode = "sandbox" if PROBLEM is None else "plain"
    seen = set()
    for _ in range(10):
        with runner(libraries["null_deref"], mode) as hostile:
            outcome = hostile.fetch(DIRS)
        seen.add((tuple((f.kind, f.index, f.input, f.message, f.hint, f.signal) for f in outcome.failures),
                  outcome.values[~np.isnan(outcome.values)].tobytes()))
    assert len(seen) == 1
