"""How one mistake is charged (issue 30), written once in grader/grading/rubric.toml's
comments and copied, with why, into docs/scoring.md: the table holds for
what the grader charges on the zoo's single-mistake submissions
(tests/submissions/wrong/, graded as tests/grading/test_grading_zoo.py grades them:
the same gradings, once a session)."""
from __future__ import annotations

import re

import pytest

from grader.grading import score
from grader.grading.grade import GradeOptions
from grading_cache import grade_once
from project_paths import PROJECT_ROOT, SUBMISSIONS

WRONG = SUBMISSIONS / "wrong"
# Not one mistake: three at once (the compound zoo's business).
SEVERAL = {"combo-swapped-and-flipped"}


def rubric_table() -> dict[str, set[str]]:
    """The rubric comment's table: mistake -> the checks it costs."""
    lines = score.RUBRIC.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if re.match(r"#\s+mistake\s+checks it costs", line))
    table = {}
    for line in lines[start + 1:]:
        row = re.match(r"#\s+([a-z0-9-]+)\s+([a-z_ ]+)$", line)
        if not row:
            break
        table[row.group(1)] = set(row.group(2).split())
    return table


def docs_table() -> dict[str, set[str]]:
    text = (PROJECT_ROOT / "docs" / "scoring.md").read_text()
    return {m.group(1): {c.strip() for c in m.group(2).split(",")}
            for m in re.finditer(r"^\| `([a-z0-9-]+)` \| ([a-z_, ]+) \|", text, re.M)}


def test_the_table_is_written_once_and_copied_faithfully():
    table = rubric_table()
    assert table == docs_table()
    scored = {name for name, entry in score.load_rubric()["checks"].items() if entry["points"] > 0}
    assert all(costs <= scored for costs in table.values()), table
    assert set(table) == {p.stem for p in WRONG.glob("*.cpp")} - SEVERAL


@pytest.mark.parametrize("name", sorted(rubric_table()))
def test_a_mistake_costs_what_the_table_says(name, tmp_path):
    result = grade_once(WRONG / f"{name}.cpp", tmp_path, GradeOptions(quick=True))
    costs = {c.name for c in result.checks if c.score < c.max_score}
    assert costs == rubric_table()[name], {c.name: c.score for c in result.checks}
