"""`python -m grader audit [SOLUTION ...]`: how many wrong lookups does the rubric let through?

    python -m grader audit --mutants 300 --jobs 2 --out out/audit

Mutants of the course's correct solutions (examples/perfect and
tests/submissions/correct/ unless SOLUTION files or folders are given), one
token changed in each (an operator, a relation, a constant, a name swapped for
a similar one, a rounding function, a sign), drawn with --seed. Each mutant's
truth is decided against the reference on dense inputs, independently of the
checks (equivalent, wrong, wrong only at extreme lengths, ties or non-square
faces, crashing, hanging, not compiling); then every mutant that compiles is
graded as grade-all grades a class, with the course's rubric or --rubric FILE.

The report (here, OUT/audit.json, OUT/audit.html): the kill rate (wrong
mutants below full marks), the false-fail rate (equivalent ones marked down),
what each check alone catches, and every escaped or falsely failed mutant with
its one-line diff. Exit status 0 when nothing escaped and nothing was falsely
failed, 1 otherwise.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .. import PROJECT_ROOT
from . import options

HELP = "measure the grader: grade single-token mutants of correct solutions and count what escapes"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.description = __doc__.split("\n", 1)[1].strip("\n")
    p.add_argument("solutions", nargs="*", type=Path, metavar="SOLUTION",
                   help="correct solutions (.cpp, or a folder with EnvironmentMap.cpp); default: the course's")
    p.add_argument("--mutants", type=int, default=200, help="mutants drawn (default 200; 0 means all of them)")
    p.add_argument("--seed", type=int, default=0, help="which mutants are drawn (default 0)")
    p.add_argument("--jobs", type=int, default=None, help="mutants judged and graded at once (default: one per core)")
    p.add_argument("--out", type=Path, help="results folder (default: out/audit/)")
    p.add_argument("--rubric", type=Path, help="the rubric to audit (default: grader/grading/rubric.toml)")
    options.quick(p)
    options.isolation(p)
    options.allow_stale(p)
    options.progress(p)


def run(args) -> int:
    from ..course.audit import run_audit
    from ..course.audit.report import summarise, terminal_text
    from ..grading.fixtures import StaleFixtures
    from ..grading.score import RubricError
    from ..worker.lookups import MODES
    from ..worker.sandbox import SandboxUnavailable, resolve_mode
    if args.mutants < 0 or (args.jobs is not None and args.jobs < 1):
        print("audit: --mutants must be at least 0 and --jobs at least 1", file=sys.stderr)
        return 2
    try:
        resolve_mode(MODES[args.sandbox], args.allow_unsafe)
    except SandboxUnavailable as e:
        print(f"audit: {e}", file=sys.stderr)
        return 3
    out = args.out or PROJECT_ROOT / "out" / "audit"
    try:
        result = run_audit(args.solutions or None, mutants=args.mutants or None, seed=args.seed, jobs=args.jobs,
                           out=out, rubric=args.rubric, quick=args.quick, sandbox=args.sandbox,
                           allow_unsafe=args.allow_unsafe, allow_stale=args.allow_stale, progress=args.progress)
    except (RubricError, FileNotFoundError) as e:
        print(f"audit: {e}", file=sys.stderr)
        return 2
    except StaleFixtures as e:
        print(f"audit: {e}", file=sys.stderr)
        return 1
    data = summarise(result)
    print(terminal_text(data))
    print(f"report: {out / 'audit.html'} (and audit.json)")
    return 0 if not data["escaped"] and not data["false_fails"] and data["controls_ok"] else 1
