"""A class roster (CSV) for grade-all: who each submission belongs to, so the
gradebook carries the student id and email an LMS imports by.

Accepted exports (columns matched by name, case and spacing ignored):

    Gradescope roster / grades   "First Name", "Last Name" or "Name", "SID", "Email"
    Canvas gradebook              "Student" ("Last, First"), "ID", "SIS User ID", "SIS Login ID",
                                  one "Name (id)" column per assignment, whose "Points Possible" row
                                  gives each one's points
    Moodle grades export          "First name", "Last name" or "Surname", "ID number", "Email address",
                                  "Assignment: Name (Real)" columns
    Moodle grading worksheet      "Identifier" ("Participant 101"), "Full name", "Email address"
    anything else                 "id" / "student id" / "student_id", "name", "email"

A login is not an email address: Canvas's "SIS Login ID" is kept apart and
counts as the email only when it is one (Moodle maps grades by email).

A submission (a folder or archive name in the class folder) is matched to
a roster row by, in order: the student id, the email or its local part,
Canvas's user id inside a Canvas download name ("doejane_12345_67890_...
"), the full name and participant number inside a Moodle download name
("Jane Doe_101_assignsubmission_file_EnvironmentMap.cpp", or the folder
"Jane Doe_101_assignsubmission_file" when downloaded in folders), the name
with everything but letters and digits removed ("Jane Doe", "jane_doe",
"doe_jane", "doejane", "janedoe"). A name that two rows share matches
neither: an ambiguous match is worse than none.

Canvas's test student ("Student, Test" in its exports, "Test Student" in
older ones) is left out, with a note (Roster.left_out): it is no one, and
would show as a student who handed in nothing.

Everything in a roster or a file name is plain text for the reports.
"""
from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..i18n import N_, Translated

# Header names, normalised (lower case, letters and digits only), by what they hold.
ID_COLUMNS = ("sid", "studentid", "sisuserid", "idnumber", "studentnumber", "matriculationnumber", "id", "userid")
EMAIL_COLUMNS = ("email", "emailaddress", "email1")
LOGIN_COLUMNS = ("sisloginid", "loginid", "username")
NAME_COLUMNS = ("name", "fullname", "student", "studentname")
FIRST_COLUMNS = ("firstname", "givenname")
LAST_COLUMNS = ("lastname", "surname", "familyname")
SECTION_COLUMNS = ("section", "sections", "group")
ROLE_COLUMN = "role"        # Gradescope's roster export lists its staff too
# Canvas's test student, as its exports name it (normalised: letters only).
CANVAS_TEST_STUDENT = ("studenttest", "teststudent")
CANVAS_ID = "id"            # Canvas's own user id, part of its download file names
MOODLE_IDENTIFIER = "identifier"   # Moodle's grading worksheet: "Participant 101", part of its download names
# Moodle's "download all submissions": "<full name>_<participant>_assignsubmission_<plugin>" then
# "_<file name>" (one flat folder) or "/<file name>" (in folders; Moodle before 3.1 ended it in "_").
MOODLE_DOWNLOAD = re.compile(r"(?P<name>[^_]+)_(?P<participant>\d+)_assignsubmission_[a-z]+(?:_.*)?", re.S)
CANVAS_ASSIGNMENT = re.compile(r"(?P<name>.*\S) \((?P<id>\d+)\)")        # "Environment map (4711)"
MOODLE_ASSIGNMENT = re.compile(r"Assignment: (?P<name>.*\S) \(Real\)")   # its grades export's column
MAX_ROSTER_BYTES = 10 << 20
# Why a roster row is no one, by key. Roster.left_out (and summary.json)
# keeps the key ("why") with the row's name and role; the command's output
# and the class page say it in their language (left_out_text).
LEFT_OUT = Translated({
    "role": N_("%(name)s: %(role)s, not a student"),
    "test-student": N_("%(name)s: Canvas's test student (Student View), not a student"),
})


class RosterError(Exception):
    """The roster cannot be read or has no column to match by."""


@dataclass(frozen=True)
class Student:
    id: str
    name: str
    email: str
    canvas_id: str = ""
    section: str = ""       # Canvas's import wants it back
    login: str = ""         # Canvas's SIS Login ID, which its import wants back
    participant: str = ""   # Moodle's participant number for one assignment (its grading worksheet)


@dataclass
class Roster:
    students: list[Student]
    columns: dict[str, str] = field(default_factory=dict)   # what -> the header it came from
    left_out: list[dict] = field(default_factory=list)      # rows that are no one, and why (LEFT_OUT)
    assignments: list[str] = field(default_factory=list)    # Canvas's assignment columns, "Name (id)"
    points_possible: dict[str, float] = field(default_factory=dict)   # Canvas: assignment column -> points
    moodle_items: list[str] = field(default_factory=list)   # a Moodle export's "Assignment: Name (Real)" columns

    def match(self, submission_names: list[str]) -> tuple[dict[str, Student], list[str], list[Student]]:
        """({submission: student}, submissions matched to nobody, students with no submission)."""
        index: dict[str, list[Student]] = {}
        for s in self.students:
            for key in _keys(s):
                bucket = index.setdefault(key, [])
                if s not in bucket:
                    bucket.append(s)
        matched: dict[str, Student] = {}
        for name in submission_names:
            student = _lookup(name, index)
            if student is not None and student not in matched.values():
                matched[name] = student
        unmatched = [n for n in submission_names if n not in matched]
        missing = [s for s in self.students if s not in matched.values()]
        return matched, unmatched, missing


def _norm(text: str) -> str:
    return re.sub(r"[^0-9a-z]", "", text.casefold())


