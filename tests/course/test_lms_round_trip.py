"""The round trip an instructor makes: the LMS's own export as roster, the
LMS's own download of the submissions, grade-all, and the grade file back
into the LMS, cell by cell.

The exports in tests/course/exports/ are shaped as Canvas, Moodle and
Gradescope write them (our own made-up students): Canvas's gradebook export
(BOM, its Points Possible row with "(read only)" totals, two assignments, its
test student, login names that are not email addresses), Moodle's grades
export (Grades -> Export -> Plain text file) and Gradescope's roster (with a
member of staff). Who handed in what is written here first (CLASS); each
import is read back by a model of the LMS's documented import rules
(_canvas_import, _moodle_import), not by the code that wrote it.
"""
from __future__ import annotations

import csv
import io
import shutil
import zipfile
from pathlib import Path

import pytest

from grader import PROJECT_ROOT

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]   # grades a class three times

EXPORTS = Path(__file__).resolve().parent / "exports"
SUBMISSIONS = PROJECT_ROOT / "tests" / "submissions"
# The class, by SIS id: what each student handed in (None: nothing) and the status it must get.
CLASS = {
    "S2026001": (SUBMISSIONS / "correct" / "if_chain.cpp", "graded"),
    "S2026002": (SUBMISSIONS / "wrong" / "v-flipped-pos-z.cpp", "graded"),
    "S2026003": (SUBMISSIONS / "build" / "syntax_error.cpp", "build-error"),
    "S2026004": (SUBMISSIONS / "correct" / "axis_table.cpp", "graded"),
    "S2026005": (None, "no-submission"),
}
# Canvas's "Download Submissions", unpacked: <lastfirst>[_LATE]_<user id>_<attachment id>_<file name>,
# "-1" added to a resubmitted file's name; a zip handed in stays a zip.
CANVAS_DOWNLOAD = {
    "S2026001": "adamsalice_9001_700001_EnvironmentMap-1.cpp",
    "S2026002": "bakerbruno_LATE_9002_700002_EnvironmentMap.cpp",
    "S2026003": "chenchiara_9003_700003_EnvironmentMap.cpp",
    "S2026004": "duboisdmitri_9004_700004_handin.zip",
}
# Moodle's "Download all submissions" in folders (its default since 3.1):
# <full name>_<participant number>_assignsubmission_file/<file name>.
MOODLE_DOWNLOAD = {
    "S2026001": "Alice Adams_1201_assignsubmission_file",
    "S2026002": "Bruno Baker_1202_assignsubmission_file",
    "S2026003": "Chiara Chen_1203_assignsubmission_file",
    "S2026004": "Dmitri Dubois_1204_assignsubmission_file",
}
CANVAS_POINTS = 10.0          # the export's Points Possible for "Environment map (4711)"
OPTIONS = {"quick": True, "only": ("read_texture", "fetch_sweep", "diagnosis")}


def _canvas_download(folder: Path) -> Path:
    folder.mkdir(parents=True)
    for sid, name in CANVAS_DOWNLOAD.items():
        source = CLASS[sid][0]
        if name.endswith(".zip"):
            with zipfile.ZipFile(folder / name, "w") as z:
                # a fixed date: the same download made twice is the same bytes (grade-all keeps it)
                z.writestr(zipfile.ZipInfo("handin/EnvironmentMap.cpp", (2026, 12, 1, 9, 0, 0)), source.read_bytes())
        else:
            shutil.copy(source, folder / name)
    return folder


def _moodle_download(folder: Path) -> Path:
    for sid, name in MOODLE_DOWNLOAD.items():
        (folder / name).mkdir(parents=True)
        shutil.copy(CLASS[sid][0], folder / name / "EnvironmentMap.cpp")
    return folder


