"""Red team of the speed check after it timed every side warm (two passes a
round, each side's fastest counted) and redrew crashed rounds.

tests/submissions/redteam3/*.cpp say on line 1 what they do and the verdict a
secure grader gives; each attack has a control, the same lookup without the
trick, shown slow here. An attack that still works has an
`xfail(strict=True)` test asserting the secure verdict: it passes now and
fails loudly once the grader is fixed (then drop the mark).

All five work (each an xfail below). Three spend the speed check's
allowances where the time is: the timing faces may be judged right 10% less
often than the sweep, and timed answers may differ from untimed ones on 1%,
both counted in lookups (not time) and pooled over every pass of every
round, while the figure that counts is one pass. Two need no allowance: the
judge asks the student's own readTexture what a correct fetchColor returns
there, and a readTexture that answers the judge otherwise than the
readTexture check on under half of a face is believed. Each attack tells
the speed check's faces by their size and random texels, so the other
checks see the control's code: graded whole, 100 against the controls' 95.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from grader.grade import GradeOptions, grade
from grader.results import FAILED, GRADED
from test_redteam2 import ISOLATION, mode  # noqa: F401  (mode: both production modes, a fixture)

REDTEAM3 = Path(__file__).parent / "submissions" / "redteam3"

CONTROLS = ("slow_control", "costly_few_control")
ATTACKS = ("one_cheap_pass_echoed", "readtexture_vouches_for_cheap_lookups", "costly_few_skipped_when_timed",
           "costly_few_wrong_on_timing_faces", "costly_few_vouched_by_readtexture")


def test_every_redteam3_submission_has_a_test():
    assert {p.stem for p in REDTEAM3.glob("*.cpp")} == set(CONTROLS + ATTACKS)
    for p in REDTEAM3.glob("*.cpp"):
        first = p.read_text().splitlines()[0]
        assert first.startswith("// ") and "Verdict" in first


def speed_of(name: str, out: Path, mode: str):
    result = grade(REDTEAM3 / f"{name}.cpp", out, GradeOptions(allow_stale=True, quick=True, only=("speed",)),
                   write_reports=False)
    # Not asserts: inside an xfail only the verdict's assertion may be what fails.
    if result.status != GRADED or result.isolation != ISOLATION[mode]:
        pytest.fail(f"{name}: {result.status}, {result.isolation}")
    (speed,) = result.checks
    return speed


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.parametrize("name", CONTROLS)
def test_the_controls_are_slow(tmp_path, mode, name):
    """What the attacks are without their tricks: 11-12x (the limit is 8x)."""
    speed = speed_of(name, tmp_path, mode)
    assert speed.status == FAILED and [d.id for d in speed.diagnoses] == ["slow"]
    assert speed.metrics["speed_ratio"] > 9.5


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="the timed match is pooled over every pass and round, the time is the fastest pass: one "
                          "pass 90% black (the untimed answers echo it) costs 9% of the judged directions, under "
                          "TIMED_SLACK, and is the figure (11x measured 4.1-4.9x)")
def test_one_cheap_pass_echoed_untimed_does_not_buy_speed(tmp_path, mode):
    speed = speed_of("one_cheap_pass_echoed", tmp_path, mode)
    assert speed.status == FAILED and speed.score == 0


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="the judge believes a live readTexture that differs from the readTexture check's on under "
                          "half of a face (own_read.DIFFERS_HERE): black on 46% of each timing face in both "
                          "(11x measured 6.2-6.5x, every answer judged right)")
def test_a_readtexture_vouching_for_cheap_lookups_does_not_buy_speed(tmp_path, mode):
    speed = speed_of("readtexture_vouches_for_cheap_lookups", tmp_path, mode)
    assert speed.status == FAILED and speed.score == 0


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="TIMED_DIFFER allows 1% of timed answers to differ, priced in lookups, not time: the 0.7% "
                          "of lookups that carry most of the time skipped while timed (11x measured 1.5-1.8x)")
def test_skipping_the_costly_few_while_timed_does_not_buy_speed(tmp_path, mode):
    speed = speed_of("costly_few_skipped_when_timed", tmp_path, mode)
    assert speed.status == FAILED and speed.score == 0


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="TIMED_SLACK lets the timing faces be judged right 10% less often than the sweep (the zoo's "
                          "honest mistakes: at most 0.3% less), priced in lookups, not time: the 0.7% of lookups "
                          "that carry most of the time black on the timing faces (11x measured 1.6x)")
def test_being_wrong_on_the_costly_few_does_not_buy_speed(tmp_path, mode):
    speed = speed_of("costly_few_wrong_on_timing_faces", tmp_path, mode)
    assert speed.status == FAILED and speed.score == 0


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="the judge believes a live readTexture on the timing faces: one that vouches for black on the "
                          "costly 0.7% of (face, u, v) is believed under any DIFFERS_HERE above 0.7%, and no answer is "
                          "wrong or differs, so no allowance is spent (11x measured 1.6x)")
def test_a_readtexture_vouching_for_the_costly_few_does_not_buy_speed(tmp_path, mode):
    speed = speed_of("costly_few_vouched_by_readtexture", tmp_path, mode)
    assert speed.status == FAILED and speed.score == 0
