"""Red team of the speed check after it timed every side warm (two passes a
round, each side's fastest counted) and redrew crashed rounds.

tests/submissions/redteam3/*.cpp say on line 1 what they do and the verdict a
secure grader gives; each attack has a control, the same lookup without the
trick, shown slow here.

All five worked when found (11x code measured 1.3-6.5x, full points). Three
spent the speed check's allowances where the time is: the timing faces could
be judged right 10% less often than the sweep, and timed answers could differ
from untimed ones on 1%, both counted in lookups (not time) and pooled over
every pass of every round, while the figure that counts is one pass. Two
needed no allowance: the judge asked the student's own readTexture what a
correct fetchColor returns there, and a readTexture that answered the judge
otherwise than the readTexture check on under half of a face was believed.
Each attack tells the speed check's faces by their size and random texels,
so the other checks see the control's code: graded whole, 100 against the
controls' 95. The fix (grader/checks/speed.py): the fastest pass is judged
on its own too, the allowances are near what honest code needs (0.1% timed
against untimed; 0.3% to 2% on the timing faces, by the sweep's own wrong
share), and on the timing faces the judge reads the handout's readTexture
where the read_texture check found the student's right (elsewhere it
believes the live one only where it differs on under 5% of a face).
"""
from __future__ import annotations

from pathlib import Path

import pytest

from grader.grading.grade import GradeOptions, grade
from grader.grading.results import FAILED, GRADED
from test_redteam2 import ISOLATION, mode  # noqa: F401  (mode: both production modes, a fixture)
from project_paths import SUBMISSIONS
from cases import cases

REDTEAM3 = SUBMISSIONS / "redteam3"

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
    if result.status != GRADED or result.isolation != ISOLATION[mode]:
        pytest.fail(f"{name}: {result.status}, {result.isolation}")
    (speed,) = result.checks
    return speed


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.parametrize("name", cases(CONTROLS, representative={"slow_control"}))   # in both modes
def test_the_controls_are_slow(tmp_path, mode, name):
    """What the attacks are without their tricks: 15-20x on an AMD EPYC (the
    limit is 8x; a busy loop's share of the time differs by machine, so the
    controls are slow by a wide margin). The attacks' tests name the
    diagnosis their defence gives, so they test it whatever the margin."""
    speed = speed_of(name, tmp_path, mode)
    assert speed.status == FAILED and [d.id for d in speed.diagnoses] == ["slow"]


@pytest.mark.representative
@pytest.mark.slow
@pytest.mark.sandbox
def test_one_cheap_pass_echoed_untimed_does_not_buy_speed(tmp_path, mode):
    speed = speed_of("one_cheap_pass_echoed", tmp_path, mode)
    assert speed.status == FAILED and [d.id for d in speed.diagnoses] == ["timing-faces-wrong"]


@pytest.mark.slow
@pytest.mark.sandbox
def test_a_readtexture_vouching_for_cheap_lookups_does_not_buy_speed(tmp_path, mode):
    speed = speed_of("readtexture_vouches_for_cheap_lookups", tmp_path, mode)
    assert speed.status == FAILED and [d.id for d in speed.diagnoses] == ["timing-faces-wrong"]


@pytest.mark.slow
@pytest.mark.sandbox
def test_skipping_the_costly_few_while_timed_does_not_buy_speed(tmp_path, mode):
    speed = speed_of("costly_few_skipped_when_timed", tmp_path, mode)
    assert speed.status == FAILED and [d.id for d in speed.diagnoses] == ["timed-output-wrong"]


@pytest.mark.slow
@pytest.mark.sandbox
def test_being_wrong_on_the_costly_few_does_not_buy_speed(tmp_path, mode):
    speed = speed_of("costly_few_wrong_on_timing_faces", tmp_path, mode)
    assert speed.status == FAILED and [d.id for d in speed.diagnoses] == ["timing-faces-wrong"]


@pytest.mark.slow
@pytest.mark.sandbox
def test_a_readtexture_vouching_for_the_costly_few_does_not_buy_speed(tmp_path, mode):
    speed = speed_of("costly_few_vouched_by_readtexture", tmp_path, mode)
    assert speed.status == FAILED and [d.id for d in speed.diagnoses] == ["timing-faces-wrong"]
