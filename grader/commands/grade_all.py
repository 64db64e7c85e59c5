"""`python -m grader grade-all SUBMISSIONS`: grade a class in parallel."""
from __future__ import annotations

import argparse
from pathlib import Path

from .. import PROJECT_ROOT

HELP = "grade every submission in a folder (one sub-folder or archive per student)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("submissions", type=Path, help="folder with one sub-folder or archive per student")
    p.add_argument("--out", type=Path, help="results folder (default: out/<folder name>/)")
    p.add_argument("--jobs", type=int, default=None, help="parallel gradings (default: one per core)")
    p.add_argument("--no-sandbox", dest="sandbox", action="store_false", default=None)
    p.add_argument("--quick", action="store_true", help="smaller direction sets")
    p.add_argument("--no-progress", dest="progress", action="store_false")


def run(args) -> int:
    from ..grade_all import grade_all
    out = args.out or PROJECT_ROOT / "out" / args.submissions.name
    rows = grade_all(args.submissions, out, args.jobs, {"sandbox": args.sandbox, "quick": args.quick}, args.progress)
    print(f"graded {len(rows)} submissions ({sum(r.skipped for r in rows)} unchanged, skipped)")
    print(f"gradebook: {out / 'gradebook.csv'}")
    print(f"summary:   {out / 'summary.md'}")
    return 0
