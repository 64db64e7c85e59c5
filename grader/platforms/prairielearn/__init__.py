"""PrairieLearn's external grader: grade /grade/student into /grade/results/results.json.

PrairieLearn runs the question's grading image with this layout (its
"External Grading" documentation):

    /grade/serverFilesCourse/envmap/  this project (the course's serverFilesCourse/envmap,
                                      copied in because info.json lists it)
    /grade/student/                   the student's files (EnvironmentMap.cpp)
    /grade/tests/                     the question's tests/ folder (unused: the rubric is ours)
    /grade/results/results.json       what we write; PrairieLearn reads nothing else

The image (Dockerfile beside this file) holds the system packages and the
virtual environment ($ENVMAP_VENV); entrypoint.sh finds them and runs
`python -m grader prairielearn`. docs/platforms.md says how to build the
image and set up the question.

results.json is shown to the student by <pl-external-grader-results>:
`score` (0 to 1), `gradable` (false when the grader failed, or when the
code did not compile and the rubric's [prairielearn] build_error_gradable is
false: PrairieLearn charges neither to the student), `message`, `output`,
`tests[]` (name, description, points, max_points, message, output) and
`images[]` ({label, url}: PNG data URLs). PrairieLearn shows message and
output in a <pre>, so they are plain text (the Markdown reports rendered by
rich, no `#`, `**`, pipes or escapes). The whole file must stay under 1 MB:
pictures are added in order of use while the file stays under RESULTS_BUDGET.

What the student sees is what Gradescope shows them (grader.reports.
gradescope_json's student view): hidden checks count towards the score but
are not listed; the grader's warnings and the isolation mode are the
instructor's and go to stderr, which PrairieLearn keeps in the grading job's
log, as does every traceback.
"""
from __future__ import annotations

import io
import json
import os
import re
import shutil
import sys
import tempfile
import time
import traceback
from pathlib import Path

from ...i18n import N_, Translated, _, ngettext
from ...grading.results import BUILD_ERROR, UNGRADABLE
from ...reports.pictures import RENDER_PICTURES

DEFAULT_ROOT = Path("/grade")
# PNGs the checks leave beside the reports (CheckResult.artifacts): shown
# under these labels, in this order (the most useful first: the budget may
# leave the last out); others follow by name.
IMAGE_LABELS = Translated({
    **{name: RENDER_PICTURES[name].caption for name in ("render_submission", "render_reference", "render_difference")},
    "arrows": N_("Axis arrows on each face"),
    "render_flip": RENDER_PICTURES["render_flip"].caption,
    "speed_accuracy_chart": N_("Speed against accuracy (your lookup is the star)"),
})
MAX_RESULTS_BYTES = 1_000_000   # PrairieLearn's limit for the whole results.json
RESULTS_BUDGET = 900_000        # what we fill, with room to spare
MAX_IMAGE_BYTES = 200_000       # per picture, encoded (larger ones are halved until they fit)
TEXT_WIDTH = 100                # columns of the plain text (PrairieLearn's <pre> scrolls wider lines)
# What build_error_gradable = false reports as not gradable: code that did not
# compile and uploads with nothing to compile. A refusal (the reference
# called, a forbidden include or object) is a verdict on the code and stays graded.
NOT_COMPILED = ("build-error", "load-error", "no-source", "empty-submission", "unknown-format", "unreadable-archive")
BUILD_ERROR_MESSAGE = N_("Your code did not compile, so it was not graded and this submission uses none of "
                         "your attempts. Fix what the compiler says below and submit again.")
FAILED_MESSAGE = N_("The autograder failed before it could grade your submission. This is not your fault: "
                    "please tell your instructor.")


def _number(value: float) -> float:
    value = float(value)
    return round(value, 4) if value == value and abs(value) != float("inf") else 0.0


def plain_text(markdown: str, width: int = TEXT_WIDTH) -> str:
    """Markdown as the plain text a terminal would show (rich's renderer, no
    colour): headings, emphasis and escapes become text, tables become
    aligned columns."""
    from rich.console import Console
    from rich.markdown import Markdown
    console = Console(width=width, color_system=None, force_terminal=False, record=True,
                      file=io.StringIO(), highlight=False, emoji=False)
    console.print(Markdown(markdown, hyperlinks=False))
    lines = [line.rstrip() for line in console.export_text().splitlines()]
    return re.sub(r"\n{3,}", "\n\n", "\n".join(lines)).strip("\n") + "\n"


def _message(result, hidden: int) -> str:
    if result.status == UNGRADABLE:
        return _(FAILED_MESSAGE)
    from ...reports.view import STATUS_TEXT
    status = STATUS_TEXT.get(result.status, result.status)
    message = _("Score: %(score)s / %(max_score)s (%(status)s).") % {
        "score": f"{result.score:g}", "max_score": f"{result.max_score:g}", "status": status}
    if hidden:
        message += " " + ngettext("%(count)d hidden check also counts towards the score.",
                                  "%(count)d hidden checks also count towards the score.", hidden) % {"count": hidden}
    return message


