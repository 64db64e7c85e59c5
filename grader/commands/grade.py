"""`python -m grader grade [SUBMISSION ...]`: grade submissions, write their reports."""
from __future__ import annotations

import argparse
from pathlib import Path

from .. import PROJECT_ROOT

HELP = "grade one submission (a folder, a .cpp, a .zip or a .tar.gz) and write its reports"
EXAMPLES = PROJECT_ROOT / "examples"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("submissions", nargs="*", type=Path,
                   help="what to grade; default: every submission in examples/")
    p.add_argument("--out", type=Path, help="report folder (default: out/<submission name>/)")
    p.add_argument("--sanitize", action="store_true", help="build with AddressSanitizer for exact memory-error reports")
    p.add_argument("--no-sandbox", dest="sandbox", action="store_false", default=None,
                   help="run the worker with resource limits only (no bubblewrap)")
    p.add_argument("--allow-stale", action="store_true", help="grade even when fixtures/ is stale")
    p.add_argument("--quick", action="store_true", help="smaller direction sets (for trying the grader out)")
    p.add_argument("--student-view", action="store_true",
                   help="leave hidden checks out of report.md and report.html (what students see)")
    p.add_argument("--fail-under", type=float, metavar="SCORE",
                   help="exit with status 1 when a score is below SCORE (for CI)")


def example_submissions() -> list[Path]:
    return sorted(p for p in EXAMPLES.iterdir() if not p.name.startswith((".", "README")))


def run(args) -> int:
    from ..grade import GradeOptions, grade
    from ..reports.terminal import print_summary
    submissions = args.submissions or example_submissions()
    if args.out and len(submissions) > 1:
        outs = [args.out / s.stem for s in submissions]
    else:
        outs = [args.out or PROJECT_ROOT / "out" / s.name.split(".")[0] for s in submissions]
    options = GradeOptions(sanitize=args.sanitize, sandbox=args.sandbox, allow_stale=args.allow_stale, quick=args.quick,
                           include_hidden=not args.student_view)
    status = 0
    for submission, out in zip(submissions, outs):
        if not submission.exists():
            print(f"error: {submission} does not exist")
            return 2
        result = grade(submission, out, options)
        print_summary(result, report_paths={name: out / name for name in ("report.html", "report.md", "results.json")},
                      include_hidden=not args.student_view)
        if args.fail_under is not None and result.score < args.fail_under:
            status = 1
    return status
