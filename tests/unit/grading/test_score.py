"""The rubric turns check outcomes into points; mistakes in it are reported."""
import pytest

from grader.grading import score
from grader.grading.results import ERROR, FAILED, GRADED, PASSED, UNGRADABLE, CheckResult, GradeResult

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
    assert set(all_checks()) == set(rubric["checks"])
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
        score.load_rubric(path, checks={"a": FakeCheck()})


class FakeCheck:
    prerequisites: tuple[str, ...] = ()


def _shipped_with(tmp_path, edit):
    """The shipped rubric, its [checks.*] tables edited by `edit(list of (name, body))`."""
    text = score.RUBRIC.read_text()
    head, *tables = text.split("\n[checks.")
    tables = [("[checks." + t).split("]", 1) for t in tables]
    tables = [(name[len("[checks."):], "]" + body) for name, body in tables]
    tables = edit(tables)
    path = tmp_path / "rubric.toml"
    path.write_text(head + "".join(f"\n[checks.{name}{body}" for name, body in tables))
    return path


def test_a_misspelt_check_name_is_refused_naming_it(tmp_path):
    path = _shipped_with(tmp_path, lambda t: [("fetch_swep" if n == "fetch_sweep" else n, b) for n, b in t])
    with pytest.raises(score.RubricError, match=r"checks\.fetch_swep is not a check"):
        score.load_rubric(path)


def test_a_check_left_out_of_the_rubric_is_refused(tmp_path):
    path = _shipped_with(tmp_path, lambda t: [(n, b) for n, b in t if n != "stability"])
    with pytest.raises(score.RubricError, match=r"no entry for checks\.stability"):
        score.load_rubric(path)


def test_a_check_listed_before_what_it_requires_is_refused(tmp_path):
    # speed requires fetch_sweep's finding: listed first, it would run without it.
    path = _shipped_with(tmp_path, lambda t: [x for x in t if x[0] == "speed"] + [x for x in t if x[0] != "speed"])
    with pytest.raises(score.RubricError, match=r"checks\.speed requires checks\.fetch_sweep, which is listed after it"):
        score.load_rubric(path)


def test_the_rubric_order_is_the_run_order(tmp_path):
    from grader.checks import ordered_checks
    path = _shipped_with(tmp_path, lambda t: [x for x in t if x[0] == "arrows"] + [x for x in t if x[0] != "arrows"])
    rubric = score.load_rubric(path)
    assert [c.name for c in ordered_checks(rubric)][:2] == ["arrows", "read_texture"]
