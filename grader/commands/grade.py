"""`python -m grader grade [SUBMISSION ...]`: grade submissions, write their reports.

    python -m grader grade                          # the examples in examples/
    python -m grader grade alice.zip                # reports in out/alice/
    python -m grader grade src/ --out feedback/ --fail-under 60

A submission is a folder, a .cpp, a .zip or a .tar.gz holding the student's
EnvironmentMap.cpp. Each one's reports (report.html, report.md, junit.xml,
results.json) go to OUT, by default out/<submission name>/. The exit status
is 0 when grading completed, whatever the score (1 with --fail-under SCORE
when a score is below it; 2 for a usage error; 3 when the grader itself
failed and the submission is ungradable, or fixtures/ or the rubric need the
instructor first).
"""
from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path

from .. import PROJECT_ROOT
from . import options

HELP = "grade one submission (a folder, a .cpp, a .zip or a .tar.gz) and write its reports"
EXAMPLES = PROJECT_ROOT / "examples"
REPORTS = ("report.html", "report.md", "junit.xml", "results.json")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.description = __doc__.split("\n", 1)[1].strip("\n")
    p.add_argument("submissions", nargs="*", type=Path, metavar="SUBMISSION",
                   help="what to grade; default: every submission in examples/")
    p.add_argument("--out", type=Path,
                   help="report folder (default: out/<submission name>/; with several submissions, "
                        "OUT/<submission name>/)")
    p.add_argument("--fail-under", type=float, metavar="SCORE",
                   help="exit with status 1 when a score is below SCORE (for CI)")
    p.add_argument("--student-view", action="store_true",
                   help="leave hidden checks out of report.md, report.html and the terminal (what students see)")
    p.add_argument("--visible-only", action="store_true",
                   help="run only the checks the rubric makes visible (students' self-check; "
                        "implies --student-view)")
    p.add_argument("--kit-inputs", action="store_true",
                   help="grade on the student kit's fixed public inputs (its seed; the checks the kit runs): "
                        "what the kit's self-check gives; implies --visible-only")
    p.add_argument("--kit-answers", type=Path, metavar="NPZ",
                   help="with --kit-inputs: the reference's lookup answers from this recording "
                        "(grader.kit.answers) instead of the live reference, as the kit has them")
    options.quick(p)
    p.add_argument("--sanitize", action="store_true", help="build with AddressSanitizer for exact memory-error reports")
    options.isolation(p)
    options.language(p)
    options.allow_stale(p)
    p.add_argument("--strict", action="store_true",
                   help="refuse (exit 3) when library or compiler versions differ from those that made fixtures/")


def example_submissions() -> list[Path]:
    if not EXAMPLES.is_dir():
        return []
    return sorted(p for p in EXAMPLES.iterdir() if p.is_dir() and not p.name.startswith("."))


def output_folders(submissions: list[Path], out: Path | None) -> list[Path]:
    from ..intake import student_name
    names = [student_name(s) for s in submissions]
    if len(set(names)) < len(names):   # e.g. a/EnvironmentMap.cpp and b/EnvironmentMap.cpp
        names = [s.name if names.count(student_name(s)) == 1 else f"{s.parent.name}-{s.name}" for s in submissions]
    if out is not None and len(submissions) == 1:
        return [out]
    base = out if out is not None else PROJECT_ROOT / "out"
    return [base / n for n in names]


def visible_checks(rubric_path: Path) -> tuple[str, ...]:
    from ..grading.score import load_rubric
    entries = load_rubric(rubric_path).get("checks", {})
    return tuple(name for name, e in entries.items() if e.get("visibility", "visible") == "visible")


def run(args) -> int:
    from ..grading.grade import GradeOptions
    from ..worker.sandbox import SandboxUnavailable
    submissions = args.submissions or example_submissions()
    missing = [s for s in submissions if not s.exists()]
    if missing:
        for s in missing:
            print(f"grade: {s} does not exist (expected a folder, a .cpp, a .zip or a .tar.gz)", file=sys.stderr)
        return 2
    if not submissions:
        print(f"grade: nothing to grade: name a submission, or put examples in {EXAMPLES}", file=sys.stderr)
        return 2
    if args.kit_answers is not None and not args.kit_inputs:
        print("grade: --kit-answers needs --kit-inputs (the answers are the kit inputs')", file=sys.stderr)
        return 2
    if args.kit_answers is not None and not args.kit_answers.is_file():
        print(f"grade: {args.kit_answers} does not exist (make it with grader.kit.answers.record)", file=sys.stderr)
        return 2
    args.visible_only = args.visible_only or args.kit_inputs
    student_view = args.student_view or args.visible_only
    options = GradeOptions(sanitize=args.sanitize, sandbox=args.sandbox, allow_stale=args.allow_stale,
                           quick=args.quick, include_hidden=not student_view, allow_unsafe=args.allow_unsafe,
                           lang=args.lang)
    if args.visible_only:
        options.only = visible_checks(options.rubric)
    if args.kit_inputs:
        from ..kit import answers
        options.seed = answers.KIT_SEED
        options.only = tuple(name for name in options.only if name not in answers.NOT_IN_KIT)
    from ..worker.lookups import MODES
    from ..worker.sandbox import resolve_mode
    try:   # before anything is built: no isolation here is the instructor's to fix
        resolve_mode(MODES[args.sandbox], args.allow_unsafe)
    except SandboxUnavailable as e:
        print(f"grade: {e}", file=sys.stderr)
        return 3
    from ..envmap import oracle
    with oracle.using(oracle.Replay(args.kit_answers)) if args.kit_answers else contextlib.nullcontext():
        return _grade_each(args, submissions, options, student_view)


def _grade_each(args, submissions, options, student_view) -> int:
    from ..grading.grade import grade
    from ..worker.sandbox import SandboxUnavailable
    from ..reports.terminal import print_summary
    from ..grading.results import UNGRADABLE
    status, written = 0, []
    from ..grading.fixtures import StaleFixtures
    from ..grading.score import RubricError
    for submission, out in zip(submissions, output_folders(submissions, args.out)):
        try:
            if args.strict:   # EnvironmentMismatch is a StaleFixtures
                from ..grading.fixtures import check_environment
                check_environment()
            result = grade(submission, out, options)
        except (StaleFixtures, RubricError, SandboxUnavailable) as e:   # the instructor's to fix, before anything is graded
            print(f"grade: {e}", file=sys.stderr)
            return 3
        print_summary(result, report_paths={name: out / name for name in ("report.html", "report.md")},
                      include_hidden=not student_view)
        written.append((result, out))
        if result.status == UNGRADABLE:
            status = max(status, 3)
        elif args.fail_under is not None and result.score < args.fail_under:
            status = max(status, 1)
    if len(written) > 1:
        print("\nreports (open report.html in a browser):")
        paths = [_relative(out / "report.html") for _, out in written]
        width = max(len(p) for p in paths)
        for path, (result, _) in zip(paths, written):
            print(f"  {path:{width}s}  {result.score:>6g} / {result.max_score:g}  {result.status}")
    return status


def _relative(path: Path) -> str:
    try:
        return str(path.resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(path)
