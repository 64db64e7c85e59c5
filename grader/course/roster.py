"""A class roster (CSV) for grade-all: who each submission belongs to, so the
gradebook carries the student id and email an LMS imports by.

Accepted exports (columns matched by name, case and spacing ignored):

    Gradescope roster / grades   "First Name", "Last Name" or "Name", "SID", "Email"
    Canvas gradebook              "Student" ("Last, First"), "ID", "SIS User ID", "SIS Login ID"
                                  (its "Points Possible" row is skipped)
    anything else                 "id" / "student id" / "student_id", "name", "email"

A submission (a folder or archive name in the class folder) is matched to
a roster row by, in order: the student id, the email or its local part,
Canvas's user id inside a Canvas download name ("doejane_12345_67890_...
"), the name with everything but letters and digits removed ("Jane Doe",
"jane_doe", "doe_jane", "doejane", "janedoe"). A name that two rows share
matches neither: an ambiguous match is worse than none.

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

# Header names, normalised (lower case, letters and digits only), by what they hold.
ID_COLUMNS = ("sid", "studentid", "sisuserid", "studentnumber", "matriculationnumber", "id", "userid")
EMAIL_COLUMNS = ("email", "emailaddress", "email1", "sisloginid", "loginid")
NAME_COLUMNS = ("name", "fullname", "student", "studentname")
FIRST_COLUMNS = ("firstname", "givenname")
LAST_COLUMNS = ("lastname", "surname", "familyname")
SECTION_COLUMNS = ("section", "sections", "group")
# Canvas's test student, as its exports name it (normalised: letters only).
CANVAS_TEST_STUDENT = ("studenttest", "teststudent")
CANVAS_ID = "id"            # Canvas's own user id, part of its download file names
MAX_ROSTER_BYTES = 10 << 20


class RosterError(Exception):
    """The roster cannot be read or has no column to match by."""


@dataclass(frozen=True)
class Student:
    id: str
    name: str
    email: str
    canvas_id: str = ""
    section: str = ""       # Canvas's import wants it back


@dataclass
class Roster:
    students: list[Student]
    columns: dict[str, str] = field(default_factory=dict)   # what -> the header it came from
    left_out: list[str] = field(default_factory=list)       # rows that are no one, and why
    assignments: list[str] = field(default_factory=list)    # Canvas's assignment columns, "Name (id)"

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
    keys = [_norm(s.id), _norm(s.email), _norm(s.email.split("@")[0]) if "@" in s.email else ""]
    words = [w for w in re.split(r"[\s,]+", s.name.casefold()) if w]
    if words:
        keys += [_norm("".join(words)), _norm("".join(reversed(words)))]
        if "," in s.name:   # Canvas: "Doe, Jane" -> janedoe as well
            last, _, first = s.name.partition(",")
            keys += [_norm(first + last), _norm(last + first)]
    keys = [k for k in keys if k]
    # Canvas's user id, found inside its download names (see _lookup).
    return keys + ([f"canvas:{s.canvas_id}"] if s.canvas_id else [])


def _lookup(name: str, index: dict[str, list[Student]]) -> Student | None:
    candidates = [_norm(name)]
    # Canvas downloads: "doejane_12345_67890_EnvironmentMap.cpp" or "doejane_LATE_12345_...".
    parts = [p for p in re.split(r"[_\-\s.]+", name) if p]
    candidates += [f"canvas:{p}" for p in parts if p.isdigit()]
    candidates += [_norm(p) for p in parts]
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
    name_col = _column(headers, NAME_COLUMNS)
    first_col, last_col = _column(headers, FIRST_COLUMNS), _column(headers, LAST_COLUMNS)
    section_col = _column(headers, SECTION_COLUMNS)
    # Canvas: "ID" is its own user id, "SIS User ID" the university's: prefer the latter as the id.
    canvas_col = headers.get(CANVAS_ID) if "sisuserid" in headers else None
    if canvas_col and id_col == canvas_col:
        id_col = headers["sisuserid"]
    if not (id_col or email_col or name_col or first_col):
        raise RosterError(f"{path}: no column to match students by (expected one of: SID, Student ID, ID, "
                          f"Email, Name, First Name/Last Name, Student; found: {', '.join(reader.fieldnames)})")
    students, left_out = [], []
    for row in reader:
        def get(col):
            return (row.get(col) or "").strip() if col else ""
        name = get(name_col) or " ".join(x for x in (get(first_col), get(last_col)) if x)
        if name.strip().lower() == "points possible":
            continue   # Canvas's second row
        if _norm(name) in CANVAS_TEST_STUDENT:
            left_out.append(f"{name}: Canvas's test student (Student View), not a student")
            continue
        student = Student(get(id_col), name, get(email_col), get(canvas_col), get(section_col))
        if student.id or student.email or student.name:
            students.append(student)
    columns = {k: v for k, v in (("id", id_col), ("name", name_col or first_col), ("email", email_col)) if v}
    # A Canvas export names each assignment's column "Name (assignment id)".
    assignments = [h for h in reader.fieldnames if h and canvas_col and re.fullmatch(r".*\S \(\d+\)", h.strip())]
    return Roster(students, columns, left_out, assignments)

