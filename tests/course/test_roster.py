"""grader/course/roster.py: class rosters from Gradescope and Canvas exports (and
plain CSVs), matched to the names of the class folder's entries."""
from __future__ import annotations

import pytest

from grader.course.grade_all import MISSING, Row, write_gradebook
from grader.course.roster import RosterError, Student, load_roster

GRADESCOPE = ("First Name,Last Name,SID,Email,Role\n"
              "Jane,Doe,1001,jdoe@uni.edu,Student\n"
              "John,Smith,1002,john.smith@uni.edu,Student\n"
              "Ann,Lee,1003,alee@uni.edu,Student\n")
CANVAS = ('\ufeffStudent,ID,SIS User ID,SIS Login ID,Section,Envmap (77)\n'
          '    Points Possible,,,,,100\n'
          '"Doe, Jane",555,1001,jdoe,S1,\n'
          '"Smith, John",556,1002,jsmith,S1,\n'
          'Test Student,999,,,S1,\n')


def roster(tmp_path, text):
    path = tmp_path / "roster.csv"
    path.write_text(text, encoding="utf-8")
    return load_roster(path)


def test_gradescope_roster_columns(tmp_path):
    r = roster(tmp_path, GRADESCOPE)
    assert r.columns == {"id": "SID", "name": "First Name", "email": "Email"}
    assert r.students[0] == Student("1001", "Jane Doe", "jdoe@uni.edu")


def test_canvas_gradebook_export_skips_points_possible_and_the_test_student(tmp_path):
    r = roster(tmp_path, CANVAS)
    assert r.columns == {"id": "SIS User ID", "name": "Student", "email": "SIS Login ID"}
    assert r.students == [Student("1001", "Doe, Jane", "jdoe", "555", "S1"),
                          Student("1002", "Smith, John", "jsmith", "556", "S1")]
    assert r.left_out == ["Test Student: Canvas's test student (Student View), not a student"]


def test_canvas_names_its_test_student_last_name_first(tmp_path):
    """Today's Canvas exports call the Student View user "Student, Test"."""
    r = roster(tmp_path, CANVAS.replace("Test Student,999", '"Student, Test",999'))
    assert [s.name for s in r.students] == ["Doe, Jane", "Smith, John"]
    assert r.left_out == ["Student, Test: Canvas's test student (Student View), not a student"]
    _, _, missing = r.match(["jdoe", "jsmith"])
    assert missing == []


@pytest.mark.parametrize("folder, sid", [
    ("1002", "1002"),                     # the student id
    ("john.smith", "1002"),               # the email's local part
    ("jdoe@uni.edu", "1001"),             # the email
    ("Jane Doe", "1001"), ("doe_jane", "1001"), ("janedoe", "1001"),   # the name, any order, any separator
])
def test_gradescope_matches(tmp_path, folder, sid):
    matched, unmatched, _ = roster(tmp_path, GRADESCOPE).match([folder])
    assert matched[folder].id == sid and unmatched == []


def test_canvas_download_names_match_by_canvas_user_id(tmp_path):
    matched, unmatched, missing = roster(tmp_path, CANVAS).match(["doejane_555_8812_EnvironmentMap", "mystery"])
    assert matched["doejane_555_8812_EnvironmentMap"].id == "1001"
    assert unmatched == ["mystery"] and [s.id for s in missing] == ["1002"]


def test_an_ambiguous_name_matches_nobody(tmp_path):
    twins = "Name,Email\nAlex Kim,ak1@uni.edu\nAlex Kim,ak2@uni.edu\n"
    matched, unmatched, missing = roster(tmp_path, twins).match(["alex_kim", "ak2"])
    assert list(matched) == ["ak2"] and unmatched == ["alex_kim"] and len(missing) == 1


def test_a_student_is_matched_once(tmp_path):
    matched, unmatched, _ = roster(tmp_path, GRADESCOPE).match(["1001", "jdoe"])
    assert list(matched) == ["1001"] and unmatched == ["jdoe"]


@pytest.mark.parametrize("content, message", [
    ("colour,size\nred,3\n", "no column to match students by"),
    ("", "empty"),
])
def test_unusable_rosters_say_why(tmp_path, content, message):
    with pytest.raises(RosterError, match=message):
        roster(tmp_path, content)


def test_a_roster_that_is_not_utf8_says_how_to_save_it(tmp_path):
    path = tmp_path / "latin1.csv"
    path.write_bytes("Name,SID\nJosé Núñez,1\n".encode("latin-1"))
    with pytest.raises(RosterError, match="save the roster as CSV UTF-8"):
        load_roster(path)


def test_gradebook_with_roster_columns_and_formula_safe_cells(tmp_path):
    rows = [Row("=HYPERLINK(1)", "graded", 30, 40, {"one": 30}, [], student_id="1001", name="+Doe", email="d@x"),
            Row("Ann Lee", MISSING, 0, 0, {}, [], student_id="1003", name="Ann Lee", email="alee@uni.edu")]
    write_gradebook(rows, tmp_path / "g.csv", roster_columns=True)
    assert (tmp_path / "g.csv").read_text().splitlines() == [
        "student,student_id,name,email,score,max_score,status,one,diagnoses",
        "'=HYPERLINK(1),1001,'+Doe,d@x,30,40,graded,30,",
        "Ann Lee,1003,Ann Lee,alee@uni.edu,,,no-submission,,"]
