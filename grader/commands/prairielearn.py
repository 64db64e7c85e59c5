"""`python -m grader prairielearn`: PrairieLearn's external-grader entry point.

Grades ROOT/student (default /grade/student) and writes
ROOT/results/results.json in PrairieLearn's format: score 0..1, gradable,
message and output (plain text), tests[] (points, max_points, output) and
images[] (the renders and arrow pictures as PNG data URLs, within
PrairieLearn's 1 MB). Exit status 0 whenever results.json was written,
whatever the grade (gradable: false says the grader failed). PrairieLearn
runs it through grader/platforms/prairielearn/entrypoint.sh;
docs/platforms.md has the image and the question's info.json.
"""
from __future__ import annotations

import argparse
from pathlib import Path

HELP = "grade /grade/student for PrairieLearn's external grader (writes /grade/results/results.json)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.description = __doc__.split("\n", 1)[1].strip("\n")
    p.add_argument("--root", type=Path, default=Path("/grade"),
                   help="PrairieLearn's grading folder (default: /grade)")
    p.add_argument("--quick", action="store_true", help="smaller direction sets (for trying the grader out)")
    p.add_argument("--lang", choices=("en", "ja"),
                   help="language of what students read (default: the rubric's grading.language)")
    p.add_argument("--keep-reports", action="store_true",
                   help="also copy report.html, report.md and junit.xml to ROOT/results/reports/")


def run(args) -> int:
    from ..i18n import override_from_command_line
    from ..platforms.prairielearn import grade_prairielearn
    override_from_command_line(args.lang)
    data = grade_prairielearn(args.root, quick=args.quick, keep_reports=args.keep_reports)
    print(f"{args.root / 'results' / 'results.json'}: score {data['score']:g}, gradable {data['gradable']}")
    return 0
