"""`python -m grader grade-all SUBMISSIONS`: grade a class in parallel.

    python -m grader grade-all submissions/ --out out/class/ --jobs 2

SUBMISSIONS holds one entry per student: a folder, a .zip, a .tar.gz or a
.cpp, named after the student. Each student's reports go to
OUT/<student>/ as soon as they are graded; OUT/gradebook.csv and the class
summary (OUT/summary.html, summary.md) are written at the end. Interrupted
(Ctrl-C, a reboot) and run again, it grades only what is missing or changed.

    python -m grader grade-all submissions/ --roster roster.csv --similarity

--roster adds student_id, name and email columns to the gradebook (a
Gradescope or Canvas export, or any CSV with id, name and email columns), a
row for each student who handed nothing in, and grade files that Canvas,
Moodle and Gradescope import as they are (grades_canvas.csv,
grades_moodle.csv, grades_gradescope.csv). A Canvas or Moodle export as
roster names the assignment's column and Canvas's points; --assignment
picks one when the export has several. Moodle's and Canvas's download
names are matched to the roster. Canvas's test student is left out. Unmatched and missing students are
printed. --similarity compares every
pair of submissions (copydetect, the template's starter code left out) and
lists the most similar pairs with their shared passages in the summary.
Entries of SUBMISSIONS that are not submissions are listed with the reason.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .. import PROJECT_ROOT
from . import options

HELP = "grade every submission in a folder (one sub-folder or archive per student)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.description = __doc__.split("\n", 1)[1].strip("\n")
    p.add_argument("submissions", type=Path, metavar="SUBMISSIONS",
                   help="folder with one sub-folder, .zip, .tar.gz or .cpp per student")
    p.add_argument("--out", type=Path, help="results folder (default: out/<folder name>/)")
    p.add_argument("--jobs", type=int, default=None, help="submissions graded at once (default: one per core)")
    p.add_argument("--force", action="store_true", help="regrade everything, even what is unchanged")
    options.quick(p)
    options.isolation(p)
    options.language(p)
    options.allow_stale(p)
    options.progress(p)
    p.add_argument("--roster", type=Path, metavar="CSV",
                   help="class roster (student id, name, email; Gradescope or Canvas export): adds those "
                        "columns to gradebook.csv")
    p.add_argument("--assignment", metavar="NAME",
                   help="the assignment's column in the LMS grade files (default: 'Environment map'; for "
                        "Canvas, its export's name, e.g. 'Environment map (1234)', fills that assignment)")
    p.add_argument("--zero-missing", action="store_true",
                   help="in the LMS grade files, 0 for a roster's student who handed in nothing (default: blank, "
                        "which Canvas leaves as it was and Moodle's file leaves out)")
    p.add_argument("--similarity", action="store_true",
                   help="compare the submissions with each other (starter code excluded) and list the most "
                        "similar pairs in the summary")


def run(args) -> int:
    from ..grading.fixtures import StaleFixtures
    from ..course.grade_all import DISTURBED, Interrupted, find_submissions, grade_all, skipped_entries
    from ..reports.class_summary import entry_text
    from ..reports.text import clean
    from ..course.lms_csv import TargetError
    from ..course.roster import RosterError, left_out_text
    from ..course.similarity import SimilarityUnavailable
    if not args.submissions.is_dir():
        print(f"grade-all: {args.submissions} is not a folder (expected one sub-folder or archive per student)",
              file=sys.stderr)
        return 2
    if args.jobs is not None and args.jobs < 1:
        print("grade-all: --jobs must be at least 1", file=sys.stderr)
        return 2
    if not find_submissions(args.submissions):
        print(f"grade-all: no submissions in {args.submissions} (expected one sub-folder, .zip, .tar.gz "
              "or .cpp per student)", file=sys.stderr)
        return 2
    out = args.out or PROJECT_ROOT / "out" / args.submissions.resolve().name
    from ..worker.lookups import MODES
    from ..worker.sandbox import SandboxUnavailable, resolve_mode
    try:   # before anything is graded: no isolation here is the instructor's to fix
        resolve_mode(MODES[args.sandbox], args.allow_unsafe)
    except SandboxUnavailable as e:
        print(f"grade-all: {e}", file=sys.stderr)
        return 3
    options = {"sandbox": args.sandbox, "quick": args.quick, "allow_stale": args.allow_stale,
               "allow_unsafe": args.allow_unsafe, "lang": args.lang}
    try:
        rows = grade_all(args.submissions, out, args.jobs, options, args.progress, force=args.force,
                         roster=args.roster, similarity=args.similarity, assignment=args.assignment,
                         zero_missing=args.zero_missing)
    except (RosterError, TargetError) as e:
        print(f"grade-all: roster: {e}", file=sys.stderr)
        return 2
    except SimilarityUnavailable as e:
        print(f"grade-all: {e}", file=sys.stderr)
        return 2
    except StaleFixtures as e:
        print(f"grade-all: {e}", file=sys.stderr)
        return 1
    except Interrupted as e:
        print(f"grade-all: {e}; what was graded is kept in {out}. Run the same command again to finish.",
              file=sys.stderr)
        return 130
    skipped = sum(r.skipped for r in rows)
    by_status: dict[str, int] = {}
    for r in rows:
        by_status[r.status] = by_status.get(r.status, 0) + 1
    print(f"{len(rows)} submissions ({len(rows) - skipped} graded now, {skipped} unchanged and kept): "
          + ", ".join(f"{n} {s}" for s, n in sorted(by_status.items())))
    for r in rows:
        if r.error:
            print(f"  {clean(r.student)}: ungradable: {clean(r.error)}", file=sys.stderr)
    summary = _summary_data(out)
    own = set((summary.get("own_timeouts") or {}).get("students") or [])
    disturbed = [r for r in rows if r.status in DISTURBED and r.student not in own]
    if own:
        print(f"  {len(own)} timeout{'' if len(own) == 1 else 's'} kept ({', '.join(sorted(clean(s) for s in own))}): "
              f"{summary['own_timeouts']['why']}.")
    if disturbed:
        print(f"  {len(disturbed)} {'result says' if len(disturbed) == 1 else 'results say'} "
              f"{' or '.join(DISTURBED)}, which another process can cause: running the same command again "
              "grades them again (and keeps the rest).")
    for entry in skipped_entries(args.submissions, exclude=out):
        # Names a student chose: no escapes to the terminal, no undecodable bytes to print.
        print(f"  skipped {clean(entry['entry'])}: {clean(entry['reason'])}")
    roster = summary.get("roster") or {}
    for key, what in (("unmatched", "matches no one on the roster (not in the LMS files)"),
                      ("missing", "handed in nothing"), ("left_out", "left out of the roster")):
        for entry in roster.get(key) or []:
            print(f"  {what}: {clean(left_out_text(entry) if key == 'left_out' else entry_text(entry))}")
    for entry in roster.get("lms_left_out") or []:
        print(f"  left out of {entry['file']}: {clean(entry['student'])}: {entry['why']}")
    for note in roster.get("lms_notes") or []:
        print(f"  note: {clean(note)}")
    for name in roster.get("lms_files") or []:
        print(f"LMS import: {out / name}")
    print(f"gradebook: {out / 'gradebook.csv'}")
    print(f"summary:   {out / 'summary.html'} (and summary.md)")
    print(f"reports:   {out}/<student>/report.html")
    return 0


def _summary_data(out: Path) -> dict:
    import json
    from ..course.grade_all import SUMMARY_DATA
    try:
        return json.loads((out / SUMMARY_DATA).read_text())
    except (OSError, ValueError):
        return {}

