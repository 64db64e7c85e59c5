"""Grade files that Canvas, Moodle and Gradescope import as they are, written
by `grade-all --roster` beside gradebook.csv. One file per LMS, since each
finds students by its own columns:

    grades_canvas.csv      Canvas, Grades -> Import. Canvas's own export's columns (Student, ID, SIS
                           User ID, SIS Login ID, Section), its "Points Possible" row, then the
                           assignment's column as the export names it, "Environment map (4711)"
                           (a name without Canvas's id would create a new assignment). Scores are
                           scaled to the export's Points Possible (a 10-point assignment gets 0-10).
    grades_moodle.csv      Moodle, Grades -> Import -> CSV file. Under "Identify user by", map
                           "ID number" to ID number or "Email address" to Email address; map the
                           assignment's column to its grade item. Moodle's importer stops the
                           whole import at a row whose student it cannot find, gives a row with a
                           blank identifier to the row before it, and reads a blank grade as "no
                           grade" (erasing one given by hand): a row goes in only with a score
                           and every identifier, and who is left out is said (`left_out`).
    grades_gradescope.csv  Gradescope's own grade export's columns (First Name, Last Name, SID,
                           Email, Total Score, Max Points, Status), for an assignment graded
                           outside it.

Only the roster's students are in them: a submission that matches no one has
nothing to be imported by (grade-all prints it). A student who handed in
nothing has a blank score, which Canvas's import leaves alone, unless the
instructor asks for 0 (`zero_missing`); a student whom the grader could not
grade is always blank (it was not their doing).
"""
from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field
from pathlib import Path

from ..grading.results import UNGRADABLE
from .class_files import MISSING, cell, write_text_atomic

DEFAULT_ASSIGNMENT = "Environment map"
CANVAS, MOODLE, GRADESCOPE = "grades_canvas.csv", "grades_moodle.csv", "grades_gradescope.csv"
FILES = (CANVAS, MOODLE, GRADESCOPE)


@dataclass
class Target:
    """Where the scores go: the assignment's column in each LMS's file and
    Canvas's points for it."""
    canvas_column: str
    moodle_column: str
    canvas_points: float | None          # None: the rubric's total
    zero_missing: bool = False
    notes: list[str] = field(default_factory=list)   # what the instructor should know before importing


class TargetError(Exception):
    """The roster's export does not say which assignment to fill."""


def choose_target(roster, assignment: str | None, zero_missing: bool = False) -> Target:
    """The assignment column each file fills, from --assignment and the
    roster's own export (a Canvas export's "Name (id)" columns, a Moodle
    export's "Assignment: Name (Real)" columns)."""
    from .roster import CANVAS_ASSIGNMENT, MOODLE_ASSIGNMENT
    notes: list[str] = []
    canvas = _pick(roster.assignments, assignment, lambda h: CANVAS_ASSIGNMENT.fullmatch(h)["name"], "Canvas")
    if canvas is None:
        canvas = assignment or DEFAULT_ASSIGNMENT
        if roster.assignments:
            notes.append(f"{CANVAS}: the Canvas export has no assignment named {canvas!r}: Canvas will create "
                         "a new assignment of that name")
    def plain(name):   # the name without Canvas's id
        return CANVAS_ASSIGNMENT.fullmatch(name)["name"] if CANVAS_ASSIGNMENT.fullmatch(name) else name
    moodle = _pick(roster.moodle_items, assignment and plain(assignment),
                   lambda h: MOODLE_ASSIGNMENT.fullmatch(h)["name"], "Moodle") or plain(canvas)
    points = roster.points_possible.get(canvas)
    return Target(canvas, moodle, points, zero_missing, notes)


