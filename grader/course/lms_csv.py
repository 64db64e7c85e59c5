"""Grade files that Canvas, Moodle and Gradescope import as they are, written
by `grade-all --roster` beside gradebook.csv. One file per LMS, since each
finds students by its own columns:

    grades_canvas.csv      Canvas, Grades -> Import: Student, ID, SIS User ID, SIS Login ID and
                           Section (the columns of Canvas's own export; it finds each student by one
                           of the first three), a "Points Possible" row, then the assignment's
                           column. A column name Canvas does not know creates a new assignment; to
                           fill an existing one, name it as Canvas's export does
                           (--assignment "Environment map (1234)").
    grades_moodle.csv      Moodle, Grades -> Import -> CSV file: under "Identify user by", map
                           "Email address" to Email address (or "ID number" to ID number), and
                           the assignment's column to its grade item.
    grades_gradescope.csv  Gradescope's own score columns (Name, SID, Email, Total Score, Max
                           Points, Status), for an assignment graded outside it.

Only the roster's students are in them: a submission that matches no one has
nothing to be imported by (grade-all prints it). A student who handed in
nothing, or whom the grader could not grade, has a blank score, which an
import leaves alone rather than overwriting with 0.
"""
from __future__ import annotations

import csv
import io
from pathlib import Path

from ..grading.results import UNGRADABLE
from .class_files import MISSING, cell, write_text_atomic

DEFAULT_ASSIGNMENT = "Environment map"
CANVAS, MOODLE, GRADESCOPE = "grades_canvas.csv", "grades_moodle.csv", "grades_gradescope.csv"
FILES = (CANVAS, MOODLE, GRADESCOPE)


def _score(row) -> str:
    return "" if row.status in (MISSING, UNGRADABLE) else f"{row.score:g}"


def _csv(header: list[str], lines: list[list[str]]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\r\n")   # RFC 4180, as the LMSs write their own
    w.writerow(header)
    w.writerows([[cell(str(v)) for v in line] for line in lines])
    return buf.getvalue()


def canvas(entries, max_score: float, assignment: str) -> str:
    lines = [["    Points Possible", "", "", "", "", f"{max_score:g}"]]
    lines += [[st.name, st.canvas_id, st.id, st.email, st.section, _score(row)] for row, st in entries]
    return _csv(["Student", "ID", "SIS User ID", "SIS Login ID", "Section", assignment], lines)


def moodle(entries, assignment: str) -> str:
    return _csv(["Full name", "Email address", "ID number", assignment],
                [[st.name, st.email, st.id, _score(row)] for row, st in entries])


def gradescope(entries, max_score: float) -> str:
    return _csv(["Name", "SID", "Email", "Total Score", "Max Points", "Status"],
                [[st.name, st.id, st.email, _score(row), f"{max_score:g}",
                  "Missing" if row.status == MISSING else "Graded" if _score(row) else "Ungraded"]
                 for row, st in entries])


def write_lms_files(entries, out: Path, assignment: str = DEFAULT_ASSIGNMENT) -> list[Path]:
    """entries: (gradebook row, roster student) for every student on the
    roster, in gradebook order. Returns the files written."""
    max_score = max([row.max_score for row, _ in entries] + [0.0])
    files = {CANVAS: canvas(entries, max_score, assignment), MOODLE: moodle(entries, assignment),
             GRADESCOPE: gradescope(entries, max_score)}
    for name, text in files.items():
        write_text_atomic(Path(out) / name, text)
    return [Path(out) / name for name in files]
