"""The words a student meets on a report (issue 19, item 9): a one-mistake
report, and a correct one, stay under 300 visible words in report.md,
report.html, Gradescope's and PrairieLearn's outputs; instrument terms stay
out of sight (explained in the details' glossary); a mistake has one count,
the same in the summary and in the check that judges it.

"Visible words" are defined in tests/helpers/report_words.py (details collapsed,
code, numbers and table markup not counted). The submissions are zoo files
whose first line states their one mistake, graded as a student's would be.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from grader.grading.grade import GradeOptions
from grading_cache import grade_once
from grader.platforms.prairielearn import results_from
from grader.reports import render_all
from grader.reports.view import GLOSSARY
from report_words import gradescope_words, html_words, markdown_words, prairielearn_words
from project_paths import SUBMISSIONS

HERE = SUBMISSIONS
ONE_MISTAKE = {   # file: the one diagnosis its first line states
    "wrong/u-flipped-pos-x.cpp": "u-flipped",
    "wrong/wrong-face-x-swapped.cpp": "wrong-face",
    "wrong/nearest-neighbor.cpp": "nearest-neighbor",
}
CORRECT = "correct/idiomatic.cpp"
LIMIT = 300
# Names of the grader's instruments and harness: not for a student's first read.
JARGON = ("SSIM", "FLIP", "ulp", "Fibonacci", "bubblewrap", "sandbox", "protocol", "Pareto")


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    out = {}
    for name in [*ONE_MISTAKE, CORRECT, "compound/strict-ties_weights-swapped.cpp"]:
        result = grade_once(HERE / name, tmp_path_factory.mktemp("words"), GradeOptions(quick=True),
                       write_reports=False)
        out[name] = (result, render_all(result))
    return out


def visible(result, texts) -> dict[str, list[str]]:
    return {"report.md": markdown_words(texts["report.md"]),
            "report.html": html_words(texts["report.html"]),
            "gradescope": gradescope_words(json.loads(texts["results.json"])),
            "prairielearn": prairielearn_words(results_from(result))}


# ---- the counter itself --------------------------------------------------------

def test_the_counter_counts_what_is_shown_and_nothing_else():
    md = ("# Two words\n\n| | # | Check | Points |\n|:-:|:--|:--|--:|\n| ✅ | 1 | `code` here | 5 / 5 |\n\n"
          "<details><summary>Shown summary</summary>\n\nhidden words are many here\n\n</details>\n\n"
          "```text\nfenced code is not words\n```\n")
    assert markdown_words(md) == ["Two", "words", "Check", "Points", "here", "Shown", "summary"]
    page = ("<html><head><title>no</title><style>p{}</style></head><body><h1>One</h1>"
            "<details><summary>Sum <span>mary</span></summary><p>hidden</p></details>"
            "<details open><summary>open</summary><p>shown <code>x = 1</code></p></details>"
            "<p>12.5 / 100 · ok</p></body></html>")
    assert html_words(page) == ["One", "Sum", "mary", "open", "shown", "ok"]


# ---- under 300 words ----------------------------------------------------------------

@pytest.mark.parametrize("name", [*ONE_MISTAKE, CORRECT])
def test_a_one_mistake_or_correct_report_is_under_300_visible_words(graded, name):
    result, texts = graded[name]
    counts = {where: len(w) for where, w in visible(result, texts).items()}
    print(name, counts)
    assert all(n < LIMIT for n in counts.values()), counts
    if name in ONE_MISTAKE:
        assert {d.id for d in result.diagnoses} == {ONE_MISTAKE[name]}    # it is a one-mistake report


@pytest.mark.parametrize("name", [*ONE_MISTAKE, CORRECT])
def test_instrument_and_harness_terms_stay_in_the_details(graded, name):
    result, texts = graded[name]
    for where, words in visible(result, texts).items():
        seen = {t.strip(".,:;()") for t in words} & set(JARGON)
        assert not seen, (where, seen)
    # Where the details use them, the glossary explains them.
    md = texts["report.md"]
    for term in ("SSIM", "FLIP", "ulp", "Fibonacci sphere"):
        if term in md:
            assert any(line.startswith(term + ":") for line in GLOSSARY.values()), term
            assert any(f"- {line}" in md.replace("\\", "") for line in GLOSSARY.values() if line.startswith(term))


# ---- one count per mistake ------------------------------------------------------------

def _summary_count(md: str, unit: str) -> tuple[int, int]:
    fix = md.split("## What to fix first", 1)[1].split("## Checks", 1)[0]
    fix = re.sub(r"<details>.*?</details>", "", fix, flags=re.S)      # what a student sees of it
    found = re.findall(rf"(\d+) of (\d+) {unit} give the wrong colour", fix)
    assert len(found) == 1, fix
    return tuple(map(int, found[0]))


@pytest.mark.parametrize("name, check", [
    ("wrong/u-flipped-pos-x.cpp", "fetch_sweep"),
    ("wrong/wrong-face-x-swapped.cpp", "fetch_sweep"),
    ("wrong/nearest-neighbor.cpp", "read_texture"),
    ("compound/strict-ties_weights-swapped.cpp", "fetch_sweep"),
])
def test_a_mistake_has_one_count_in_every_place(graded, name, check):
    result, texts = graded[name]
    unit = "directions" if check == "fetch_sweep" else "readTexture calls"
    wrong, total = _summary_count(texts["report.md"], unit)
    judged = next(c for c in result.checks if c.name == check)
    # The judging check's own first line gives the same numbers.
    assert judged.output.startswith(f"{wrong} of {total} "), judged.output[:200]
    # No other "k of n directions/calls" anywhere in the report counts it differently.
    others = {m for m in re.findall(rf"(\d+) of (\d+) (?:{unit})", texts["report.md"])}
    assert others == {(str(wrong), str(total))}, others
    # The same sentence heads the mistake in report.html and in Gradescope's summary.
    sentence = f"{wrong} of {total} "
    shown = re.sub(r"<details.*?</details>", "", texts["report.html"].split("What to fix first", 1)[1], flags=re.S)
    assert sentence in shown.split("<h2>", 1)[0]
    assert sentence in json.loads(texts["results.json"])["output"]


def test_the_renamed_id_says_what_is_missing():
    from grader.grading import catalogue
    info = catalogue.describe("not-divided-by-m")
    assert "divide by m" in info.title
    assert catalogue.describe("not-normalized") is info          # the kit's old id still reads
