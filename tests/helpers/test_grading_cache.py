"""tests/helpers/grading_cache.py: a grading is done once per key, each caller gets
its own copy of the real result and reports, and what changes a grading
(bytes, name, options, language, isolation mode) changes the key."""
from __future__ import annotations

import os
import shutil
from pathlib import Path

import grading_cache
import session_once
from fake_bwrap import write_failing_bwrap
from grader.grading.grade import GradeOptions, grade
from grader.grading.results import BUILD_ERROR
from grader.worker import sandbox
from grading_cache import grade_once, grading_key
from project_paths import SUBMISSIONS

# A build error: a real grading in a fraction of a second.
BROKEN = SUBMISSIONS / "wrong" / "syntax-error.cpp"
QUICK = GradeOptions(quick=True)


def test_one_grading_per_key_and_a_copy_for_each_caller(tmp_path, monkeypatch):
    calls = []
    monkeypatch.setattr(grading_cache, "grade", lambda *a, **k: calls.append(a) or grade(*a, **k))
    monkeypatch.setattr(session_once, "FOLDER", tmp_path / "cache")
    first = grade_once(BROKEN, tmp_path / "a", QUICK)
    first.checks[0].score = 99.0                    # a test changing what it got changes nobody else's
    second = grade_once(BROKEN, tmp_path / "b", QUICK, write_reports=False)
    assert len(calls) == 1
    assert second.status == BUILD_ERROR and second.checks[0].score == 0.0
    direct = grade(BROKEN, tmp_path / "direct", QUICK)             # what grading it again gives
    assert (second.status, second.score, second.checks) == (direct.status, direct.score, direct.checks)
    for name in ("results.json", "report.md", "report.html", "junit.xml"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "cache" / f"grading-{grading_key(BROKEN, QUICK)}"
                                                        / "out" / name).read_bytes()
    assert not (tmp_path / "b" / "results.json").exists()     # write_reports=False writes none


def test_what_changes_a_grading_changes_the_key(tmp_path, monkeypatch):
    key = grading_key(BROKEN, QUICK)
    same = tmp_path / "elsewhere" / BROKEN.name
    same.parent.mkdir()
    shutil.copyfile(BROKEN, same)
    assert grading_key(same, QUICK) == key                       # the bytes and name, not the folder
    assert grading_key(same, GradeOptions(quick=True, lang="en")) == key   # the rubric's language anyway
    renamed = tmp_path / "other.cpp"
    shutil.copyfile(BROKEN, renamed)
    assert grading_key(renamed, QUICK) != key                    # the name is in the report
    same.write_text(same.read_text() + "\n")
    assert grading_key(same, QUICK) != key
    assert grading_key(BROKEN, GradeOptions(quick=True, lang="ja")) != key
    assert grading_key(BROKEN, GradeOptions()) != key
    assert grading_key(BROKEN, GradeOptions(quick=True, only=("speed",))) != key
    monkeypatch.setenv("GRADER_SECRET", "another course")
    assert grading_key(BROKEN, QUICK) != key
    monkeypatch.delenv("GRADER_SECRET")
    fake = write_failing_bwrap(tmp_path / "fakebin")
    monkeypatch.setenv("PATH", f"{fake}:{os.environ.get('PATH', '/usr/bin:/bin')}")
    sandbox.sandbox_problem.cache_clear()
    try:
        assert grading_key(BROKEN, QUICK) != key                 # privilege-drop mode, not bubblewrap
    finally:
        sandbox.sandbox_problem.cache_clear()