def _pick(columns: list[str], wanted: str | None, name_of, lms: str) -> str | None:
    """The export's column for `wanted` (its full header, or its name without
    the LMS's decoration); with nothing wanted, the only column or the one
    named DEFAULT_ASSIGNMENT. None when the export has no such column."""
    if not columns:
        return None
    if wanted is None and len(columns) == 1:
        return columns[0]
    key = (wanted or DEFAULT_ASSIGNMENT).strip().casefold()
    found = [c for c in columns if c.casefold() == key] or [c for c in columns if name_of(c).casefold() == key]
    if len(found) == 1:
        return found[0]
    if wanted is None or len(found) > 1:
        raise TargetError(f"the {lms} export has {len(columns)} assignments ({', '.join(columns)}); name the one "
                          "to fill with --assignment")
    return None


def _missing(row) -> bool:
    return row.status == MISSING


def _score(row, target: Target, scale_to: float | None = None) -> str:
    """The cell: blank when there is nothing to import (ungradable; nothing
    handed in unless 0 was asked for), else the score, scaled to `scale_to`
    points when given."""
    if row.status == UNGRADABLE or (_missing(row) and not target.zero_missing):
        return ""
    if _missing(row) or row.max_score <= 0:
        return "0"
    score = row.score if scale_to is None else row.score * scale_to / row.max_score
    return f"{round(score, 2):g}"


def _csv(header: list[str], lines: list[list[str]]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\r\n")   # RFC 4180, as the LMSs write their own
    w.writerow(header)
    w.writerows([[cell(str(v)) for v in line] for line in lines])
    return buf.getvalue()


def canvas(entries, max_score: float, target: Target) -> str:
    points = max_score if target.canvas_points is None else target.canvas_points
    lines = [["    Points Possible", "", "", "", "", f"{points:g}"]]
    lines += [[st.name, st.canvas_id, st.id, st.login or st.email, st.section, _score(row, target, points)]
              for row, st in entries]
    return _csv(["Student", "ID", "SIS User ID", "SIS Login ID", "Section", target.canvas_column], lines)


def moodle(entries, target: Target, left_out: list[dict]) -> str:
    # The identifier columns the roster has for anyone; a row needs each of them.
    ids = [(h, f) for h, f in (("ID number", "id"), ("Email address", "email"))
           if any(getattr(st, f) for _, st in entries)]
    lines = []
    for row, st in entries:
        score = _score(row, target)
        lacking = [h for h, f in ids if not getattr(st, f)]
        if score and not lacking:
            lines.append([st.name, *[getattr(st, f) for _, f in ids], score])
        elif score:
            left_out.append({"file": MOODLE, "student": st.name or st.id or st.email,
                             "why": f"no {' or '.join(lacking)} to be found by"})
    return _csv(["Full name", *[h for h, _ in ids], target.moodle_column], lines)


def gradescope(entries, max_score: float, target: Target) -> str:
    lines = []
    for row, st in entries:
        first, last = _first_last(st.name)
        score = _score(row, target)
        status = "Missing" if _missing(row) else "Graded" if score else "Ungraded"
        lines.append([first, last, st.id, st.email, score, f"{max_score:g}", status])
    return _csv(["First Name", "Last Name", "SID", "Email", "Total Score", "Max Points", "Status"], lines)


def _first_last(name: str) -> tuple[str, str]:
    """Gradescope's two name columns from a roster's one: Canvas's "Last,
    First" or "First Last" (the last word as the last name)."""
    if "," in name:
        last, _, first = name.partition(",")
        return first.strip(), last.strip()
    first, _, last = name.strip().rpartition(" ")
    return (first, last) if first else (last, "")


def write_lms_files(entries, out: Path, target: Target) -> tuple[list[Path], list[dict]]:
    """entries: (gradebook row, roster student) for every student on the
    roster, in gradebook order. Returns the files written and the students
    left out of one, with the reason."""
    max_score = max([row.max_score for row, _ in entries] + [0.0])
    left_out: list[dict] = []
    files = {CANVAS: canvas(entries, max_score, target), MOODLE: moodle(entries, target, left_out),
             GRADESCOPE: gradescope(entries, max_score, target)}
    for name, text in files.items():
        write_text_atomic(Path(out) / name, text)
    return [Path(out) / name for name in files], left_out
