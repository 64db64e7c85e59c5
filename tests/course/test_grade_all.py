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
import re
import shutil
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
from grader.course.grade_all import RECORD_FILE, Row, find_submissions, skipped_entries, write_gradebook
from grader.grading.score import RUBRIC, load_rubric
from grader.reports.gradescope_json import load_schema

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]   # grades whole classes

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
def resumed():
    """Run 1 killed after the first result, run 2 to the end, run 3 with nothing
    changed: once per session for both xdist workers (tests/helpers/session_once.py);
    tests read what it left, or copy it first."""
    import session_once
    return session_once.once("grade-all-resumed", _resume)


def _resume(root: Path) -> dict:
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
                third=third, after_third=finished(out), class_dir=class_dir)


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


@pytest.mark.representative
def test_gradebook_columns_and_statuses(resumed):
    with open(resumed["out"] / "gradebook.csv", newline="") as f:
        rows = {r["student"]: r for r in csv.DictReader(f)}
        f.seek(0)
        header = next(csv.reader(f))
    assert header[:4] == ["student", "score", "max_score", "status"] and header[-1] == "diagnoses"
    checks = header[4:-1]
    assert checks == list(load_rubric(RUBRIC)["checks"])   # every rubric key, in the rubric's order
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


@pytest.mark.representative
def test_class_summary_written(resumed):
    out = resumed["out"]
    summary = (out / "summary.md").read_text()
    assert f"{len(CLASS)} submissions: 1 compile error, {len(CLASS) - 1} graded." in summary
    for diagnosis in ("v-flipped", "crash", "build-error"):
        assert f"`{diagnosis}`" in summary
    for image in ("summary_histogram.png", "summary_speed_accuracy.png"):
        assert (out / image).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert f"({image})" in summary
    page = (out / "summary.html").read_text()
    assert page.count("data:image/png;base64,") == 2
    for student in CLASS:   # every student's report is one click away, beside their score
        assert f'<td class="who"><a href="{student}/report.html">{student}</a></td>' in page
        assert f"| [{student}](<{student}/report.html>) | " in summary


def test_student_names_come_from_folders_and_archives(tmp_path):
    for name in ("alice", "bob.zip", "carol.tar.gz", "dave.cpp", "erin.tgz", ".hidden", "notes.txt", "frank",
                 "hank.rar", "ivy.7z", "judy.tar.xz"):
        (tmp_path / name).mkdir() if "." not in name else (tmp_path / name).write_text("")
    (tmp_path / "frank.zip").write_text("")   # frank twice: neither hides the other
    names = find_submissions(tmp_path)
    # A .rar or .7z is graded, so that its student reads why it cannot be (unknown-format), not dropped.
    assert sorted(names) == ["alice", "bob", "carol", "dave", "erin", "frank", "frank.zip", "hank", "ivy", "judy"]
    assert skipped_entries(tmp_path) == [
        {"entry": ".hidden", "reason": "a hidden file or folder (its name starts with a dot)", "why": "hidden"},
        {"entry": "notes.txt",
         "reason": "a .txt file, not a submission (expected a folder, an archive or a .cpp per student)",
         "why": "file", "suffix": ".txt"}]


def test_every_skipped_entry_is_in_the_summary_data_and_printed(resumed):
    data = json.loads((resumed["out"] / "summary.json").read_text())
    assert [e["entry"] for e in data["skipped"]] == [".DS_Store", "notes.txt"]
    assert all(e["reason"] for e in data["skipped"])
    assert data["roster"] is None and data["similarity"] is None    # both off by default
    assert "skipped notes.txt: a .txt file, not a submission" in resumed["third"].stdout


# ---- roster ----------------------------------------------------------------------------


