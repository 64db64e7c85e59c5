"""No cliffs (issue 30): a 0.1% change in what fetchColor gets right never
moves the score by more than a point.

The submission is in-process (tests/fake_lookups.py): the handout's lookup,
except that fetchColor returns black inside a cap around +z whose size sets
the share of the sphere that is right. Pairs of caps 0.1% of the sphere
apart are graded on the checks that hang on the sweep (fetch_sweep, and
stability and speed, which earn a share of their points from it); speed's
own verdict is taken as passed (its timing is not what is tested here), its
credit is the runner's, as for stability.

    PYTHONPATH=tests/helpers:. .venv/bin/python tests/unit/grading/test_score_steps.py
prints the largest step found over a finer scan (the figure in issue 30's
note); it runs on any version of the grader that has these checks."""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

from cases import cases
from fake_lookups import FakeLookups
from grader.grading import score
from grader.checks import all_checks, run_checks
from grader.checks.context import CheckContext
from grader.grading.results import PASSED, CheckResult, GradeResult

# Two sweeps a case, in-process (3 s): slow; two cases stand for them in `make test`.
pytestmark = [pytest.mark.slow]

STEP = 0.001            # 0.1% of the sphere
POINT = 1.0             # the most a step may move the score


class CapLookups(FakeLookups):
    """Right everywhere but inside the cap z > cos(angle) of unit directions,
    where fetchColor returns black: a share (1 + c) / 2 of the sphere right."""

    def __init__(self, right: float):
        super().__init__()
        self.c = 2.0 * right - 1.0

    def fetch(self, dirs, placement="end"):
        out = super().fetch(dirs, placement)
        dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            z = dirs[:, 2] / np.linalg.norm(dirs, axis=1)
        out.values[np.nan_to_num(z, nan=-2.0) > self.c] = 0.0
        return out


def points(right: float, folder: Path) -> float:
    """fetch_sweep + stability + speed (its own verdict passed) for CapLookups(right)."""
    checks = all_checks()
    order = [checks[n] for n in ("read_texture", "fetch_sweep", "stability", "speed")]
    ctx = CheckContext(lookups=CapLookups(right), seed=1234, artifacts=folder, quick=True)
    ran = {r.name: r for r in run_checks(order[:3], ctx).results}
    speed = CheckResult("speed", "speed", status=PASSED)
    try:   # speed's share of its points after the sweep, as the runner gives it
        from grader.checks import _apply_credit, Ran
        _apply_credit(checks["speed"], speed, {"fetch_sweep": Ran(ran["fetch_sweep"], _sweep_finding(ran["fetch_sweep"]), True)})
    except ImportError:   # a grader with a threshold instead (before issue 30): speed runs at >= 50%
        if ran["fetch_sweep"].fraction < 0.5:
            speed.status, speed.fraction = "skipped", 0.0
    result = score.apply(GradeResult("cap", checks=[ran["fetch_sweep"], ran["stability"], speed]), score.load_rubric())
    return result.score


def _sweep_finding(sweep: CheckResult):
    from grader.checks.fetch_sweep import SweepFinding
    return SweepFinding(fraction=sweep.fraction)


def largest_step(shares, folder: Path) -> tuple[float, float, float]:
    """(the largest score change, at which share, its sweep share) over pairs STEP apart."""
    worst = (0.0, 0.0, 0.0)
    for s in shares:
        a, b = points(s, folder), points(s + STEP, folder)
        if abs(b - a) > worst[0]:
            worst = (abs(b - a), s, a)
    return worst


# Where the credit bends (30%, 60%), the old threshold (50%), between, and
# the shares of one, two and three faces wrong.
SHARES = (0.25, 0.2995, 0.35, 0.4995, 0.5, 0.55, 0.5995, 0.6, 2 / 3, 5 / 6)


@pytest.mark.parametrize("right", cases(SHARES, representative={"0.4995", "0.5995"}))
def test_a_tenth_of_a_percent_moves_the_score_by_a_point_at_most(right, tmp_path):
    a, b = points(right, tmp_path), points(right + STEP, tmp_path)
    assert abs(b - a) <= POINT, (right, a, b)
    assert b >= a - 0.01, (right, a, b)    # more right never scores less


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as folder:
        fine = np.round(np.arange(0.20, 0.90, 0.01), 4)
        step, at, score_at = largest_step(fine, Path(folder))
        print(f"largest change for {STEP:.1%} of the sphere: {step:.2f} points, from {at:.1%} right ({score_at:.2f} points)",
              file=sys.stdout)
