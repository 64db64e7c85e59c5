"""PrairieLearn's external grader, in a local copy of its /grade layout:
serverFilesCourse/ holds the project (a symlink here), student/ the
student's file, results/results.json is what PrairieLearn shows.
"""
from __future__ import annotations

import base64
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from grader import PROJECT_ROOT

SUBMISSIONS = PROJECT_ROOT / "tests" / "submissions"


@pytest.fixture
def grade_root(tmp_path) -> Path:
    root = tmp_path / "grade"
    for folder in ("student", "tests", "serverFilesCourse"):
        (root / folder).mkdir(parents=True)
    (root / "serverFilesCourse" / "envmap").symlink_to(PROJECT_ROOT)
    return root


def results(root: Path) -> dict:
    data = json.loads((root / "results" / "results.json").read_text())
    assert set(data) == {"gradable", "score", "message", "output", "tests", "images"}
    for test in data["tests"]:
        assert {"name", "points", "max_points", "output"} <= set(test)
        assert 0 <= test["points"] <= test["max_points"]
    for image in data["images"]:
        assert image["label"] and image["url"].startswith("data:image/png;base64,")
        assert base64.b64decode(image["url"].split(",", 1)[1])[:8] == b"\x89PNG\r\n\x1a\n"
    return data


@pytest.mark.slow
def test_entrypoint_grades_a_correct_submission(grade_root):
    (grade_root / "student" / "EnvironmentMap.cpp").write_bytes((SUBMISSIONS / "correct" / "if_chain.cpp").read_bytes())
    entry = grade_root / "serverFilesCourse" / "envmap" / "grader" / "platforms" / "prairielearn" / "entrypoint.sh"
    run = subprocess.run([str(entry)], capture_output=True, text=True, timeout=300,
                         env={**os.environ, "PL_GRADE_ROOT": str(grade_root)})
    assert run.returncode == 0, run.stdout + run.stderr
    data = results(grade_root)
    assert data["gradable"] is True and data["score"] == 1.0, data["message"]
    assert data["tests"] and all(t["points"] == t["max_points"] for t in data["tests"])
    labels = [i["label"] for i in data["images"]]
    assert "Your render" in labels and "Reference render" in labels


@pytest.mark.slow
def test_a_wrong_submission_gets_partial_credit_and_its_diagnosis(grade_root):
    (grade_root / "student" / "EnvironmentMap.cpp").write_bytes(
        (SUBMISSIONS / "wrong" / "v-flipped-pos-z.cpp").read_bytes())
    run = subprocess.run([sys.executable, "-m", "grader", "prairielearn", "--root", str(grade_root), "--quick"],
                         cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    data = results(grade_root)
    assert data["gradable"] is True and 0 < data["score"] < 1
    assert "v-flipped" in data["output"]
    assert any(t["points"] < t["max_points"] for t in data["tests"])
    assert "Traceback" not in json.dumps(data)


def test_the_graders_own_failure_is_not_gradable_and_shows_no_traceback(grade_root, monkeypatch, capsys):
    import grader.grade
    from grader.platforms.prairielearn import grade_prairielearn

    def broken(*args, **kwargs):
        raise RuntimeError("fixtures unreadable\n  File \"/secret/path.py\", line 1")
    monkeypatch.setattr(grader.grade, "grade", broken)
    (grade_root / "student" / "EnvironmentMap.cpp").write_text("// anything\n")
    data = grade_prairielearn(grade_root)
    assert data == results(grade_root)
    assert data["gradable"] is False and data["score"] == 0
    assert "not your fault" in data["message"] and "RuntimeError: fixtures unreadable" in data["message"]
    assert "/secret/path.py" not in json.dumps(data)
    assert "Traceback" in capsys.readouterr().err     # the instructor's copy, in PrairieLearn's job log


def test_no_student_folder_is_not_gradable(tmp_path):
    from grader.platforms.prairielearn import grade_prairielearn
    data = grade_prairielearn(tmp_path)
    assert data["gradable"] is False and "student is missing" in data["message"]
    assert json.loads((tmp_path / "results" / "results.json").read_text()) == data
