"""Attacks on the score (the first red-team round, tests/submissions/redteam/):
- black_on_axes: wrong on 6 of ~127,000 sweep directions scored 30 / 30 on
  a *failed* check (rounding to 0.01 point). Now a failed check never shows
  full points (grader/grading/score.py).
"""
from __future__ import annotations

import json

import pytest

from grader.grading.grade import GradeOptions, grade
from grader.grading.results import FAILED, PASSED, CheckResult, GradeResult
from red_team import REDTEAM

RED_TEAM = {"redteam": {"black_on_axes"}}


def test_a_failed_check_never_rounds_up_to_full_points():
    from grader.grading import score
    rubric = {"checks": {"sweep": {"points": 30, "partial": "fraction"}, "speed": {"points": 5, "partial": "all"},
                         "ok": {"points": 10, "partial": "fraction"}}}
    result = GradeResult("x", checks=[CheckResult("sweep", "S", FAILED, fraction=1 - 6 / 126_662),
                                      CheckResult("speed", "T", FAILED, fraction=1.0),
                                      CheckResult("ok", "O", PASSED, fraction=1.0)])
    score.apply(result, rubric)
    assert [c.score for c in result.checks] == [29.99, 0.0, 10.0]
    assert result.score < result.max_score


@pytest.mark.slow
@pytest.mark.sandbox
def test_black_on_the_axes_is_not_full_marks(tmp_path):
    result = grade(REDTEAM / "black_on_axes.cpp", tmp_path, GradeOptions(allow_stale=True, only=("fetch_sweep",)))
    (sweep,) = result.checks
    assert sweep.status == FAILED and sweep.score < sweep.max_score == 30
    assert "axes" in sweep.output and result.score < result.max_score
    assert json.loads((tmp_path / "results.json").read_text())["score"] < 30
