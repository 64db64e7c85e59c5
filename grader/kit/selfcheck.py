"""The student kit's self-check: the grader itself on the student's machine.

    python -m grader.kit.selfcheck --out build/selfcheck [--fail-under PERCENT]

run from the kit's root (`make selfcheck` does, through selfcheck/bootstrap.py,
with the kit's copy of the grader, selfcheck/grader/, on PYTHONPATH). It
grades the kit's EnvironmentMap.cpp with grader.grading.grade.grade(), the grader's
own path: the same build (a refused source is refused the same way), the
worker, the checks the rubric makes visible (speed left out), the rubric's
points and the grader's report writers. Two things differ from grading on
submission, and only these: the lookup's answers come from the recording
made when the kit was built (grader.envmap.oracle.Replay; the kit holds no lookup),
so the inputs are the kit's public ones (seed KIT_SEED, no secret); and the
worker runs without a sandbox where this machine has none (the student's
own code on the student's own machine), in bubblewrap where it has one.

Writes into OUT the grader's reports (report.html, report.md, junit.xml,
results.json) and selfcheck.json (the same as results.json, the name the
kit's workflow reads). Exit status: 0 when the checks ran; 1 when the file
did not compile, or with --fail-under when the score is below that
percentage of the visible points; 3 when the self-check itself failed
(ungradable: not the student's fault) or the kit's own files were changed
(integrity.py: no score then).
"""
from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

from .. import PROJECT_ROOT
from ..i18n.languages import CODES
from . import ANSWERS, KIT_SEED, NOT_IN_KIT, integrity

SOURCE = Path("EnvironmentMap.cpp")
# Where the self-check ran without a sandbox: the student's own code on
# their own machine. One quiet line says so (reports/view.py ISOLATION_TEXT);
# the grader's warning for that case (worker/sandbox.py fallback_warning,
# written for an instructor's --unsafe-no-sandbox) read as an alarm here.
OWN_MACHINE, UNSAFE_NONE = "own-machine", "unsafe-none"
FALLBACK_WARNING = "sandbox unavailable: "
SUMMARY = "selfcheck.json"
# What grade() writes into OUT, with SUMMARY.
REPORTS = ("results.json", "report.html", "report.md", "junit.xml")


def kit_options(rubric: Path | None = None, lang: str | None = None):
    """The GradeOptions of the self-check: those of `grade --kit-inputs`, and
    a worker that may run unconfined where no isolation is possible."""
    from ..grading.grade import GradeOptions
    from ..grading.score import load_rubric
    options = GradeOptions(sandbox=None, allow_unsafe=True, include_hidden=False, seed=KIT_SEED, lang=lang)
    if rubric is not None:
        options.rubric = rubric
    entries = load_rubric(options.rubric).get("checks", {})
    options.only = tuple(n for n, e in entries.items() if e.get("visibility", "visible") == "visible"
                         and n not in NOT_IN_KIT)
    # The kit carries the fixture renders but not fixtures/manifest.json (it
    # hashes the reference's lookup.c): the kit build checked they are fresh.
    options.allow_stale = True
    return options


def quiet_about_own_machine(result) -> None:
    """No sandbox on the student's own machine: said once, quietly, as the
    isolation line; the grader's warning for it is left out."""
    if result.isolation == UNSAFE_NONE:
        result.isolation = OWN_MACHINE
        result.warnings = [w for w in result.warnings if not w.startswith(FALLBACK_WARNING)]


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="make selfcheck", description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=Path, default=Path("build/selfcheck"), help="report folder (default: build/selfcheck)")
    p.add_argument("--fail-under", type=float, metavar="PERCENT",
                   help="exit with status 1 when the score is below PERCENT of the visible points")
    p.add_argument("--source", type=Path, default=SOURCE, help="the file to check (default: EnvironmentMap.cpp)")
    p.add_argument("--lang", choices=CODES, help="the reports' language (default: the course's)")
    args = p.parse_args(argv)
    if args.fail_under is not None and not 0 <= args.fail_under <= 100:
        p.error("--fail-under is a percentage of the visible points, from 0 to 100")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if not args.source.is_file():
        print(f"selfcheck: {args.source} not found: run it from the kit's folder", file=sys.stderr)
        return 2
    changed = integrity.changed_files(PROJECT_ROOT)
    if changed:
        for name in (SUMMARY, *REPORTS):       # no earlier score left to read
            (args.out / name).unlink(missing_ok=True)
        print("selfcheck: the kit's own files in selfcheck/ are not as the kit was built, so its score would not be "
              f"the grader's; no score given. Changed: {', '.join(changed[:10])}"
              f"{' ...' if len(changed) > 10 else ''}. Unpack the kit again (keep your EnvironmentMap.cpp).",
              file=sys.stderr)
        return 3
    edited = integrity.edited_api_files(args.source.resolve().parent, PROJECT_ROOT)
    if edited:
        print(f"selfcheck: {', '.join(edited)} here {'is' if len(edited) == 1 else 'are'} not the course's: the "
              "self-check, like grading, compiles EnvironmentMap.cpp with the course's copies "
              "(selfcheck/student_template/).", file=sys.stderr)
    from ..envmap import oracle
    from ..grading.grade import grade, write_harness_log
    from ..grading.results import BUILD_ERROR, UNGRADABLE
    from ..reports import write_all
    from ..reports.terminal import print_summary
    options = kit_options(lang=args.lang)
    with oracle.using(oracle.Replay(PROJECT_ROOT / ANSWERS)):
        result = grade(args.source, args.out, options, write_reports=False)
    quiet_about_own_machine(result)
    write_all(result, args.out, include_hidden=options.include_hidden)
    write_harness_log(result, args.out)
    shutil.copyfile(args.out / "results.json", args.out / SUMMARY)
    print_summary(result, report_paths={name: args.out / name for name in ("report.html", "report.md")})
    if result.status == UNGRADABLE:
        return 3
    if result.status == BUILD_ERROR:
        return 1
    if args.fail_under is not None and result.score < args.fail_under / 100 * result.max_score - 1e-9:
        print(f"selfcheck: {result.score:g} of {result.max_score:g} points is below FAIL_UNDER={args.fail_under:g}%")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
