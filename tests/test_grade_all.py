"""`python -m grader grade-all` on a class made here: folders, a .zip, a
.tar.gz, a loose .cpp, a build error and a crash; the gradebook, the class
summary, and an interrupted run resumed.

The interrupted run is killed (SIGKILL, to its whole process group) as soon
as the first student's results appear: nothing gets to clean up, as when a
machine goes down. The re-run must keep what was finished (its files not
rewritten), grade the rest, and a third run must grade nothing.
"""
from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import tarfile
import time
import zipfile
from pathlib import Path

import jsonschema
import pytest

from grader import PROJECT_ROOT
from grader.grade_all import RECORD_FILE, Row, find_submissions, write_gradebook
from grader.reports.gradescope_json import load_schema

SUBMISSIONS = PROJECT_ROOT / "tests" / "submissions"
# student -> (what they hand in, expected status, a diagnosis id expected or None)
CLASS = {
    "alice": ("folder", SUBMISSIONS / "correct" / "if_chain.cpp", "graded", None),
    "bob": ("zip", SUBMISSIONS / "correct" / "axis_table.cpp", "graded", None),
    "carol": ("tar.gz", SUBMISSIONS / "wrong" / "v-flipped-pos-z.cpp", "graded", "v-flipped"),
    "dave": ("cpp", SUBMISSIONS / "build" / "syntax_error.cpp", "build-error", "build-error"),
    "erin": ("folder", SUBMISSIONS / "wrong" / "crash-null.cpp", "graded", "crash"),
    # Hostile: writes a fake results.json from inside fetchColor; prints a fake
    # score and megabytes (which makes it slow, and nothing else).
    "frank": ("folder", SUBMISSIONS / "hostile" / "write_results.cpp", "graded", "forbidden-syscall"),
    "grace": ("folder", SUBMISSIONS / "hostile" / "fake_score.cpp", "graded", "slow"),
}


def make_class(folder: Path) -> Path:
    folder.mkdir(parents=True)
    for student, (kind, source, _, _) in CLASS.items():
        text = source.read_bytes()
        if kind == "folder":
            (folder / student).mkdir()
            (folder / student / "EnvironmentMap.cpp").write_bytes(text)
        elif kind == "cpp":
            (folder / f"{student}.cpp").write_bytes(text)
        elif kind == "zip":
            with zipfile.ZipFile(folder / f"{student}.zip", "w") as z:
                z.writestr("handin/EnvironmentMap.cpp", text)
        else:
            staged = folder.parent / f"{student}-staging" / "EnvironmentMap.cpp"
            staged.parent.mkdir()
            staged.write_bytes(text)
            with tarfile.open(folder / f"{student}.tar.gz", "w:gz") as t:
                t.add(staged, arcname="EnvironmentMap.cpp")
    (folder / ".DS_Store").write_text("not a student")
    (folder / "notes.txt").write_text("not a submission either")
    return folder


def grade_all_cmd(class_dir: Path, out: Path, jobs: int) -> list[str]:
    return [sys.executable, "-m", "grader", "grade-all", str(class_dir), "--out", str(out),
            "--jobs", str(jobs), "--quick", "--no-progress"]


def finished(out: Path) -> dict[str, float]:
    """Students whose results are complete -> mtime of their results.json."""
    return {s: (out / s / "results.json").stat().st_mtime_ns
            for s in CLASS if (out / s / RECORD_FILE).is_file()}


