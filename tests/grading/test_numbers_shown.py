"""The numbers shown are the numbers used, to the digit, in both languages
(issue 30, item 4): every check that earns part of its points prints the
share its points come from (and its prerequisite's credit, where one cuts
them), so that max x share (x credit), rounded to 0.01 as score.apply does,
is the points the report gives; and the Japanese report prints the same
numbers as the English one.

The submissions: one mistake on one face (the sweep, arrows, robustness and
renders share in it), three faces right (robustness and speed on a credit
from the sweep), and a readTexture wrong in part of each texel."""
from __future__ import annotations

import re

import pytest

from grader.grading.grade import GradeOptions
from grading_cache import grade_once
from project_paths import SUBMISSIONS

pytestmark = pytest.mark.slow      # six quick gradings

NAMES = ["wrong/u-flipped-pos-x.cpp", "offmodel/opengl-table_if-chain.cpp", "kit_redteam/nan_inf_denormal.cpp"]
PERCENT = re.compile(r"(\d+(?:\.\d+)?)%")


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    return {(name, lang): grade_once(SUBMISSIONS / name, tmp_path_factory.mktemp("shown"),
                                     GradeOptions(quick=True, lang=lang), write_reports=False)
            for name in NAMES for lang in ("en", "ja")}


def reproduced(check) -> bool:
    """Some printed share, times some printed share or 1, gives the points."""
    printed = [float(p) / 100 for p in PERCENT.findall(check.output)] + [1.0]
    for share in printed:
        for credit in printed:
            points = round(check.max_score * share * credit, 2)
            if points >= check.max_score and check.status == "failed":
                points = round(check.max_score - 0.01, 2)      # score.apply: a failed check never shows full points
            if abs(points - check.score) < 1e-9:
                return True
    return False


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("lang", ["en", "ja"])
def test_partial_points_come_from_the_shares_printed(graded, name, lang):
    assert not [c.name for c in graded[name, lang].checks if c.status == "error"]   # a harness error shows 0: no share
    partial = [c for c in graded[name, lang].checks if 0 < c.score < c.max_score]
    assert partial, name
    wrong = {c.name: (c.score, PERCENT.findall(c.output)) for c in partial if not reproduced(c)}
    assert not wrong, wrong


@pytest.mark.parametrize("name", NAMES)
def test_both_languages_print_the_same_numbers(graded, name):
    en, ja = graded[name, "en"], graded[name, "ja"]
    # speed's numbers are times, measured afresh in each grading (0.9 and 0.8 seen): its points only.
    assert [(c.name, c.score, PERCENT.findall(c.output) if c.name != "speed" else []) for c in en.checks] == \
           [(c.name, c.score, PERCENT.findall(c.output) if c.name != "speed" else []) for c in ja.checks]