def _grade(root: Path) -> dict:
    """Both downloads graded with their LMS's export; the Moodle download again
    with Gradescope's roster (nothing regraded). Once per session."""
    from grader.course.grade_all import grade_all
    canvas = _canvas_download(root / "canvas")
    moodle = _moodle_download(root / "moodle")
    grade_all(canvas, root / "out-canvas", 2, dict(OPTIONS), progress=False, roster=EXPORTS / "canvas_gradebook.csv")
    grade_all(moodle, root / "out-moodle", 2, dict(OPTIONS), progress=False, roster=EXPORTS / "moodle_grades.csv")
    shutil.copytree(root / "out-moodle", root / "out-gradescope")
    rows = grade_all(moodle, root / "out-gradescope", 2, dict(OPTIONS), progress=False,
                     roster=EXPORTS / "gradescope_roster.csv")
    assert all(r.skipped for r in rows)
    return {lms: root / f"out-{lms}" for lms in ("canvas", "moodle", "gradescope")}


@pytest.fixture(scope="module")
def graded():
    import session_once
    return session_once.once("lms-round-trip", _grade)


def _read(path: Path) -> list[dict]:
    return list(csv.DictReader(io.StringIO(path.read_bytes().decode("utf-8-sig"), newline="")))


def _gradebook(out: Path) -> dict[str, dict]:
    return {r["student_id"]: r for r in _read(out / "gradebook.csv")}


def _canvas_import(path: Path, export: Path) -> dict[str, str]:
    """Canvas's gradebook import, as documented: students found by ID, SIS
    User ID or SIS Login ID; an assignment column named as the export names it
    ("Name (id)") fills that assignment, any other name makes a new one; the
    Points Possible row is not a student; a blank cell changes nothing.
    Returns {SIS User ID: cell} for the existing assignment."""
    known = _read(export)
    header = list(_read(path)[0])
    column = "Environment map (4711)"
    assert header[:5] == ["Student", "ID", "SIS User ID", "SIS Login ID", "Section"]
    assert column in header, f"Canvas would create a new assignment: {header[5:]}"
    by = {(key, r[key]): r["SIS User ID"] for r in known for key in ("ID", "SIS User ID", "SIS Login ID") if r[key]}
    cells = {}
    for row in _read(path):
        if row["Student"].strip() == "Points Possible":
            continue
        found = {by.get((key, row[key])) for key in ("ID", "SIS User ID", "SIS Login ID") if row[key]}
        assert len(found) == 1 and None not in found, f"Canvas finds no single student for {row}"
        cells[found.pop()] = row[column]
    return cells


def _moodle_import(path: Path, export: Path, mapped_by: str) -> dict[str, str]:
    """Moodle's CSV grade import (grade/import/csv/classes/load_data.php):
    each row's user found by the column mapped to ID number or Email address;
    a user not found stops the whole import; a blank identifier leaves the row
    to the previous user (so none may be blank); "" or "-" is no grade, else a
    number. Returns {ID number: grade}."""
    users = {r[mapped_by]: r["ID number"] for r in _read(export)}
    grades = {}
    header = list(_read(path)[0])
    assert header[-1] == "Assignment: Environment map (Real)", header   # as Moodle's own export names it
    for row in _read(path):
        assert row[mapped_by], f"a blank {mapped_by} gives this row's grade to the previous student: {row}"
        assert row[mapped_by] in users, f"Moodle stops the import: no user with {mapped_by} {row[mapped_by]!r}"
        value = row[header[-1]]
        assert value not in ("", "-"), f"a blank grade erases the student's grade in Moodle: {row}"
        float(value)
        grades[users[row[mapped_by]]] = value
    return grades


def _expected(row: dict, scale: float | None = None) -> str:
    """What the LMS should receive for a gradebook row: nothing for a student
    who handed in nothing, else the score (scaled)."""
    if row["status"] == "no-submission":
        return ""
    score = float(row["score"])
    return f"{round(score * scale / float(row['max_score']), 2):g}" if scale else row["score"]