def _pictures(checks) -> list[tuple[str, Path]]:
    """(label, path) of the visible checks' pictures, most useful first."""
    order = list(IMAGE_LABELS)
    named = sorted(((name, Path(path)) for c in checks for name, path in c.artifacts.items()),
                   key=lambda kv: (order.index(kv[0]) if kv[0] in order else len(order), kv[0]))
    return [(IMAGE_LABELS[name] if name in IMAGE_LABELS else name.replace("_", " "), path) for name, path in named]


def _size(data: dict) -> int:
    return len(json.dumps(data, indent=1, sort_keys=True).encode()) + 1


def results_from(result) -> dict:
    """PrairieLearn's results.json for one GradeResult (student view)."""
    from ...reports.gradescope_json import check_markdown, png_data_url, ran, student_summary
    from ...reports.text import clean
    from ...reports.view import check_label, check_state, is_visible
    shown = [c for c in result.checks if is_visible(c)]
    built = result.status != BUILD_ERROR
    tests = [{
        "name": clean(check_label(check)) or check.name,
        "description": check.name,
        "points": _number(check.score),
        "max_points": _number(check.max_score),
        "message": _(check_state(check)) if ran(check, built) else _("not run"),
        "output": plain_text(check_markdown(check)),
    } for check in shown]
    gradable = result.status != UNGRADABLE
    data = {
        "gradable": gradable,
        "score": _number(result.score / result.max_score) if gradable and result.max_score > 0 else 0.0,
        "message": _message(result, len(result.checks) - len(shown)),
        "output": plain_text(student_summary(result)),
        "tests": tests,
        "images": [],
    }
    left_out = 0
    for label, path in _pictures(shown):
        url = png_data_url(path, MAX_IMAGE_BYTES)
        if url is None:
            continue
        picture = {"label": label, "url": url}
        if _size(data) + len(json.dumps(picture)) + 4 <= RESULTS_BUDGET:
            data["images"].append(picture)
        else:
            left_out += 1
    if left_out:
        data["output"] += "\n(" + ngettext("%(count)d picture left out to keep the results under PrairieLearn's size limit.",
                                           "%(count)d pictures left out to keep the results under PrairieLearn's size limit.",
                                           left_out) % {"count": left_out} + ")\n"
    return data


# PrairieLearn stops a job at the question's externalGradingOptions.timeout
# (30 s when info.json gives none). The job itself is never told it: only
# its files and environment reach the container, so the instructor checks
# info.json (check_question), and every job says in its log how long it took.
PL_DEFAULT_TIMEOUT_S = 30
# Every job is cold (the reference, the worker's objects and the submission
# built each time): 22-44 s wall-clock measured on a 2-core host at load
# 10-15 (docs/platforms.md), which 120 s covers with room; docs suggest 300.
NEEDED_TIMEOUT_S = 120
DOCUMENTED_ENTRYPOINT = "/grade/serverFilesCourse/envmap/grader/platforms/prairielearn/entrypoint.sh"


