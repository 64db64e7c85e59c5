"""Issue 11's runtime attacks as whole gradings (tests/submissions/
runtime_attacks/*.cpp, each file's header says the attack and the verdict):
the grader finishes, writes its reports, gives less than full marks and
names the attack's diagnosis; nothing is "the grader failed".
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from grader.grading.grade import GradeOptions, grade
from grader.grading.results import UNGRADABLE
from fake_bwrap import write_failing_bwrap
from project_paths import SUBMISSIONS
from cases import cases

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]   # whole gradings / workers (tests/conftest.py's markers)

ZOO = SUBMISSIONS / "runtime_attacks"
EXPECTED = {
    "guard_mprotect": "forbidden-syscall",     # mprotect on the guard pages
    "forged_reply": "protocol",                # an ARGUMENT reply written by the submission
    "timed_black": "timing-faces-wrong",       # black on the timing faces only (timed or not)
    "timed_cache": "slow",                     # a cache of answers never hits fresh directions
    "clock_got": "forbidden-syscall",          # the worker's pages made writable at load
    "thread_bomb": "exception",                # idle threads until refused: std::thread throws while loading
}
CORRECT = SUBMISSIONS / "correct"


def test_every_attack_has_an_expectation():
    assert {p.stem for p in ZOO.glob("*.cpp")} == set(EXPECTED)


@pytest.mark.parametrize("name", cases(sorted(EXPECTED), representative={"forged_reply", "timed_black"}))
def test_an_attack_gets_its_verdict_and_the_report_is_intact(name, tmp_path):
    result = grade(ZOO / f"{name}.cpp", tmp_path, GradeOptions(quick=True, allow_stale=True))
    ids = {d.id for d in result.diagnoses}
    assert result.status != UNGRADABLE, result.warnings
    assert EXPECTED[name] in ids, (ids, [c.output[:300] for c in result.checks if c.status != "passed"])
    assert result.score < result.max_score
    if name == "timed_cache":
        # Its lookup is right: a cache of answers is slow here, not wrong (the
        # record's second run meets remembered answers; issue 29).
        wrong = {c.name for c in result.checks if c.status != "passed"}
        assert wrong == {"speed"}, (wrong, ids)
    saved = json.loads((tmp_path / "results.json").read_text())
    assert saved["score"] == result.score
    report = (tmp_path / "report.md").read_text()
    assert "Traceback" not in report and "grader itself failed" not in report


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="privilege-drop mode needs root")
def test_a_thread_bomb_graded_beside_a_classmate_leaves_the_classmate_full_marks(tmp_path):
    """Issue 18: in privilege-drop mode (a failing bwrap first on PATH, as on
    Gradescope) the bomb exhausted the container's pids and everyone graded
    beside it was ungradable. Both are graded at once, in two processes."""
    fake = write_failing_bwrap(tmp_path / "fakebin")
    env = {**os.environ, "PATH": f"{fake}:{os.environ['PATH']}"}
    runs = {name: subprocess.Popen([sys.executable, "-m", "grader", "grade", str(path), "--quick", "--allow-stale",
                                    "--out", str(tmp_path / name)], env=env, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True)
            for name, path in (("bomb", ZOO / "thread_bomb.cpp"), ("classmate", CORRECT / "idiomatic.cpp"))}
    printed = {name: run.communicate(timeout=600)[0] for name, run in runs.items()}
    results = {name: json.loads((tmp_path / name / "results.json").read_text()) for name in runs}
    for name in runs:
        assert "separate unprivileged user" in printed[name], printed[name]   # privilege-drop mode
    classmate = results["classmate"]
    assert classmate["score"] == sum(t["max_score"] for t in classmate["tests"]), printed["classmate"]
    assert results["bomb"]["score"] == 0, printed["bomb"]
    assert "uncaught C++ exception" in (tmp_path / "bomb" / "report.md").read_text()
