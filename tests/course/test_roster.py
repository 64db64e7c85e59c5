"""grader/course/roster.py: class rosters from Gradescope and Canvas exports (and
plain CSVs), matched to the names of the class folder's entries."""
from __future__ import annotations

import pytest

from grader.course.grade_all import MISSING, Row, write_gradebook
from grader.course.roster import RosterError, Student, left_out_text, load_roster

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
    assert r.columns == {"id": "SIS User ID", "name": "Student", "login": "SIS Login ID"}
    assert r.students == [Student("1001", "Doe, Jane", "", "555", "S1", "jdoe"),     # a login, not an email
                          Student("1002", "Smith, John", "", "556", "S1", "jsmith")]
    assert [left_out_text(x) for x in r.left_out] == ["Test Student: Canvas's test student (Student View), not a student"]


def test_canvas_names_its_test_student_last_name_first(tmp_path):
    """Today's Canvas exports call the Student View user "Student, Test"."""
    r = roster(tmp_path, CANVAS.replace("Test Student,999", '"Student, Test",999'))
    assert [s.name for s in r.students] == ["Doe, Jane", "Smith, John"]
    assert [left_out_text(x) for x in r.left_out] == ["Student, Test: Canvas's test student (Student View), not a student"]
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


# ---- Moodle, logins, points, staff -----------------------------------------------------

MOODLE = ('"First name","Last name","ID number",Institution,Department,"Email address",'
          '"Assignment: Environment map (Real)","Last downloaded from this course"\n'
          'Jane,Doe,1001,Uni,CS,jane.doe@uni.edu,-,1796601600\n'
          'John,Smith,1002,Uni,CS,john.smith@uni.edu,-,1796601600\n')


@pytest.mark.parametrize("entry", [
    "Jane Doe_101_assignsubmission_file",                      # downloaded in folders (Moodle 3.1 and later)
    "Jane Doe_101_assignsubmission_file_",                     # in folders, before 3.1
    "Jane Doe_101_assignsubmission_file_EnvironmentMap",       # one flat folder (.cpp taken off)
    "Jane Doe_101_assignsubmission_file_my_handin",            # a zip the student named
])
def test_moodle_download_names_match_by_full_name(tmp_path, entry):
    matched, unmatched, missing = roster(tmp_path, MOODLE).match([entry])
    assert matched[entry].id == "1001" and unmatched == [] and [s.id for s in missing] == ["1002"]


def test_a_moodle_participant_number_is_never_taken_for_a_canvas_or_student_id(tmp_path):
    """Participant 555 is Moodle's number for one assignment: Jane's Canvas id
    555 must not claim John's download."""
    matched, unmatched, _ = roster(tmp_path, CANVAS).match(["John Smith_555_assignsubmission_file"])
    assert matched["John Smith_555_assignsubmission_file"].id == "1002"


def test_moodle_grading_worksheet_matches_by_participant_number(tmp_path):
    worksheet = ('Identifier,"Full name","Email address",Status,Grade,"Maximum Grade"\n'
                 '"Participant 101","Jane Doe",jane.doe@uni.edu,"Submitted for grading",,100.00\n'
                 '"Participant 102","Jane Doe",jane.d@uni.edu,"Submitted for grading",,100.00\n')
    matched, unmatched, _ = roster(tmp_path, worksheet).match(["Jane Doe_102_assignsubmission_file"])
    assert matched["Jane Doe_102_assignsubmission_file"].email == "jane.d@uni.edu"   # two Jane Does: the number decides


def test_moodle_export_gives_id_number_email_and_its_assignment_columns(tmp_path):
    r = roster(tmp_path, MOODLE)
    assert r.students[0] == Student("1001", "Jane Doe", "jane.doe@uni.edu")
    assert r.moodle_items == ["Assignment: Environment map (Real)"]


def test_a_login_is_an_email_only_when_it_is_one(tmp_path):
    r = roster(tmp_path, CANVAS.replace("jsmith", "john.smith@uni.edu"))
    assert [(s.email, s.login) for s in r.students] == [("", "jdoe"), ("john.smith@uni.edu", "john.smith@uni.edu")]


def test_canvas_points_possible_per_assignment(tmp_path):
    text = ("Student,ID,SIS User ID,SIS Login ID,Section,Environment map (4711),Quiz (12),Current Points\n"
            "    Points Possible,,,,,10.00,5.00,(read only)\n"
            '"Doe, Jane",555,1001,jdoe,S1,,,\n')
    r = roster(tmp_path, text)
    assert r.points_possible == {"Environment map (4711)": 10.0, "Quiz (12)": 5.0}


def test_gradescope_staff_are_left_out(tmp_path):
    r = roster(tmp_path, GRADESCOPE + "Grace,Hopper,,ghopper@uni.edu,Instructor\n")
    assert [s.name for s in r.students] == ["Jane Doe", "John Smith", "Ann Lee"]
    assert [left_out_text(x) for x in r.left_out] == ["Grace Hopper: Instructor, not a student"]


@pytest.mark.parametrize("wanted, canvas, moodle", [
    (None, "Environment map (4711)", "Assignment: Environment map (Real)"),      # the default name
    ("Environment map (4711)", "Environment map (4711)", "Assignment: Environment map (Real)"),
    ("quiz", "Quiz (12)", "Assignment: Quiz (Real)"),                            # the name without decoration
])
def test_the_assignment_to_fill_is_found_in_the_export(tmp_path, wanted, canvas, moodle):
    from grader.course.lms_csv import choose_target
    text = ("Student,ID,SIS User ID,SIS Login ID,Section,Quiz (12),Environment map (4711)\n"
            "    Points Possible,,,,,5,10\n")
    r = roster(tmp_path, text)
    r.moodle_items = ["Assignment: Quiz (Real)", "Assignment: Environment map (Real)"]
    target = choose_target(r, wanted)
    assert (target.canvas_column, target.moodle_column) == (canvas, moodle)
    assert target.canvas_points == r.points_possible[canvas] and target.notes == []


def test_an_export_with_several_assignments_and_none_named_is_refused(tmp_path):
    from grader.course.lms_csv import TargetError, choose_target
    r = roster(tmp_path, "Student,ID,SIS User ID,SIS Login ID,Section,Quiz (12),Lab 2 (13)\n")
    with pytest.raises(TargetError, match=r"the Canvas export has 2 assignments \(Quiz \(12\), Lab 2 \(13\)\); "
                                          "name the one to fill with --assignment"):
        choose_target(r, None)
    target = choose_target(r, "Environment map")     # named, but not in the export: a new assignment, said so
    assert target.canvas_column == "Environment map" and target.canvas_points is None
    assert target.notes == ["grades_canvas.csv: the Canvas export has no assignment named 'Environment map': "
                            "Canvas will create a new assignment of that name"]
