"""Attacks on the speed check: lookups that buy speed by being cheaper,
or differently right, only while timed (the red-team rounds' C++ files;
test_speed_trust.py has the wrappers around the reference that need no build).

From the first round (tests/submissions/redteam/):
- fast_when_timed: ten times slow, except on the speed check's 256 x 256
  faces (told by their size) where it took the nearest texel, within the 1%
  the timed colours were checked to: 5 / 5. The timing faces are now judged
  as the sweep judges them, through the student's own readTexture called
  live (grader/checks/speed.py, timing-faces-wrong).

From issue 18's round (tests/submissions/redteam2/): a closed form of the
timing faces, a cheap half of a timed pass, an unchecked tail of one; each
with the slow control it is without its trick.

From the round after the speed check timed every side warm
(tests/submissions/redteam3/): round, each side's fastest counted) and redrew crashed rounds.

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

from grader.checks import speed as speed_check
from grader.grading.grade import GradeOptions, grade
from grader.grading.results import FAILED, GRADED
from cases import cases
from isolation import ISOLATION, isolation_mode
from red_team import REDTEAM, REDTEAM2, REDTEAM3, graded

CONTROLS = ("slow_control", "costly_few_control")
ATTACKS = ("one_cheap_pass_echoed", "readtexture_vouches_for_cheap_lookups", "costly_few_skipped_when_timed",
           "costly_few_wrong_on_timing_faces", "costly_few_vouched_by_readtexture")
RED_TEAM = {"redteam": {"fast_when_timed"},
            "redteam2": {"analytic_when_timed", "slow_busy_control", "black_half_a_timed_pass",
                         "unchecked_tail_of_timed_pass"},
            "redteam3": set(CONTROLS + ATTACKS)}

# Both production modes (tests/helpers/isolation.py), under the name these tests use.
mode = isolation_mode


def speed_of(name: str, out: Path, mode: str, folder: Path = REDTEAM3):
    result = grade(folder / f"{name}.cpp", out, GradeOptions(allow_stale=True, quick=True, only=("speed",)),
                   write_reports=False)
    if result.status != GRADED or result.isolation != ISOLATION[mode]:
        pytest.fail(f"{name}: {result.status}, {result.isolation}")
    (speed,) = result.checks
    return speed


def aimed(name: str, out: Path, mode: str, monkeypatch, folder: Path = REDTEAM3):
    """The speed check with no warm-up, its timed passes where an attack that
    counts a process's calls aims (the first rounds' passes, told by the
    count): how those passes are judged. Graded first as in production,
    where the trick lands in the untimed warm-up of a drawn length or the
    passes after it, unknown to the attack: speed fails all the same."""
    production = speed_of(name, out / "production", mode, folder)
    assert production.status == FAILED and production.score == 0, production.output
    monkeypatch.setattr(speed_check, "WARM_UP_PASSES", (0, 0))
    return speed_of(name, out / "aimed", mode, folder)


# ---- the timing faces told apart by their size -----------------------------------

@pytest.mark.slow
@pytest.mark.sandbox
def test_a_cheaper_path_on_the_timing_faces_fails_the_speed_check(tmp_path):
    result = grade(REDTEAM / "fast_when_timed.cpp", tmp_path, GradeOptions(allow_stale=True, quick=True,
                                                                           only=("speed",)))
    (speed,) = result.checks
    assert speed.status == FAILED and speed.score == 0
    assert [d.id for d in speed.diagnoses] == ["timing-faces-wrong"]
    assert speed.metrics["timed_match"] < 0.5


# ---- speed: the timing faces have a closed form --------------------------------

@pytest.mark.slow
@pytest.mark.sandbox
def test_a_closed_form_of_the_timing_faces_does_not_buy_speed(tmp_path, mode):
    (speed,) = graded(REDTEAM2 / "analytic_when_timed.cpp", tmp_path, mode, only=("speed",)).checks
    assert speed.status == FAILED and speed.score == 0


# ---- speed: which timed answers are compared ------------------------------------

@pytest.mark.slow
@pytest.mark.sandbox
def test_the_slow_control_is_slow(tmp_path, mode):
    """What black_half_a_timed_pass.cpp and unchecked_tail_of_timed_pass.cpp are
    without their tricks: about 25x, slow."""
    (speed,) = graded(REDTEAM2 / "slow_busy_control.cpp", tmp_path, mode, only=("speed",)).checks
    assert speed.status == FAILED and [d.id for d in speed.diagnoses] == ["slow"]


@pytest.mark.slow
@pytest.mark.sandbox
def test_a_cheap_half_pass_does_not_buy_speed(tmp_path, mode, monkeypatch):
    """Worked before the verdict rework (the timed match was pooled over the
    passes, the time the fastest pass: 11x measured 6x); now each pass's
    timed answers are compared with the same code's untimed ones."""
    speed = aimed("black_half_a_timed_pass", tmp_path, mode, monkeypatch, REDTEAM2)
    assert speed.status == FAILED and speed.score == 0
    assert [d.id for d in speed.diagnoses] == ["timed-output-wrong"]     # caught, not merely slow


@pytest.mark.slow
@pytest.mark.sandbox
def test_the_unchecked_tail_of_a_timed_pass_does_not_buy_speed(tmp_path, mode, monkeypatch):
    speed = aimed("unchecked_tail_of_timed_pass", tmp_path, mode, monkeypatch, REDTEAM2)
    assert speed.status == FAILED and speed.score == 0
    assert [d.id for d in speed.diagnoses] == ["timed-output-wrong"]     # caught, not merely slow


# ---- every side timed warm: the fastest pass, the costly few --------------------

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
def test_one_cheap_pass_echoed_untimed_does_not_buy_speed(tmp_path, mode, monkeypatch):
    speed = aimed("one_cheap_pass_echoed", tmp_path, mode, monkeypatch)
    assert speed.status == FAILED and [d.id for d in speed.diagnoses] == ["timing-faces-wrong"]


@pytest.mark.slow
@pytest.mark.sandbox
def test_a_readtexture_vouching_for_cheap_lookups_does_not_buy_speed(tmp_path, mode):
    speed = speed_of("readtexture_vouches_for_cheap_lookups", tmp_path, mode)
    assert speed.status == FAILED and [d.id for d in speed.diagnoses] == ["timing-faces-wrong"]


@pytest.mark.slow
@pytest.mark.sandbox
def test_skipping_the_costly_few_while_timed_does_not_buy_speed(tmp_path, mode, monkeypatch):
    speed = aimed("costly_few_skipped_when_timed", tmp_path, mode, monkeypatch)
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
