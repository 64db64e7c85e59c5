"""`python -m grader gradescope`: build autograder.zip for Gradescope.

Upload the zip as a "Zip file upload" autograder (base image Ubuntu 24.04,
which has Python 3.12; on 22.04 setup.sh installs python3.11). Gradescope
runs setup.sh once to build the image, then run_autograder for every
submission, each in its own container. Set the course secret in
grader/grading/rubric.toml ([grading] secret) before building: the zip carries it
to Gradescope, whose students never see the autograder's files.

With --grade, it is what run_autograder calls for each submission: `grade
--student-view` into RESULTS, its results.json's summary as HTML with the
render that differs most (Gradescope shows images only in html output),
plus Gradescope's leaderboard (speed and accuracy) when the rubric has
[gradescope] leaderboard = true. The instructor's notes (the grader's
warnings, the isolation mode) are printed on stdout, which results.json
hides from students (stdout_visibility: hidden). Exit status 3 when the
grader could not grade (run_autograder then writes a results.json that says
so).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .. import PROJECT_ROOT
from . import options

HELP = "build autograder.zip for Gradescope"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.description = __doc__.split("\n", 1)[1].strip("\n")
    p.add_argument("--out", type=Path, default=PROJECT_ROOT / "build" / "autograder.zip",
                   help="where to write the zip (default: build/autograder.zip)")
    p.add_argument("--grade", type=Path, metavar="SUBMISSION",
                   help="instead: grade SUBMISSION as Gradescope does (run_autograder calls this)")
    p.add_argument("--results", type=Path, default=Path("/autograder/results"),
                   help="with --grade: where results.json goes (default: /autograder/results)")
    options.language(p)
    options.quick(p, when="with --grade: ")
    options.isolation(p, when="with --grade: ", no_sandbox=False)


def run(args) -> int:
    if args.grade is not None:
        return grade_for_gradescope(args.grade, args.results, quick=args.quick, lang=args.lang,
                                    allow_unsafe=getattr(args, "allow_unsafe", False))
    from ..platforms.gradescope import build_bundle, course_secret_problem
    path = build_bundle(args.out)
    print(f"wrote {path} ({path.stat().st_size / 1e6:.1f} MB): upload it as the autograder on Gradescope")
    problem = course_secret_problem()
    if problem:
        print(f"warning: {problem}", file=sys.stderr)
    return 0


def grade_for_gradescope(submission: Path, results: Path, quick: bool = False, allow_unsafe: bool = False,
                         lang: str | None = None) -> int:
    from ..grading.grade import GradeOptions, grade
    from ..platforms.gradescope import add_leaderboard, leaderboard, leaderboard_enabled
    from ..reports import gradescope_json
    from ..grading.results import UNGRADABLE
    from ..grading.score import load_rubric
    options = GradeOptions(quick=quick, include_hidden=False, allow_unsafe=allow_unsafe, lang=lang)
    try:
        result = grade(submission, results, options)
        rubric = load_rubric(options.rubric)
    except Exception as e:   # stale fixtures, a bad rubric, no sandbox: the instructor's, not the student's
        print(f"gradescope: {type(e).__name__}: {e}", file=sys.stderr)
        return 3
    (results / "results.json").write_text(gradescope_json.render(result, output_format="html"))
    entries = leaderboard(result) if leaderboard_enabled(rubric) else []
    if entries:
        add_leaderboard(results / "results.json", entries)
    print(f"{result.submission}: {result.score:g} / {result.max_score:g} ({result.status})")
    for note in gradescope_json.instructor_notes(result):
        print(f"note: {note}")
    return 3 if result.status == UNGRADABLE else 0