@pytest.fixture(scope="module")
def resumed(tmp_path_factory):
    """Run 1 killed after the first result, run 2 to the end, run 3 with nothing changed."""
    root = tmp_path_factory.mktemp("class")
    class_dir, out = make_class(root / "submissions"), root / "out"
    # One job: the first result appears while the others are still waiting.
    killed = subprocess.Popen(grade_all_cmd(class_dir, out, 1), cwd=PROJECT_ROOT, start_new_session=True,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 240
    while not finished(out) and killed.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    os.killpg(killed.pid, signal.SIGKILL)
    killed.wait()
    after_kill = finished(out)
    second = subprocess.run(grade_all_cmd(class_dir, out, 2), cwd=PROJECT_ROOT, capture_output=True,
                            text=True, timeout=300)
    after_second = finished(out)
    third = subprocess.run(grade_all_cmd(class_dir, out, 2), cwd=PROJECT_ROOT, capture_output=True,
                           text=True, timeout=300)
    return dict(out=out, after_kill=after_kill, second=second, after_second=after_second,
                third=third, after_third=finished(out))


def test_killed_run_kept_only_complete_results(resumed):
    done = resumed["after_kill"]
    assert 1 <= len(done) < len(CLASS), f"the kill came too late to test resuming: {sorted(done)}"
    for student in done:
        results = json.loads((resumed["out"] / student / "results.json").read_text())
        jsonschema.validate(results, load_schema())


def test_rerun_skips_finished_and_completes_the_rest(resumed):
    second = resumed["second"]
    assert second.returncode == 0, second.stdout + second.stderr
    before, after = resumed["after_kill"], resumed["after_second"]
    assert set(after) == set(CLASS)
    for student, mtime in before.items():
        assert after[student] == mtime, f"{student} was graded again although unchanged"
    assert f"{len(CLASS) - len(before)} graded now, {len(before)} unchanged" in second.stdout
    assert not list(resumed["out"].glob(".tmp-*")), "an interrupted grading's folder was left behind"


def test_rerun_with_nothing_changed_grades_nothing(resumed):
    third = resumed["third"]
    assert third.returncode == 0, third.stdout + third.stderr
    assert resumed["after_third"] == resumed["after_second"]
    assert f"0 graded now, {len(CLASS)} unchanged" in third.stdout


def test_gradebook_columns_and_statuses(resumed):
    with open(resumed["out"] / "gradebook.csv", newline="") as f:
        rows = {r["student"]: r for r in csv.DictReader(f)}
        f.seek(0)
        header = next(csv.reader(f))
    assert header[:4] == ["student", "score", "max_score", "status"] and header[-1] == "diagnoses"
    checks = header[4:-1]
    rubric = json.loads((resumed["out"] / "alice" / "results.json").read_text())
    assert checks == [t["extra_data"]["check"] for t in rubric["tests"]]   # rubric keys, in rubric order
    assert set(rows) == set(CLASS)
    for student, (_, _, status, diagnosis) in CLASS.items():
        row = rows[student]
        results = json.loads((resumed["out"] / student / "results.json").read_text())
        assert row["status"] == status, student
        assert float(row["score"]) == pytest.approx(results["score"])
        assert float(row["max_score"]) == results["extra_data"]["max_score"] > 0
        assert sum(float(row[c] or 0) for c in checks) == pytest.approx(results["score"], abs=0.05)
        if diagnosis:
            assert diagnosis in row["diagnoses"].split(), (student, row["diagnoses"])
    for correct in ("alice", "bob"):
        assert rows[correct]["score"] == rows[correct]["max_score"]
        assert rows[correct]["diagnoses"] == ""
    assert float(rows["carol"]["score"]) < float(rows["carol"]["max_score"])


def test_class_summary_written(resumed):
    out = resumed["out"]
    summary = (out / "summary.md").read_text()
    assert f"{len(CLASS)} submissions: 1 build-error, {len(CLASS) - 1} graded." in summary
    for diagnosis in ("v-flipped", "crash", "build-error"):
        assert f"`{diagnosis}`" in summary
    for image in ("summary_histogram.png", "summary_speed_accuracy.png"):
        assert (out / image).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert f"({image})" in summary
    page = (out / "summary.html").read_text()
    assert page.count("data:image/png;base64,") == 2
    for student in CLASS:   # every student's report is one click away
        assert f'<td><a href="{student}/report.html">{student}</a></td>' in page
        assert f"[{student}](<{student}/report.html>)" in summary


def test_student_names_come_from_folders_and_archives(tmp_path):
    for name in ("alice", "bob.zip", "carol.tar.gz", "dave.cpp", "erin.tgz", ".hidden", "notes.txt", "frank"):
        (tmp_path / name).mkdir() if "." not in name else (tmp_path / name).write_text("")
    (tmp_path / "frank.zip").write_text("")   # frank twice: neither hides the other
    names = find_submissions(tmp_path)
    assert sorted(names) == ["alice", "bob", "carol", "dave", "erin", "frank", "frank.zip"]


def test_gradebook_leaves_checks_that_did_not_run_blank(tmp_path):
    rows = [Row("a", "graded", 30, 40, {"one": 10, "two": 20}, ["x"]),
            Row("b", "ungradable", 0, 0, {}, [], error="boom")]
    write_gradebook(rows, tmp_path / "g.csv")
    assert (tmp_path / "g.csv").read_text().splitlines() == [
        "student,score,max_score,status,one,two,diagnoses", "a,30,40,graded,10,20,x", "b,0,0,ungradable,,,"]


def test_missing_folder_is_a_clear_error(tmp_path):
    run = subprocess.run([sys.executable, "-m", "grader", "grade-all", str(tmp_path / "nope")],
                         cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=60)
    assert run.returncode == 2 and "is not a folder" in run.stderr
