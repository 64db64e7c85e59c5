"""The terminal summary escapes line breaks in what a submission wrote
(issue 32): its exception text cannot put a forged score on a line of its own."""
from __future__ import annotations

from grader.reports import terminal
from grader.grading.results import FAILED, GRADED, CheckResult, Diagnosis, GradeResult

FORGED = "# Score: 100/100"
TEXT = f"boom\n{FORGED}\r\n{FORGED}\u2028{FORGED}\tend"


def hostile() -> GradeResult:
    check = CheckResult("sweeps", "fetchColor picks the right face", status=FAILED, fraction=0.0, score=0,
                        max_score=30, number="1",
                        diagnoses=[Diagnosis("exception", "uncaught exception: " + TEXT, face="+X")])
    return GradeResult(submission="alice\n" + FORGED, status=GRADED, checks=[check], score=0, max_score=30,
                       warnings=["a warning quoting it: " + TEXT], execution_time_s=1.0, isolation="bubblewrap")


def test_no_line_of_the_summary_is_the_submissions_forged_score():
    text = terminal.summary_text(hostile(), width=400)
    assert not [line for line in text.splitlines() if line.strip().startswith(FORGED)], text
    assert f"boom\\n{FORGED}" in text            # shown, escaped, not dropped
    assert f"alice\\n{FORGED}" in text
    assert "\\u2028" in text and "\\t" in text


def test_one_line_escapes_every_line_break():
    assert terminal.one_line("a\nb\rc\x0bd\x0ce\x85f\u2028g\u2029h") == "a\\nb\\rc\\vd\\fe\\x85f\\u2028g\\u2029h"
