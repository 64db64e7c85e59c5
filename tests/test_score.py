"""The rubric turns check outcomes into points; mistakes in it are reported."""
import pytest

from grader import score
from grader.results import ERROR, FAILED, GRADED, PASSED, UNGRADABLE, CheckResult, GradeResult

RUBRIC = {"checks": {
    "a": {"points": 10, "partial": "fraction", "visibility": "visible", "tags": ["x"]},
    "b": {"points": 5, "partial": "all", "visibility": "hidden"},
}}


def graded(*checks):
    return score.apply(GradeResult("s", checks=list(checks)), RUBRIC)


def test_fraction_gives_partial_credit_and_all_gives_none():
    r = graded(CheckResult("a", "A", FAILED, fraction=0.75), CheckResult("b", "B", FAILED, fraction=0.99))
    assert [c.score for c in r.checks] == [7.5, 0.0]
    assert r.score == 7.5 and r.max_score == 15.0
    assert r.checks[1].visibility == "hidden" and r.checks[0].tags == ["x"]


def test_full_marks_when_everything_passes():
    r = graded(CheckResult("a", "A", PASSED, 1.0), CheckResult("b", "B", PASSED, 1.0))
    assert r.score == r.max_score == 15.0 and r.status == GRADED


def test_a_harness_error_makes_the_submission_ungradable_not_zero():
    r = graded(CheckResult("a", "A", ERROR, 0.0), CheckResult("b", "B", PASSED, 1.0))
    assert r.status == UNGRADABLE


def test_the_shipped_rubric_loads_and_names_every_check():
    from grader.checks import all_checks
    rubric = score.load_rubric()
    assert {c.name for c in all_checks()} == set(rubric["checks"])
    assert sum(e["points"] for e in rubric["checks"].values()) == 100


@pytest.mark.parametrize("entry, message", [
    ({"points": -1}, "points"),
    ({"points": 1, "partial": "some"}, "partial"),
    ({"points": 1, "visibility": "secret"}, "visibility"),
])
def test_rubric_mistakes_are_reported(tmp_path, entry, message):
    path = tmp_path / "rubric.toml"
    body = "\n".join(f"{k} = {v!r}".replace("'", '"') for k, v in entry.items())
    path.write_text(f"[checks.a]\n{body}\n")
    with pytest.raises(score.RubricError, match=message):
        score.load_rubric(path)
