"""Issue 11's runtime attacks as whole gradings (tests/submissions/
runtime_attacks/*.cpp, each file's header says the attack and the verdict):
the grader finishes, writes its reports, gives less than full marks and
names the attack's diagnosis; nothing is "the grader failed".
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from grader.grade import GradeOptions, grade
from grader.results import UNGRADABLE

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]   # whole gradings / workers (tests/conftest.py's markers)

ZOO = Path(__file__).parent / "submissions" / "runtime_attacks"
EXPECTED = {
    "guard_mprotect": "forbidden-syscall",     # mprotect on the guard pages
    "forged_reply": "protocol",                # an ARGUMENT reply written by the submission
    "timed_black": "timing-faces-wrong",       # black on the timing faces only (timed or not)
    "timed_cache": "slow",                     # a cache of answers never hits fresh directions
    "clock_got": "forbidden-syscall",          # the worker's pages made writable at load
}


def test_every_attack_has_an_expectation():
    assert {p.stem for p in ZOO.glob("*.cpp")} == set(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_an_attack_gets_its_verdict_and_the_report_is_intact(name, tmp_path):
    result = grade(ZOO / f"{name}.cpp", tmp_path, GradeOptions(quick=True, allow_stale=True))
    ids = {d.id for d in result.diagnoses}
    assert result.status != UNGRADABLE, result.warnings
    assert EXPECTED[name] in ids, (ids, [c.output[:300] for c in result.checks if c.status != "passed"])
    assert result.score < result.max_score
    saved = json.loads((tmp_path / "results.json").read_text())
    assert saved["score"] == result.score
    report = (tmp_path / "report.md").read_text()
    assert "Traceback" not in report and "grader itself failed" not in report
