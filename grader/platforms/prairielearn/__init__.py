"""PrairieLearn's external grader: grade /grade/student into /grade/results/results.json.

PrairieLearn runs the course's grading image with this layout (its
"external grading" documentation):

    /grade/serverFilesCourse/   the course's serverFilesCourse/ (this project can live there)
    /grade/student/             the student's files (EnvironmentMap.cpp)
    /grade/tests/               the question's tests/ folder (unused: the rubric is ours)
    /grade/results/results.json what we write; PrairieLearn reads nothing else

and shows results.json to the student: `score` (0 to 1), `gradable`
(false only when the grader failed, which PrairieLearn does not charge to
the student), `message`, `output`, `tests[]` (name, description, points,
max_points, message, output) and `images[]` ({label, url}: PNG data URLs).

What the student sees is what Gradescope shows them: hidden checks count
towards the score but are not listed; no traceback ever reaches a student
(the instructor's copy goes to stderr, which PrairieLearn keeps in its job
log). Question set-up (info.json):

    "externalGradingOptions": {"enabled": true, "image": "<an image with this project's
        set-up, e.g. Gradescope's setup.sh>", "entrypoint":
        "/grade/serverFilesCourse/envmap/grader/platforms/prairielearn/entrypoint.sh", "timeout": 120}
"""
from __future__ import annotations

import base64
import json
import os
import shutil
import sys
import tempfile
import traceback
from pathlib import Path

from ...results import UNGRADABLE

DEFAULT_ROOT = Path("/grade")
# PNGs the checks leave beside the reports (CheckResult.artifacts): shown
# under these labels, in this order; others follow by name.
IMAGE_LABELS = {
    "render_submission": "Your render",
    "render_reference": "Reference render",
    "render_difference": "Difference (brighter is further off)",
    "render_flip": "FLIP error map",
    "arrows": "Axis arrows on each face",
}
MAX_IMAGE_BYTES = 2_000_000     # per picture: results.json must stay small enough to store
FAILED_MESSAGE = ("The autograder failed before it could grade your submission. This is not your fault: "
                  "please tell your instructor.")


def _number(value: float) -> float:
    value = float(value)
    return round(value, 4) if value == value and abs(value) != float("inf") else 0.0


def _image(label: str, path: Path) -> dict | None:
    try:
        data = path.read_bytes()
    except OSError:
        return None
    if not data.startswith(b"\x89PNG\r\n\x1a\n") or len(data) > MAX_IMAGE_BYTES:
        return None
    return {"label": label, "url": "data:image/png;base64," + base64.b64encode(data).decode()}


def results_from(result, report_md: str = "") -> dict:
    """PrairieLearn's results.json for one GradeResult (student view)."""
    from ...reports.text import clean, truncate_middle
    from ...reports.view import check_output
    tests, images, hidden = [], [], 0
    for check in result.checks:
        if check.visibility != "visible":
            hidden += 1
            continue
        tests.append({
            "name": clean(check.title) or check.name,
            "description": check.name,
            "points": _number(check.score),
            "max_points": _number(check.max_score),
            "message": check.status,
            "output": truncate_middle(check_output(check)),
        })
        named = sorted(check.artifacts.items(),
                       key=lambda kv: (list(IMAGE_LABELS).index(kv[0]) if kv[0] in IMAGE_LABELS else 99, kv[0]))
        for name, path in named:
            picture = _image(IMAGE_LABELS.get(name, name.replace("_", " ")), Path(path))
            if picture:
                images.append(picture)
    gradable = result.status != UNGRADABLE
    top = result.max_score
    if not gradable:
        message = FAILED_MESSAGE
    else:
        message = f"Score: {result.score:g} / {top:g} ({result.status})."
        if hidden:
            message += f" {hidden} hidden check{'s' if hidden > 1 else ''} also count towards the score."
    return {
        "gradable": gradable,
        "score": _number(result.score / top) if gradable and top > 0 else 0.0,
        "message": message,
        "output": truncate_middle(report_md),
        "tests": tests,
        "images": images,
    }


def failure_results(reason: str = "") -> dict:
    """What results.json says when the grader itself failed (never a traceback)."""
    return {"gradable": False, "score": 0.0, "message": FAILED_MESSAGE + (f" ({reason})" if reason else ""),
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
    traceback on stderr for the instructor."""
    from ...grade import GradeOptions, grade
    root = Path(root)
    results_path = root / "results" / "results.json"
    work = Path(tempfile.mkdtemp(prefix="envmap-pl-"))
    try:
        student = root / "student"
        if not student.is_dir():
            data = failure_results(f"{student} is missing")
        else:
            result = grade(student, work / "reports", GradeOptions(quick=quick, include_hidden=False))
            md = work / "reports" / "report.md"
            data = results_from(result, md.read_text() if md.is_file() else "")
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