def test_every_student_is_matched_and_graded_as_handed_in(graded):
    for lms, out in graded.items():
        book = _gradebook(out)
        assert sorted(book) == sorted(CLASS), lms
        for sid, (_, status) in CLASS.items():
            assert book[sid]["status"] == status, (lms, sid, book[sid])
    assert float(_gradebook(graded["canvas"])["S2026001"]["score"]) > float(
        _gradebook(graded["canvas"])["S2026002"]["score"]) > 0   # the flipped face costs points


def test_a_moodle_download_and_a_canvas_download_grade_to_the_same_gradebook(graded):
    def grades(out):
        return {sid: {k: v for k, v in row.items() if k not in ("student", "name", "email")}
                for sid, row in _gradebook(out).items()}
    assert grades(graded["moodle"]) == grades(graded["canvas"])


def test_canvas_imports_its_own_assignment_scaled_to_its_points(graded):
    out = graded["canvas"]
    cells = _canvas_import(out / "grades_canvas.csv", EXPORTS / "canvas_gradebook.csv")
    book = _gradebook(out)
    assert cells == {sid: _expected(book[sid], CANVAS_POINTS) for sid in CLASS}
    assert cells["S2026005"] == "" and float(cells["S2026001"]) == CANVAS_POINTS
    points_row = _read(out / "grades_canvas.csv")[0]
    assert points_row["Student"].strip() == "Points Possible" and points_row["Environment map (4711)"] == "10"
    assert "Student, Test" not in (out / "grades_canvas.csv").read_text()


def test_canvas_gets_zero_for_nothing_handed_in_when_asked(graded, tmp_path):
    from grader.course.grade_all import grade_all
    out = tmp_path / "out"
    shutil.copytree(graded["canvas"], out)
    rows = grade_all(_canvas_download(tmp_path / "canvas"), out, 1, dict(OPTIONS), progress=False,
                     roster=EXPORTS / "canvas_gradebook.csv", zero_missing=True)
    assert all(r.skipped for r in rows)
    cells = _canvas_import(out / "grades_canvas.csv", EXPORTS / "canvas_gradebook.csv")
    assert cells["S2026005"] == "0"


@pytest.mark.parametrize("mapped_by", ["ID number", "Email address"])
def test_moodle_imports_by_id_number_or_email(graded, mapped_by):
    out = graded["moodle"]
    grades = _moodle_import(out / "grades_moodle.csv", EXPORTS / "moodle_grades.csv", mapped_by)
    book = _gradebook(out)
    assert grades == {sid: _expected(book[sid]) for sid in CLASS if CLASS[sid][0] is not None}


def test_moodle_import_from_a_canvas_roster_has_no_login_as_email(graded):
    """Canvas's SIS Login ID is a login name here: Moodle's file carries the
    ID number alone rather than a login in its Email address column."""
    rows = _read(graded["canvas"] / "grades_moodle.csv")
    assert list(rows[0]) == ["Full name", "ID number", "Environment map"]
    assert {r["ID number"] for r in rows} == {sid for sid in CLASS if CLASS[sid][0] is not None}


def test_gradescope_file_has_its_export_columns_cell_by_cell(graded):
    out = graded["gradescope"]
    rows = _read(out / "grades_gradescope.csv")
    book = _gradebook(out)
    roster = {r["SID"]: r for r in _read(EXPORTS / "gradescope_roster.csv") if r["Role"] == "Student"}
    assert [r["SID"] for r in rows] == [sid for sid in book]
    for r in rows:
        sid = r["SID"]
        assert (r["First Name"], r["Last Name"], r["Email"]) == (
            roster[sid]["First Name"], roster[sid]["Last Name"], roster[sid]["Email"])
        assert r["Total Score"] == _expected(book[sid])
        assert r["Status"] == ("Missing" if CLASS[sid][0] is None else "Graded")
    assert "Hopper" not in (out / "grades_gradescope.csv").read_text()    # staff are not students
