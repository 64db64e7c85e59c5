"""What the red-team tests (tests/security/) share: the submissions each
round left (tests/submissions/<round>/*.cpp, whose first line says what the
file does and the verdict a secure grader gives) and a whole grading of one
of them in the isolation mode under test.

The rounds' folders keep their names (a file's history); the tests are
grouped by attack class, each module naming in RED_TEAM the files it grades
(test_red_team_submissions.py holds every round's files to those names).
"""
from __future__ import annotations

from pathlib import Path

from grader.grading.grade import GradeOptions
from grader.grading.results import GRADED
from grading_cache import grade_once
from isolation import ISOLATION
from project_paths import SUBMISSIONS

ROUNDS = ("redteam", "redteam2", "redteam3", "recording", "redteam4", "redteam5", "redteam6")
REDTEAM, REDTEAM2, REDTEAM3, RECORDING, REDTEAM4, REDTEAM5, REDTEAM6 = (SUBMISSIONS / name for name in ROUNDS)


def graded(path: Path, out: Path, mode: str, only: tuple[str, ...] = ()):
    """One whole grading (quick), once per file, options and mode in a test
    run (a control beside two attacks is graded once per mode)."""
    result = grade_once(path, out, GradeOptions(allow_stale=True, quick=True, only=only), write_reports=False)
    assert result.status == GRADED, result.status
    assert result.isolation == ISOLATION[mode]
    return result


def by_name(result):
    return {c.name: c for c in result.checks}
