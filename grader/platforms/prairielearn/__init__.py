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
`score` (0 to 1), `gradable` (false only when the grader failed, which
PrairieLearn does not charge to the student), `message`, `output`,
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
import traceback
from pathlib import Path

from ...i18n import N_, Translated, _, ngettext
from ...grading.results import BUILD_ERROR, UNGRADABLE

DEFAULT_ROOT = Path("/grade")
# PNGs the checks leave beside the reports (CheckResult.artifacts): shown
# under these labels, in this order (the most useful first: the budget may
# leave the last out); others follow by name.
IMAGE_LABELS = Translated({
    "render_submission": N_("Your render"),
    "render_reference": N_("Reference render"),
    "render_difference": N_("Difference (brighter is further off)"),
    "arrows": N_("Axis arrows on each face"),
    "render_flip": N_("Where it looks different (brighter is further off)"),
    "speed_accuracy_chart": N_("Speed against accuracy (your lookup is the star)"),
})
MAX_RESULTS_BYTES = 1_000_000   # PrairieLearn's limit for the whole results.json
RESULTS_BUDGET = 900_000        # what we fill, with room to spare
MAX_IMAGE_BYTES = 200_000       # per picture, encoded (larger ones are halved until they fit)
TEXT_WIDTH = 100                # columns of the plain text (PrairieLearn's <pre> scrolls wider lines)
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


def failure_results(reason: str = "") -> dict:
    """What results.json says when the grader itself failed (never a traceback)."""
    return {"gradable": False, "score": 0.0, "message": _(FAILED_MESSAGE) + (f" ({reason})" if reason else ""),
            "output": "", "tests": [], "images": []}


def _write_json(path: Path, data: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    os.replace(tmp, path)


def grade_prairielearn(root: Path = DEFAULT_ROOT, quick: bool = False, keep_reports: bool = False) -> dict:
    """Grade root/student, write root/results/results.json, return what was written.

    Every failure ends in a results.json: the grader's own (stale fixtures,
    no sandbox, a bug) as gradable: false with the reason's first line, the
    traceback on stderr for the instructor. The grader's warnings and the
    isolation mode go to stderr too (PrairieLearn's job log)."""
    from ...grading.grade import GradeOptions, grade
    from ...reports.gradescope_json import instructor_notes
    root = Path(root)
    results_path = root / "results" / "results.json"
    work = Path(tempfile.mkdtemp(prefix="envmap-pl-"))
    try:
        student = root / "student"
        if not student.is_dir():
            data = failure_results(f"{student} is missing")
        else:
            result = grade(student, work / "reports", GradeOptions(quick=quick, include_hidden=False))
            for note in instructor_notes(result):
                print(f"prairielearn: note: {note}", file=sys.stderr)
            data = results_from(result)
            if keep_reports:    # report.html and friends for the instructor, beside results.json
                shutil.copytree(work / "reports", root / "results" / "reports", dirs_exist_ok=True)
    except Exception as e:   # the harness, not the student: say so, keep the details off the student's page
        traceback.print_exc(file=sys.stderr)
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        data = failure_results(f"{type(e).__name__}: {first}"[:300])
    finally:
        shutil.rmtree(work, ignore_errors=True)
    _write_json(results_path, data)
    return data