def check_question(info_json: Path) -> list[str]:
    """What in a question's info.json would stop this grader from running
    or finishing (empty when nothing). Reads the file as PrairieLearn does."""
    try:
        info = json.loads(Path(info_json).read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        return [f"{info_json}: cannot be read as JSON ({e})"]
    options = info.get("externalGradingOptions") if isinstance(info, dict) else None
    if not isinstance(options, dict) or options.get("enabled") is False:
        return [f"{info_json}: no externalGradingOptions (or enabled is false): PrairieLearn will not run the grader"]
    problems = []
    if info.get("gradingMethod") != "External":
        problems.append(f'gradingMethod is {info.get("gradingMethod")!r}, not "External"')
    if "envmap/" not in (options.get("serverFilesCourse") or []):
        problems.append('serverFilesCourse does not list "envmap/": the grader\'s files are not copied into the job')
    if options.get("entrypoint") != DOCUMENTED_ENTRYPOINT:
        problems.append(f"entrypoint is {options.get('entrypoint')!r}, not {DOCUMENTED_ENTRYPOINT!r}")
    timeout = options.get("timeout", PL_DEFAULT_TIMEOUT_S)
    given = "timeout" in options
    if not isinstance(timeout, (int, float)) or isinstance(timeout, bool) or timeout < NEEDED_TIMEOUT_S:
        said = f"timeout is {timeout!r} s" if given else f"no timeout: PrairieLearn's default is {PL_DEFAULT_TIMEOUT_S} s"
        problems.append(f"{said}, too short for a cold grading job (22-44 s measured on a busy 2-core host): "
                        f"set externalGradingOptions.timeout to at least {NEEDED_TIMEOUT_S} (300 suggested)")
    return [f"{info_json}: {p}" for p in problems]


def timing_note(seconds: float) -> str:
    """The job log's line on how long this cold job took, and what it means
    for the question's timeout."""
    note = f"this cold job took {seconds:.0f} s wall-clock"
    if seconds > PL_DEFAULT_TIMEOUT_S:
        note += (f", longer than PrairieLearn's default timeout ({PL_DEFAULT_TIMEOUT_S} s): the question needs "
                 f"externalGradingOptions.timeout of at least {NEEDED_TIMEOUT_S} (check it with python -m grader "
                 "prairielearn --check-question questions/<question>/info.json)")
    return note


def build_error_gradable(rubric: dict) -> bool:
    """The rubric's [prairielearn] build_error_gradable (default true)."""
    from ...grading.score import RubricError
    value = rubric.get("prairielearn", {}).get("build_error_gradable", True)
    if not isinstance(value, bool):
        raise RubricError(f"prairielearn.build_error_gradable must be true or false, not {value!r}")
    return value


def build_not_gradable(result, rubric: dict) -> bool:
    """True when this result is reported not gradable for not compiling
    (the rubric's choice, NOT_COMPILED's cases)."""
    return (result.status == BUILD_ERROR and not build_error_gradable(rubric)
            and bool(result.diagnoses) and {d.id for d in result.diagnoses} <= set(NOT_COMPILED))


def not_gradable_build(data: dict) -> dict:
    """A build error reported as not gradable: PrairieLearn charges no
    attempt; the compiler's messages stay in the output."""
    return {**data, "gradable": False, "score": 0.0, "message": _(BUILD_ERROR_MESSAGE)}


def failure_results(reason: str = "") -> dict:
    """What results.json says when the grader itself failed (never a traceback)."""
    return {"gradable": False, "score": 0.0, "message": _(FAILED_MESSAGE) + (f" ({reason})" if reason else ""),
            "output": "", "tests": [], "images": []}


def _write_json(path: Path, data: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    os.replace(tmp, path)


def _build_ahead() -> None:
    """Every job starts cold: the reference library and the worker, which the
    grading needs only once the submission is built, are built in a thread
    beside the submission's build instead of after it (on one core this
    changes nothing). Each builder holds its own lock, so the grading waits
    for what is still being built and never builds it twice; a failure here
    is met again, and reported, where the grading needs that part."""
    import threading

    def build() -> None:
        from ...envmap import library
        from ...worker import native
        try:
            library.ensure_built()
            native.worker_binary()
            native.null_library()
            import matplotlib.figure  # noqa: F401  (the speed chart's, a second of imports)
        except Exception:    # noqa: BLE001  (the grading builds it again and says why)
            pass
    threading.Thread(target=build, name="build-ahead", daemon=True).start()


def grade_prairielearn(root: Path = DEFAULT_ROOT, quick: bool = False, keep_reports: bool = False) -> dict:
    """Grade root/student, write root/results/results.json, return what was written.

    Every failure ends in a results.json: the grader's own (stale fixtures,
    no sandbox, a bug) as gradable: false with the reason's first line, the
    traceback on stderr for the instructor. The grader's warnings and the
    isolation mode go to stderr too (PrairieLearn's job log)."""
    from ...grading.grade import GradeOptions, grade
    from ...reports.gradescope_json import instructor_notes
    from ...grading.score import load_rubric
    started = time.monotonic()
    root = Path(root)
    results_path = root / "results" / "results.json"
    work = Path(tempfile.mkdtemp(prefix="envmap-pl-"))
    try:
        student = root / "student"
        if not student.is_dir():
            data = failure_results(f"{student} is missing")
        else:
            options = GradeOptions(quick=quick, include_hidden=False)
            rubric = load_rubric(options.rubric)
            build_error_gradable(rubric)   # a bad value is the instructor's: said before grading
            _build_ahead()
            result = grade(student, work / "reports", options)
            for note in instructor_notes(result):
                print(f"prairielearn: note: {note}", file=sys.stderr)
            data = results_from(result)
            if build_not_gradable(result, rubric):
                data = not_gradable_build(data)
                print("prairielearn: note: a build error, not gradable ([prairielearn] build_error_gradable = "
                      "false): no attempt charged", file=sys.stderr)
            if keep_reports:    # report.html and friends for the instructor, beside results.json
                shutil.copytree(work / "reports", root / "results" / "reports", dirs_exist_ok=True)
    except Exception as e:   # the harness, not the student: say so, keep the details off the student's page
        traceback.print_exc(file=sys.stderr)
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        data = failure_results(f"{type(e).__name__}: {first}"[:300])
    finally:
        shutil.rmtree(work, ignore_errors=True)
    _write_json(results_path, data)
    print(f"prairielearn: {timing_note(time.monotonic() - started)}", file=sys.stderr)
    return data