def _keys(s: Student) -> list[str]:
    keys = [_norm(s.id), _norm(s.email), _norm(s.email.split("@")[0]) if "@" in s.email else "", _norm(s.login)]
    words = [w for w in re.split(r"[\s,]+", s.name.casefold()) if w]
    if words:
        keys += [_norm("".join(words)), _norm("".join(reversed(words)))]
        if "," in s.name:   # Canvas: "Doe, Jane" -> janedoe as well
            last, _, first = s.name.partition(",")
            keys += [_norm(first + last), _norm(last + first)]
    keys = [k for k in keys if k]
    # Canvas's user id and Moodle's participant number, found inside their download names (see _lookup).
    return (keys + ([f"canvas:{s.canvas_id}"] if s.canvas_id else [])
            + ([f"moodle:{s.participant}"] if s.participant else []))


def _lookup(name: str, index: dict[str, list[Student]]) -> Student | None:
    moodle = MOODLE_DOWNLOAD.fullmatch(name)
    if moodle:   # its number is Moodle's participant number, never a Canvas id or a student id
        return _first_unique([f"moodle:{moodle['participant']}", _norm(moodle["name"])], index)
    candidates = [_norm(name)]
    # Canvas downloads: "doejane_12345_67890_EnvironmentMap.cpp" or "doejane_LATE_12345_...".
    parts = [p for p in re.split(r"[_\-\s.]+", name) if p]
    candidates += [f"canvas:{p}" for p in parts if p.isdigit()]
    candidates += [_norm(p) for p in parts]
    return _first_unique(candidates, index)


def _first_unique(candidates: list[str], index: dict[str, list[Student]]) -> Student | None:
    for key in candidates:
        found = index.get(key, [])
        if len(found) == 1:
            return found[0]
    return None


def _column(headers: dict[str, str], wanted: tuple[str, ...]) -> str | None:
    for name in wanted:
        if name in headers:
            return headers[name]
    return None


def load_roster(path: Path) -> Roster:
    """Read a roster CSV (UTF-8, with or without Excel's byte-order mark)."""
    path = Path(path)
    try:
        if path.stat().st_size > MAX_ROSTER_BYTES:
            raise RosterError(f"{path}: larger than {MAX_ROSTER_BYTES >> 20} MB; is it a roster?")
        text = path.read_bytes().decode("utf-8-sig")
    except OSError as e:
        raise RosterError(f"{path}: {e.strerror or e}") from None
    except UnicodeDecodeError:
        raise RosterError(f"{path}: not UTF-8 text (save the roster as CSV UTF-8)") from None
    reader = csv.DictReader(io.StringIO(text))
    if not reader.fieldnames:
        raise RosterError(f"{path}: empty")
    headers = {_norm(h): h for h in reader.fieldnames if h}
    id_col = _column(headers, ID_COLUMNS)
    email_col = _column(headers, EMAIL_COLUMNS)
    login_col = _column(headers, LOGIN_COLUMNS)
    participant_col = headers.get(MOODLE_IDENTIFIER)
    name_col = _column(headers, NAME_COLUMNS)
    first_col, last_col = _column(headers, FIRST_COLUMNS), _column(headers, LAST_COLUMNS)
    section_col = _column(headers, SECTION_COLUMNS)
    role_col = headers.get(ROLE_COLUMN)
    # Canvas: "ID" is its own user id, "SIS User ID" the university's: prefer the latter as the id.
    canvas_col = headers.get(CANVAS_ID) if "sisuserid" in headers else None
    if canvas_col and id_col == canvas_col:
        id_col = headers["sisuserid"]
    if not (id_col or email_col or login_col or name_col or first_col):
        raise RosterError(f"{path}: no column to match students by (expected one of: SID, Student ID, ID, "
                          f"Email, Name, First Name/Last Name, Student; found: {', '.join(reader.fieldnames)})")
    # A Canvas export names each assignment's column "Name (assignment id)".
    assignments = [h for h in reader.fieldnames if h and canvas_col and CANVAS_ASSIGNMENT.fullmatch(h.strip())]
    students, left_out, points = [], [], {}
    for row in reader:
        def get(col):
            return (row.get(col) or "").strip() if col else ""
        name = get(name_col) or " ".join(x for x in (get(first_col), get(last_col)) if x)
        if name.strip().lower() == "points possible":   # Canvas's second row
            points = {a: float(get(a)) for a in assignments if _is_number(get(a))}
            continue
        if get(role_col) and _norm(get(role_col)) != "student":
            left_out.append({"why": "role", "name": name, "role": get(role_col)})
            continue
        if _norm(name) in CANVAS_TEST_STUDENT:
            left_out.append({"why": "test-student", "name": name})
            continue
        login = get(login_col)
        email = get(email_col) or (login if "@" in login else "")
        participant = re.sub(r"\D", "", get(participant_col))
        student = Student(get(id_col), name, email, get(canvas_col), get(section_col), login, participant)
        if student.id or student.email or student.login or student.name:
            students.append(student)
    columns = {k: v for k, v in (("id", id_col), ("name", name_col or first_col), ("email", email_col),
                                 ("login", login_col)) if v}
    moodle_items = [h.strip() for h in reader.fieldnames if h and MOODLE_ASSIGNMENT.fullmatch(h.strip())]
    return Roster(students, columns, left_out, assignments, points, moodle_items)


def left_out_text(entry: dict | str) -> str:
    """A row left out of the roster, with why, in the current language (an
    entry without a known key, from an older grader's summary.json: as it
    was written)."""
    if isinstance(entry, dict) and entry.get("why") in LEFT_OUT:
        return LEFT_OUT[entry["why"]] % {"name": str(entry.get("name", "")), "role": str(entry.get("role", ""))}
    return str(entry)


def _is_number(text: str) -> bool:
    try:
        return float(text) >= 0
    except ValueError:
        return False

