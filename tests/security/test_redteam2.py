"""Red team, issue 18's round: attacks a motivated student tried against the
grader after issue 18's trust work, aimed at privilege-drop mode (root, no
bubblewrap: Gradescope, PrairieLearn) and at the scoring logic.

tests/submissions/redteam2/*.cpp say on line 1 what they do and the verdict a
secure grader gives. An attack that still works has an
`xfail(strict=True)` test asserting the secure verdict: it passes now and
fails loudly once the grader is fixed (then drop the mark). An attack that
is held has a plain test that it stays held. docs/security.md, "Red team
(issue 18 round)", has the findings and the fix proposed for each.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from grader.grading.grade import GradeOptions
from grader.grading.results import FAILED, GRADED
from grading_cache import grade_once
from isolation import ISOLATION, isolation_mode
from project_paths import SUBMISSIONS

REDTEAM2 = SUBMISSIONS / "redteam2"

TESTED = {"analytic_when_timed", "fit_on_direct_calls", "half_texel_fetch_control", "black_half_a_timed_pass",
          "slow_busy_control", "caller_by_address", "caller_by_flag", "nearest_control", "echo_fetch_answers",
          "v_flipped_control", "pays_to_be_believed", "unchecked_tail_of_timed_pass",
          "believed_on_two_faces", "swapped_on_y_control"}



def test_every_redteam2_submission_has_a_test():
    assert {p.stem for p in REDTEAM2.glob("*.cpp")} == TESTED
    for p in REDTEAM2.glob("*.cpp"):
        first = p.read_text().splitlines()[0]
        assert first.startswith("// ") and "Verdict" in first


# Both production modes (tests/helpers/isolation.py), under the name these tests use.
mode = isolation_mode


def graded(name: str, out: Path, mode: str, only: tuple[str, ...] = ()):
    # A control beside two attacks is graded once per mode (the cache keys the mode).
    result = grade_once(REDTEAM2 / f"{name}.cpp", out, GradeOptions(allow_stale=True, quick=True, only=only),
                        write_reports=False)
    assert result.status == GRADED, result.status
    assert result.isolation == ISOLATION[mode]
    return result


def by_name(result):
    return {c.name: c for c in result.checks}


# ---- speed: the timing faces have a closed form --------------------------------

@pytest.mark.slow
@pytest.mark.sandbox
def test_a_closed_form_of_the_timing_faces_does_not_buy_speed(tmp_path, mode):
    (speed,) = graded("analytic_when_timed", tmp_path, mode, only=("speed",)).checks
    assert speed.status == FAILED and speed.score == 0


# ---- speed: which timed answers are compared ------------------------------------

@pytest.mark.slow
@pytest.mark.sandbox
def test_the_slow_control_is_slow(tmp_path, mode):
    """What black_half_a_timed_pass.cpp and unchecked_tail_of_timed_pass.cpp are
    without their tricks: about 25x, slow."""
    (speed,) = graded("slow_busy_control", tmp_path, mode, only=("speed",)).checks
    assert speed.status == FAILED and [d.id for d in speed.diagnoses] == ["slow"]


@pytest.mark.slow
@pytest.mark.sandbox
def test_a_cheap_half_pass_does_not_buy_speed(tmp_path, mode):
    """Worked before the verdict rework (the timed match was pooled over the
    passes, the time the fastest pass: 11x measured 6x); now each pass's
    timed answers are compared with the same code's untimed ones."""
    (speed,) = graded("black_half_a_timed_pass", tmp_path, mode, only=("speed",)).checks
    assert speed.status == FAILED and speed.score == 0
    assert [d.id for d in speed.diagnoses] == ["timed-output-wrong"]     # caught, not merely slow


@pytest.mark.slow
@pytest.mark.sandbox
def test_the_unchecked_tail_of_a_timed_pass_does_not_buy_speed(tmp_path, mode):
    (speed,) = graded("unchecked_tail_of_timed_pass", tmp_path, mode, only=("speed",)).checks
    assert speed.status == FAILED and speed.score == 0
    assert [d.id for d in speed.diagnoses] == ["timed-output-wrong"]     # caught, not merely slow


# ---- the judge believes readTexture answers nothing grades ----------------------

CHECKS_OF_FETCH = ("read_texture", "fetch_sweep", "stability")


@pytest.mark.slow
@pytest.mark.sandbox
def test_acting_for_the_model_fit_buys_no_points(tmp_path, mode):
    """Worked before the verdict rework (fetchColor was judged through a model
    fitted on readTexture's direct calls: 75.96 against 40.26); now it is
    judged through readTexture called live, and a readTexture honest on the
    check's sizes but not on the judge's is not believed."""
    attack = graded("fit_on_direct_calls", tmp_path / "attack", mode, only=CHECKS_OF_FETCH)
    control = graded("half_texel_fetch_control", tmp_path / "control", mode, only=CHECKS_OF_FETCH)
    assert by_name(control)["fetch_sweep"].status == FAILED       # the control's fetchColor is wrong
    assert by_name(attack)["fetch_sweep"].status == FAILED
    assert attack.score <= control.score


# ---- readTexture that knows who calls it ----------------------------------------

@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.parametrize("attack, control", [("caller_by_address", "nearest_control"),
                                             ("caller_by_flag", "nearest_control"),
                                             ("echo_fetch_answers", "v_flipped_control")])
def test_a_readtexture_that_knows_its_caller_buys_no_points(tmp_path, mode, attack, control):
    """Bilinear for the grader, something else for fetchColor (by address or
    a flag), or fetchColor's own answers echoed back to a judge that calls
    readTexture: never more than the same fetchColor over one honest readTexture."""
    a = graded(attack, tmp_path / "attack", mode, only=CHECKS_OF_FETCH + ("renders",))
    c = graded(control, tmp_path / "control", mode, only=CHECKS_OF_FETCH + ("renders",))
    assert a.score <= c.score


@pytest.mark.slow
@pytest.mark.sandbox
def test_paying_a_little_readtexture_to_be_believed_buys_no_points(tmp_path, mode):
    a = graded("pays_to_be_believed", tmp_path / "attack", mode, only=CHECKS_OF_FETCH + ("speed",))
    c = graded("v_flipped_control", tmp_path / "control", mode, only=CHECKS_OF_FETCH + ("speed",))
    assert by_name(c)["fetch_sweep"].status == FAILED
    assert by_name(a)["fetch_sweep"].status == FAILED
    assert a.score <= c.score


@pytest.mark.slow
@pytest.mark.sandbox
def test_a_readtexture_acting_on_faces_the_check_never_reads_buys_no_points(tmp_path, mode):
    a = graded("believed_on_two_faces", tmp_path / "attack", mode, only=CHECKS_OF_FETCH)
    c = graded("swapped_on_y_control", tmp_path / "control", mode, only=CHECKS_OF_FETCH)
    assert by_name(c)["fetch_sweep"].status == FAILED
    assert by_name(a)["fetch_sweep"].status == FAILED
    assert a.score <= c.score
