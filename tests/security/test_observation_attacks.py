"""Attacks on what the grader observes: a readTexture or fetchColor that
tells when, or by whom, it is being measured, to be right only then.

From issue 18's round (tests/submissions/redteam2/): acting for the model
fit on readTexture's direct calls; a readTexture that knows its caller (by
address, by a flag) or echoes fetchColor's answers to the judge; one that
pays a little to be believed, or acts on faces the check never reads. Each
is graded beside the control it is without its trick: never more points.

From issue 29's round (tests/submissions/recording/): a fetchColor that
tries to tell when its readTexture calls are being recorded, to behave only
then. The grader records each direction twice (answered with its own tags,
and by the student's own readTexture) through one map class, and judges a
direction on the record only where both runs ask the same: any behaviour
that depends on who answers shows as different calls or an answer not
returned.

Both isolation modes (tests/helpers/isolation.py).
"""
from __future__ import annotations

import pytest

from grader.grading.results import FAILED
from isolation import isolation_mode
from red_team import RECORDING, REDTEAM2, by_name, graded

DETECTORS = ("tag_detector", "tag_shaped", "call_counter")
RED_TEAM = {"redteam2": {"fit_on_direct_calls", "half_texel_fetch_control", "caller_by_address", "caller_by_flag",
                         "nearest_control", "echo_fetch_answers", "v_flipped_control", "pays_to_be_believed",
                         "believed_on_two_faces", "swapped_on_y_control"},
            "recording": set(DETECTORS) | {"typeid_detector"}}
# Checks that judge fetchColor on the record (renders stay end to end: they
# show what the code does when it is not recorded).
ON_THE_RECORD = ("fetch_sweep", "diagnosis", "arrows", "stability")

# Both production modes (tests/helpers/isolation.py), under the name these tests use.
mode = isolation_mode


# ---- the judge believes readTexture answers nothing grades ----------------------

CHECKS_OF_FETCH = ("read_texture", "fetch_sweep", "stability")


@pytest.mark.slow
@pytest.mark.sandbox
def test_acting_for_the_model_fit_buys_no_points(tmp_path, mode):
    """Worked before the verdict rework (fetchColor was judged through a model
    fitted on readTexture's direct calls: 75.96 against 40.26); now it is
    judged through readTexture called live, and a readTexture honest on the
    check's sizes but not on the judge's is not believed."""
    attack = graded(REDTEAM2 / "fit_on_direct_calls.cpp", tmp_path / "attack", mode, only=CHECKS_OF_FETCH)
    control = graded(REDTEAM2 / "half_texel_fetch_control.cpp", tmp_path / "control", mode, only=CHECKS_OF_FETCH)
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
    a = graded(REDTEAM2 / f"{attack}.cpp", tmp_path / "attack", mode, only=CHECKS_OF_FETCH + ("renders",))
    c = graded(REDTEAM2 / f"{control}.cpp", tmp_path / "control", mode, only=CHECKS_OF_FETCH + ("renders",))
    assert a.score <= c.score


@pytest.mark.slow
@pytest.mark.sandbox
def test_paying_a_little_readtexture_to_be_believed_buys_no_points(tmp_path, mode):
    a = graded(REDTEAM2 / "pays_to_be_believed.cpp", tmp_path / "attack", mode, only=CHECKS_OF_FETCH + ("speed",))
    c = graded(REDTEAM2 / "v_flipped_control.cpp", tmp_path / "control", mode, only=CHECKS_OF_FETCH + ("speed",))
    assert by_name(c)["fetch_sweep"].status == FAILED
    assert by_name(a)["fetch_sweep"].status == FAILED
    assert a.score <= c.score


@pytest.mark.slow
@pytest.mark.sandbox
def test_a_readtexture_acting_on_faces_the_check_never_reads_buys_no_points(tmp_path, mode):
    a = graded(REDTEAM2 / "believed_on_two_faces.cpp", tmp_path / "attack", mode, only=CHECKS_OF_FETCH)
    c = graded(REDTEAM2 / "swapped_on_y_control.cpp", tmp_path / "control", mode, only=CHECKS_OF_FETCH)
    assert by_name(c)["fetch_sweep"].status == FAILED
    assert by_name(a)["fetch_sweep"].status == FAILED
    assert a.score <= c.score


# ---- fetchColor that tells the recording apart ----------------------------------


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.parametrize("attack", DETECTORS)
def test_telling_the_recording_apart_buys_no_fetch_color_points(tmp_path, mode, attack):
    """Right only when recorded, v flipped otherwise: no more than the same
    mistake made plainly, on every check that judges the record, and the
    sweep names what it saw."""
    a = by_name(graded(RECORDING / f"{attack}.cpp", tmp_path / "a", mode))
    c = by_name(graded(REDTEAM2 / "v_flipped_control.cpp", tmp_path / "c", mode))
    for name in ON_THE_RECORD:
        assert a[name].score <= c[name].score + 1e-9, (name, a[name].score, c[name].score, a[name].output[:400])
    assert a["fetch_sweep"].fraction <= c["fetch_sweep"].fraction
    assert {d.id for d in a["fetch_sweep"].diagnoses} & {"asks-otherwise", "fetch-not-returned"}


@pytest.mark.slow
@pytest.mark.sandbox
def test_the_map_has_one_type_recorded_or_not(tmp_path, mode):
    """typeid(*this) is the same on every call, recorded or not: the code is
    judged on one behaviour, and the sweep (on the record) and the renders
    (end to end) agree."""
    a = by_name(graded(RECORDING / "typeid_detector.cpp", tmp_path, mode))
    assert a["fetch_sweep"].fraction == 1.0
    assert a["renders"].score == a["renders"].max_score
