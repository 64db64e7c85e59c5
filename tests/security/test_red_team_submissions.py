"""Every file the red-team rounds left (tests/submissions/<round>/*.cpp) is
graded by a test of its attack class, and says on line 1 what it does and
the verdict a secure grader gives. The modules name their files in RED_TEAM."""
from __future__ import annotations

import pytest

import test_build_attacks
import test_observation_attacks
import test_redteam4
import test_redteam5
import test_report_injection_e2e
import test_scoring_attacks
import test_spare_attacks
import test_speed_attacks
import test_worker_lifetime_attacks
from red_team import ROUNDS
from project_paths import SUBMISSIONS

CLASSES = (test_build_attacks, test_observation_attacks, test_redteam4, test_redteam5, test_report_injection_e2e,
           test_scoring_attacks, test_spare_attacks, test_speed_attacks, test_worker_lifetime_attacks)


@pytest.mark.parametrize("round_name", ROUNDS)
def test_every_red_team_submission_has_a_test(round_name):
    folder = SUBMISSIONS / round_name
    named = set().union(*(m.RED_TEAM.get(round_name, set()) for m in CLASSES))
    assert {p.stem for p in folder.glob("*.cpp")} == named
    for p in folder.glob("*.cpp"):
        first = p.read_text().splitlines()[0]
        assert first.startswith("// ") and "Verdict" in first, p.name
