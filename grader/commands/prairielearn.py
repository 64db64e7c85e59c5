"""`python -m grader prairielearn`: PrairieLearn's external-grader entry point.

Grades ROOT/student (default /grade/student) and writes
ROOT/results/results.json in PrairieLearn's format: score 0..1, gradable,
message and output (plain text), tests[] (points, max_points, output) and
images[] (the renders and arrow pictures as PNG data URLs, within
PrairieLearn's 1 MB). Exit status 0 whenever results.json was written,
whatever the grade (gradable: false says the grader failed). PrairieLearn
runs it through grader/platforms/prairielearn/entrypoint.sh;
docs/platforms.md has the image and the question's info.json.

    python -m grader prairielearn --check-question questions/envmap/info.json

checks a question's info.json before students use it: external grading on,
envmap/ among serverFilesCourse, the entry point, and a timeout long enough
for a cold job (PrairieLearn never tells the job its timeout; each job's log
says how long it took).
"""
from __future__ import annotations

import argparse
from pathlib import Path

from . import options

HELP = "grade /grade/student for PrairieLearn's external grader (writes /grade/results/results.json)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.description = __doc__.split("\n", 1)[1].strip("\n")
    p.add_argument("--root", type=Path, default=Path("/grade"),
                   help="PrairieLearn's grading folder (default: /grade)")
    options.quick(p)
    options.language(p)
    p.add_argument("--check-question", type=Path, metavar="INFO_JSON",
                   help="instead: check a question's info.json (timeout, entry point, serverFilesCourse)")
    p.add_argument("--keep-reports", action="store_true",
                   help="also copy report.html, report.md and junit.xml to ROOT/results/reports/")


def run(args) -> int:
    if args.check_question is not None:
        from ..platforms.prairielearn import check_question
        problems = check_question(args.check_question)
        for problem in problems:
            print(f"prairielearn: {problem}")
        if not problems:
            print(f"{args.check_question}: external grading, entry point, serverFilesCourse and timeout are as "
                  "docs/platforms.md sets them")
        return 1 if problems else 0
    from ..i18n import override_from_command_line
    from ..platforms.prairielearn import grade_prairielearn
    override_from_command_line(args.lang)
    data = grade_prairielearn(args.root, quick=args.quick, keep_reports=args.keep_reports)
    print(f"{args.root / 'results' / 'results.json'}: score {data['score']:g}, gradable {data['gradable']}")
    return 0