def test_roster_adds_id_name_email_and_the_students_who_handed_in_nothing(resumed, tmp_path):
    """A Canvas export (its "Points Possible" row, "Last, First" names, SIS ids)
    on the graded class: nothing is regraded, the gradebook gains the columns."""
    out = tmp_path / "out"
    shutil.copytree(resumed["out"], out)
    roster = tmp_path / "canvas.csv"
    lines = ["Student,ID,SIS User ID,SIS Login ID,Section,Environment map (1234)",
             "    Points Possible,,,,,100"]
    lines += [f'"{s.title()}son, {s.title()}",{900 + i},S{i:03d},{s}@uni.example,A,'
              for i, s in enumerate(CLASS)]
    lines.append('"Absent, Zed",999,S999,zed@uni.example,A,')
    roster.write_text("\ufeff" + "\n".join(lines) + "\n")     # Excel's byte-order mark, as Canvas writes it
    run = subprocess.run(grade_all_cmd(resumed["class_dir"], out, 2) + ["--roster", str(roster)],
                         cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert f"0 graded now, {len(CLASS)} unchanged" in run.stdout
    with open(out / "gradebook.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0])[:7] == ["student", "student_id", "name", "email", "score", "max_score", "status"]
    by_student = {r["student"]: r for r in rows}
    for i, student in enumerate(CLASS):    # matched by the email's local part, the folder's name
        assert by_student[student]["student_id"] == f"S{i:03d}"
        assert by_student[student]["email"] == f"{student}@uni.example"
    absent = rows[-1]
    assert (absent["student_id"], absent["name"], absent["status"], absent["score"]) == (
        "S999", "Absent, Zed", "no-submission", "")
    summary = json.loads((out / "summary.json").read_text())["roster"]
    assert summary["matched"] == len(CLASS) and summary["unmatched"] == []
    assert summary["missing"] == [{"id": "S999", "name": "Absent, Zed", "email": "zed@uni.example"}]
    assert "  handed in nothing: Absent, Zed (S999, zed@uni.example)\n" in run.stdout
    # Canvas's import file fills the assignment the export named, the absent student left blank.
    with open(out / "grades_canvas.csv", newline="") as f:
        canvas = list(csv.reader(f))
    assert canvas[0] == ["Student", "ID", "SIS User ID", "SIS Login ID", "Section", "Environment map (1234)"]
    assert canvas[1] == ["    Points Possible", "", "", "", "", "100"]
    assert canvas[2] == ["Aliceson, Alice", "900", "S000", "alice@uni.example", "A", by_student["alice"]["score"]]
    assert canvas[-1] == ["Absent, Zed", "999", "S999", "zed@uni.example", "A", ""]
    for name in ("grades_canvas.csv", "grades_moodle.csv", "grades_gradescope.csv"):
        assert f"LMS import: {out / name}" in run.stdout


@pytest.mark.representative
def test_unmatched_students_and_canvas_test_student_are_printed(resumed, tmp_path):
    out = tmp_path / "out"
    shutil.copytree(resumed["out"], out)
    roster = tmp_path / "canvas.csv"
    lines = ["Student,ID,SIS User ID,SIS Login ID,Section"]
    lines += [f'"{s.title()}son, {s.title()}",{900 + i},S{i:03d},{s}@uni.example,A' for i, s in enumerate(CLASS)
              if s != "alice"]
    lines.append('"Student, Test",999,,,A')
    roster.write_text("\n".join(lines) + "\n")
    run = subprocess.run(grade_all_cmd(resumed["class_dir"], out, 2) + ["--roster", str(roster)],
                         cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "  matches no one on the roster (not in the LMS files): alice\n" in run.stdout
    assert "  left out of the roster: Student, Test: Canvas's test student (Student View), not a student\n" in run.stdout
    assert "handed in nothing" not in run.stdout
    with open(out / "gradebook.csv", newline="") as f:
        assert "Student, Test" not in f.read()
    with open(out / "grades_moodle.csv", newline="") as f:
        moodle = list(csv.DictReader(f))
    assert [r["Email address"] for r in moodle] == [f"{s}@uni.example" for s in CLASS if s != "alice"]


def test_an_unreadable_roster_is_a_usage_error(resumed, tmp_path):
    roster = tmp_path / "roster.csv"
    roster.write_text("colour,size\nred,3\n")
    run = subprocess.run(grade_all_cmd(resumed["class_dir"], tmp_path / "out", 1) + ["--roster", str(roster)],
                         cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=120)
    assert run.returncode == 2
    assert "no column to match students by" in run.stderr and "colour, size" in run.stderr
    assert not (tmp_path / "out" / "gradebook.csv").exists()    # refused before grading


# ---- similarity ---------------------------------------------------------------------------


def near_copy(source: str) -> str:
    """Renamed identifiers, another layout, other comments: what hiding a copy looks like."""
    renames = {"direction": "d", "face": "which", "alpha": "wx", "beta": "wy", "px": "sx", "py": "sy",
               "ix": "i", "iy": "j", "c00": "q1", "c10": "q2", "c01": "q3", "c11": "q4", "addr": "base"}
    for old, new in renames.items():
        source = re.sub(rf"\b{old}\b", new, source)
    lines = [line.strip() for line in source.splitlines() if not line.strip().startswith("//")]
    return "// written by me\n" + "\n".join(("\t" + line) if line.endswith(";") else line for line in lines)


def test_similarity_finds_the_near_copy_among_independent_solutions(tmp_path):
    klass = tmp_path / "class"
    klass.mkdir()
    independent = sorted((SUBMISSIONS / "correct").glob("*.cpp"))
    assert len(independent) >= 5
    for path in independent:
        shutil.copy(path, klass / f"{path.stem}.cpp")
    (klass / "copycat").mkdir()
    (klass / "copycat" / "EnvironmentMap.cpp").write_text(near_copy((SUBMISSIONS / "correct" / "if_chain.cpp").read_text()))
    with zipfile.ZipFile(klass / "untouched.zip", "w") as z:     # the template as handed out: nothing of its own
        z.write(PROJECT_ROOT / "student_template" / "EnvironmentMap.cpp", "EnvironmentMap.cpp")
    from grader.course.grade_all import find_submissions as found
    from grader.course.similarity import class_similarity
    data = class_similarity(found(klass))
    assert data["tool"].startswith("copydetect ") and data["boilerplate"] == "student_template/EnvironmentMap.cpp"
    top = data["pairs"][0]
    assert (top["a"], top["b"]) == ("copycat", "if_chain") and top["similarity"] > 0.9
    assert [p for p in data["pairs"] if p is not top] == []      # independent solutions stay below the bar
    assert top["passages"] and all(p["a_text"] and p["b_text"] for p in top["passages"])
    assert any("readTexture" in p["b_text"] or "fetchColor" in p["b_text"] for p in top["passages"])
    assert data["not_compared"] == [{"student": "untouched", "reason": "nothing of its own beyond the template"}]
    assert data["compared"] == len(independent) + 1


@pytest.mark.slow
def test_grade_all_similarity_writes_the_pairs_into_the_summary_data(tmp_path):
    klass = tmp_path / "class"
    klass.mkdir()
    shutil.copy(SUBMISSIONS / "correct" / "if_chain.cpp", klass / "alice.cpp")
    shutil.copy(SUBMISSIONS / "correct" / "switch_on_face.cpp", klass / "bob.cpp")
    (klass / "mallory.cpp").write_text(near_copy((SUBMISSIONS / "correct" / "if_chain.cpp").read_text()))
    run = subprocess.run(grade_all_cmd(klass, tmp_path / "out", 2) + ["--similarity"], cwd=PROJECT_ROOT,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    pairs = json.loads((tmp_path / "out" / "summary.json").read_text())["similarity"]["pairs"]
    assert [(p["a"], p["b"]) for p in pairs] == [("alice", "mallory")]


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


def test_similarity_without_its_tool_is_refused_before_grading(tmp_path, monkeypatch):
    import builtins

    import grader.course.grade_all
    from grader.course.similarity import SimilarityUnavailable
    real_import = builtins.__import__

    def no_copydetect(name, *args, **kwargs):
        if name.startswith("copydetect"):
            raise ImportError("No module named 'copydetect'")
        return real_import(name, *args, **kwargs)
    monkeypatch.setattr(builtins, "__import__", no_copydetect)
    klass = tmp_path / "class"
    klass.mkdir()
    shutil.copy(SUBMISSIONS / "build" / "syntax_error.cpp", klass / "alice.cpp")
    with pytest.raises(SimilarityUnavailable, match="make venv"):
        grader.course.grade_all.grade_all(klass, tmp_path / "out", 1, {"quick": True}, progress=False, similarity=True)
    assert not (tmp_path / "out" / "alice").exists()


# ---- a class that survives one student ------------------------------------------------


def grading_that_breaks_for_aaron_and_zed(student, submission, out, key, options):
    """grade-all's grading of one student (run in its grading processes),
    broken for two of them as a hostile classmate breaks it: aaron's grading
    process dies (SIGKILL, as a process ended by the kernel for its memory or
    by a thread bomb's effects) as soon as bob's grading starts beside it;
    zed's cannot start a thread. Every attempt is logged beside the results."""
    from grader.course.grade_all import _grade_one
    with open(Path(out).parent / f"attempts-{student}.log", "a") as log:
        log.write(f"{os.getpid()}\n")
    if student == "aaron":
        deadline = time.monotonic() + 120
        while not (Path(out).parent / "attempts-bob.log").exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        os.kill(os.getpid(), signal.SIGKILL)
    if student == "zed":
        raise RuntimeError("can't start new thread")
    return _grade_one(student, submission, out, key, options)


def test_a_grading_process_that_dies_costs_only_its_own_student(tmp_path):
    from grader.course.grade_all import grade_all
    klass, out = tmp_path / "class", tmp_path / "out"
    klass.mkdir()
    for student in ("aaron", "alice", "bob", "carol", "zed"):
        shutil.copy(SUBMISSIONS / "correct" / "if_chain.cpp", klass / f"{student}.cpp")
    rows = {r.student: r for r in grade_all(klass, out, 2, {"quick": True}, progress=False,
                                            grade_one=grading_that_breaks_for_aaron_and_zed)}
    for student in ("alice", "bob", "carol"):
        r = rows[student]
        assert (r.status, r.error) == ("graded", "") and r.score == r.max_score > 0, r
    # bob was being graded when aaron's process died: graded again, alone.
    assert len((out / "attempts-bob.log").read_text().split()) == 2
    for student, why in (("aaron", "its grading process was killed by SIGKILL"),
                         ("zed", "RuntimeError: can't start new thread")):
        r = rows[student]
        assert r.status == "ungradable" and r.error.startswith(why + " (graded alone"), r
        assert len((out / f"attempts-{student}.log").read_text().split()) == 2   # retried once, not more
    with open(out / "gradebook.csv", newline="") as f:
        assert {r["student"]: r["status"] for r in csv.DictReader(f)} == {
            "aaron": "ungradable", "alice": "graded", "bob": "graded", "carol": "graded", "zed": "ungradable"}
    assert not list(out.glob(".tmp-*")), "a killed grading's folder was left behind"


def test_a_resume_keeps_a_students_own_timeout_with_the_reason(tmp_path, isolation_mode):
    """spinner loops forever near +x: the worker sees it use its whole
    CPU-time limit, which no classmate can cause: kept on a resumed run,
    with the reason (a timeout stopped by the wall-clock bound alone is
    graded again: test_only_a_timeout_the_code_caused_is_kept). An unchanged
    good result is kept too."""
    from grader.course.grade_all import OWN_TIMEOUT_WHY, grade_all
    klass, out = tmp_path / "class", tmp_path / "out"
    klass.mkdir()
    shutil.copy(SUBMISSIONS / "correct" / "if_chain.cpp", klass / "alice.cpp")
    shutil.copy(SUBMISSIONS / "hostile" / "spin.cpp", klass / "spinner.cpp")   # loops forever near +x
    options = {"quick": True, "only": ["fetch_sweep"]}
    first = {r.student: r for r in grade_all(klass, out, 2, options, progress=False)}
    assert first["alice"].status == "graded" and first["alice"].score == first["alice"].max_score > 0
    assert first["spinner"].status == "timeout"
    assert json.loads((out / "spinner" / "results.json").read_text())["extra_data"]["isolation"] == isolation_mode
    assert json.loads((out / "spinner" / RECORD_FILE).read_text())["timeouts"] == ["code"]
    mtimes = {s: (out / s / "results.json").stat().st_mtime_ns for s in first}
    second = {r.student: r for r in grade_all(klass, out, 2, options, progress=False)}
    for kept in ("alice", "spinner"):
        assert second[kept].skipped and (out / kept / "results.json").stat().st_mtime_ns == mtimes[kept]
    assert second["spinner"].status == "timeout"
    data = json.loads((out / "summary.json").read_text())
    assert data["own_timeouts"] == {"students": ["spinner"], "why": OWN_TIMEOUT_WHY}
    assert data["grade_again"]["students"] == []
    page = (out / "summary.html").read_text()
    assert "1 timeout kept</strong> (spinner): the code used up its CPU-time limit" in page


@pytest.mark.parametrize("status, stops, kept", [
    ("timeout", ["code"], True),
    ("timeout", ["code", "code"], True),
    ("timeout", ["code", "grader"], False),   # one stopped by the wall-clock bound: maybe the machine's
    ("timeout", [], False),                   # an older grader's record: not known, graded again
    ("ungradable", ["code"], False),
])
def test_only_a_timeout_the_code_caused_is_kept(status, stops, kept):
    from grader.course.grade_all import own_timeout
    assert own_timeout(Row("s", status, 0.0, 100.0), {"timeouts": stops}) is kept


def test_a_timeout_says_what_stopped_it():
    """The worker's view (grader_limit: the wall-clock bound only) becomes the
    diagnosis's stopped_by, which grade-all records."""
    from grader.checks.context import failure_diagnoses
    from grader.worker.runner import Failure

    def timeout(grader_limit):
        return Failure("timeout", "fetchColor", 3, "fetchColor(...)", "did not finish in time", "a loop",
                       grader_limit=grader_limit)
    assert [d.stopped_by for d in failure_diagnoses([timeout(False)])] == ["code"]
    assert [d.stopped_by for d in failure_diagnoses([timeout(False), timeout(True)])] == ["grader"]
    crash = Failure("crash", "fetchColor", 1, "fetchColor(...)", "SIGSEGV", "a pointer")
    assert [d.stopped_by for d in failure_diagnoses([crash])] == [""]
