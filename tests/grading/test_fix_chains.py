"""Monotone (issue 30): fixing a mistake never lowers the score.

Each compound submission (tests/submissions/compound/) has its mistakes
fixed one at a time, in every order: its sidecar's `fixes` say how, as text
replaced in the file (written from the code, like the rest of its truth; a
fix may say how it reads once another is made, `if_fixed`). Every subset of
the fixes is one submission, graded once (quick, tests/grading_cache.py);
every order of fixing is a path up the lattice of subsets, so each step of
one fix, from every subset, must not lower the total."""
from __future__ import annotations

import itertools
import json

import pytest

from grader.grading.grade import GradeOptions
from grading_cache import grade_once
from project_paths import SUBMISSIONS

ZOO = SUBMISSIONS / "compound"
NAMES = sorted(p.stem for p in ZOO.glob("*.cpp"))


def fixes(name: str) -> list[dict]:
    return json.loads((ZOO / f"{name}.json").read_text())["fixes"]


def fixed(name: str, made: frozenset[str]) -> str:
    """The source with the fixes named in `made` made (in the sidecar's order)."""
    text = (ZOO / f"{name}.cpp").read_text()
    done = set()
    for fix in fixes(name):
        if fix["fixes"] in made:
            replace = next((r for other, r in fix.get("if_fixed", {}).items() if other in done), fix["replace"])
            for old, new in replace:
                assert old in text, (name, fix["fixes"], old)
                text = text.replace(old, new)
            done.add(fix["fixes"])
    return text


def test_every_compound_submission_says_how_to_fix_each_mistake():
    for name in NAMES:
        made = [f["fixes"] for f in fixes(name)]
        assert made and len(set(made)) == len(made), name
        every = frozenset(made)
        assert fixed(name, every) != fixed(name, frozenset()), name
        # Each fix changes the source whatever else is fixed.
        for fix in made:
            for k in range(len(made)):
                for others in itertools.combinations([m for m in made if m != fix], k):
                    assert fixed(name, frozenset(others) | {fix}) != fixed(name, frozenset(others)), (name, fix, others)


@pytest.mark.parametrize("name", NAMES)
def test_fixing_a_mistake_never_lowers_the_score(name, tmp_path):
    made = [f["fixes"] for f in fixes(name)]
    subsets = [frozenset(c) for k in range(len(made) + 1) for c in itertools.combinations(made, k)]
    total = {}
    for i, subset in enumerate(subsets):
        folder = tmp_path / f"fixed{i}"
        folder.mkdir()
        source = folder / "EnvironmentMap.cpp"
        source.write_text(fixed(name, subset))
        total[subset] = grade_once(source, folder / "out", GradeOptions(quick=True)).score
    lower = {(tuple(sorted(s)), fix): (total[s], total[s | {fix}])
             for s in subsets for fix in made if fix not in s and total[s | {fix}] < total[s] - 0.01}
    assert not lower, lower
    assert total[frozenset(made)] > total[frozenset()], total
