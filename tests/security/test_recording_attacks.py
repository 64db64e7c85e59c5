"""Red team on the recording (issue 29): a fetchColor that tries to tell
when its readTexture calls are being recorded, to behave only then.

tests/submissions/recording/*.cpp say on line 1 what they do and the secure
verdict. The grader records each direction twice (answered with its own tags,
and by the student's own readTexture) through one map class, and judges a
direction on the record only where both runs ask the same: any behaviour that
depends on who answers shows as different calls or an answer not returned.
Both isolation modes (test_redteam2's `mode` fixture).
"""
from __future__ import annotations

from pathlib import Path

import pytest

from grader.grading.grade import GradeOptions
from grader.grading.results import GRADED
from grading_cache import grade_once
from project_paths import SUBMISSIONS
from test_redteam2 import ISOLATION, REDTEAM2, by_name, mode  # noqa: F401 (mode: the fixture)

# Each grades whole submissions in both isolation modes.
pytestmark = [pytest.mark.slow, pytest.mark.sandbox]

RECORDING = SUBMISSIONS / "recording"
DETECTORS = ("tag_detector", "tag_shaped", "call_counter")
# Checks that judge fetchColor on the record (renders stay end to end: they
# show what the code does when it is not recorded).
ON_THE_RECORD = ("fetch_sweep", "diagnosis", "arrows", "stability")


def graded(path: Path, out: Path, mode: str):
    result = grade_once(path, out, GradeOptions(allow_stale=True, quick=True), write_reports=False)
    assert result.status == GRADED, result.status
    assert result.isolation == ISOLATION[mode]
    return by_name(result)


def test_every_recording_attack_has_a_test():
    assert {p.stem for p in RECORDING.glob("*.cpp")} == set(DETECTORS) | {"typeid_detector"}
    for p in RECORDING.glob("*.cpp"):
        first = p.read_text().splitlines()[0]
        assert first.startswith("// ") and "Verdict" in first


@pytest.mark.parametrize("attack", DETECTORS)
def test_telling_the_recording_apart_buys_no_fetch_color_points(tmp_path, mode, attack):
    """Right only when recorded, v flipped otherwise: no more than the same
    mistake made plainly, on every check that judges the record, and the
    sweep names what it saw."""
    a = graded(RECORDING / f"{attack}.cpp", tmp_path / "a", mode)
    c = graded(REDTEAM2 / "v_flipped_control.cpp", tmp_path / "c", mode)
    for name in ON_THE_RECORD:
        assert a[name].score <= c[name].score + 1e-9, (name, a[name].score, c[name].score, a[name].output[:400])
    assert a["fetch_sweep"].fraction <= c["fetch_sweep"].fraction
    assert {d.id for d in a["fetch_sweep"].diagnoses} & {"asks-otherwise", "fetch-not-returned"}


def test_the_map_has_one_type_recorded_or_not(tmp_path, mode):
    """typeid(*this) is the same on every call, recorded or not: the code is
    judged on one behaviour, and the sweep (on the record) and the renders
    (end to end) agree."""
    a = graded(RECORDING / "typeid_detector.cpp", tmp_path, mode)
    assert a["fetch_sweep"].fraction == 1.0
    assert a["renders"].score == a["renders"].max_score
