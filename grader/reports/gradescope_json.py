"""results.json in Gradescope's format (gradescope-autograders.readthedocs.io,
"Autograder Specifications"); schema/results.schema.json describes it.

- tests[] holds every check, hidden ones included: Gradescope hides each
  entry by its `visibility`, so a hidden check's output belongs there.
- The top-level `output` is shown to students whatever the tests'
  visibility, so it is built from the students' ReportView (view.py) and
  never mentions a hidden check. It carries nothing that is the
  instructor's: the grader's warnings (versions that differ from the
  fixtures', which file was graded as EnvironmentMap.cpp, sandbox notes)
  and the isolation mode go to extra_data and instructor_notes(), which
  `gradescope --grade` prints on stdout (stdout_visibility: hidden).
- extra_data is stored for instructors and not shown to students; its
  `diagnoses` list every finding (the gradebook's diagnosis ids), as
  {"id", "face" (where it applies), "detail"}.
- stdout is hidden from students: a submission's own printing must not
  reach them through the harness's log.
- output_format: each test's output is "md", the same inert Markdown as
  report.md (student text escaped, a check's output shown literally when it
  would form more than paragraphs, lists, tables, emphasis and code). The
  top-level output is "md" in every report folder; on Gradescope
  (`gradescope --grade`) it is "html": the same summary rendered by
  markdown-it with raw HTML off, followed by the render that differs most
  and the reference's, as small base64 PNGs (Gradescope shows images only
  in html output, which it sanitises without naming its rules: the markup
  keeps to Rails' default safelist, _render_pair_html).
- A test's status says whether the check ran and passed: a check that did
  not run (the build failed, it was skipped, the grader failed in it) is
  "failed", whatever its points; a check worth no points that ran reports
  "passed": it informs, it does not fail.

Deterministic: keys sorted, no timestamps; only execution_time varies
between runs.
"""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

from ..i18n import _
from ..grading.results import BUILD_ERROR, ERROR, PASSED, SKIPPED, CheckResult, GradeResult
from . import markdown
from .pictures import RENDER_PICTURES
from .text import clean, inert_markdown, md_escape, truncate_middle
from .view import (ISOLATION_TEXT, ReportView, build_view, check_label, check_output, group_diagnoses,
                   is_informational, is_visible)

SCHEMA_PATH = Path(__file__).with_name("schema") / "results.schema.json"

# Gradescope's test statuses are only these two.
GS_PASSED, GS_FAILED = "passed", "failed"
# The pair of pictures the html output shows (the render check's artifacts:
# the render that differs most, grader/checks/renders.py), with their captions.
RENDER_PAIR = tuple((name, RENDER_PICTURES[name].caption) for name in ("render_submission", "render_reference"))
# Per picture, once encoded: results.json stays small (a 128 x 128 render is about 20 kB).
MAX_PICTURE_BYTES = 60_000


def _number(value: float) -> float:
    # Rounded so that sums like 0.1 + 0.2 do not print as 0.30000000000000004.
    return round(float(value), 4) if math.isfinite(value) else 0.0


def ran(check: CheckResult, built: bool = True) -> bool:
    """Whether the check ran on the submission: not when the build failed,
    and not when it was skipped or the grader failed in it."""
    return built and check.status not in (SKIPPED, ERROR)


def check_markdown(check: CheckResult) -> str:
    """A check's own output as inert Markdown, with its worst cases; a
    hidden check carries its own diagnoses (the summary lists only the
    visible checks'), shown when the check is."""
    output = "\n".join([inert_markdown(truncate_middle(check_output(check))), "",
                        *markdown.worst_cases(check)]).strip()
    if not is_visible(check) and check.diagnoses:
        sections = [line for g in group_diagnoses(check.diagnoses)
                    for line in markdown.diagnosis_section(g, "####")]
        output = "\n".join([output, "", "### " + _("What to fix"), "", *sections]).strip()
    return output


def _test(check: CheckResult, built: bool = True) -> dict:
    # The name is the check's short label (the list of tests stays short);
    # its output opens with the check's whole sentence.
    output = "\n\n".join(p for p in (f"_{md_escape(check.title)}_" if check.title else "",
                                      check_markdown(check)) if p)
    entry = {
        "name": clean(check_label(check)) or check.name,
        "score": _number(check.score),
        "max_score": _number(check.max_score),
        "status": GS_PASSED if ran(check, built) and (check.status == PASSED or is_informational(check))
        else GS_FAILED,
        "output": output,
        "output_format": "md",
        "visibility": check.visibility,
        "tags": sorted(set(check.tags)),
        "extra_data": {"check": check.name, "status": check.status},
    }
    if is_visible(check):
        # The ids this check found (the kit's agreement test compares them per check).
        entry["extra_data"]["diagnoses"] = sorted({d.id for d in check.diagnoses})
    if check.number:
        entry["number"] = check.number
    return entry


def student_view(result: GradeResult) -> ReportView:
    """What a student is shown: the visible checks, without the grader's
    warnings (they are the instructor's: instructor_notes)."""
    return dataclasses.replace(build_view(result, include_hidden=False), warnings=[])


def student_summary(result: GradeResult) -> str:
    """The top-level summary (markdown.summary) of the student view (the
    isolation mode is an instructor's note, never in it)."""
    view = student_view(result)
    text = markdown.summary(view).strip()
    return (text or _("See each check below for details.")) + "\n"


def instructor_notes(result: GradeResult) -> list[str]:
    """What only instructors should read: the grader's warnings and how the
    submission's code was isolated."""
    notes = [clean(w) for w in result.warnings]
    if result.isolation:
        notes.append("the submission's code ran under: "
                     + clean(ISOLATION_TEXT.get(result.isolation, result.isolation)))
    return notes


def png_data_url(path: Path, max_bytes: int = MAX_PICTURE_BYTES) -> str | None:
    """A PNG as a data: URL of at most max_bytes (halved in size until it
    fits), or None when the file is not a readable PNG."""
    import base64
    import io

    from PIL import Image
    try:
        data = Path(path).read_bytes()
        if not data.startswith(b"\x89PNG\r\n\x1a\n"):
            return None
        image = Image.open(io.BytesIO(data))
        image.load()
    except (OSError, ValueError):
        return None
    prefix = "data:image/png;base64,"
    while len(prefix) + 4 * ((len(data) + 2) // 3) > max_bytes:
        if min(image.size) < 16:
            return None
        image = image.resize((image.width // 2, image.height // 2), Image.LANCZOS)
        buffer = io.BytesIO()
        image.save(buffer, format="PNG", optimize=True)
        data = buffer.getvalue()
    return prefix + base64.b64encode(data).decode()


def _render_pair_html(result: GradeResult) -> str:
    """The render check's pictures (the render that differs most and the
    reference's), when that check is one students see.

    Gradescope sanitises html output and names no rules; the markup keeps to
    Rails' default safelist (rails-html-sanitizer: no figure, no style
    attribute) and Loofah's URI rule (data: allowed for image/png), which
    tests/unit/reports/test_gradescope_html.py holds it to. The pictures come
    last, after the whole summary, so a sanitiser that drops them takes
    nothing else with it."""
    from html import escape
    for check in result.checks:
        if not is_visible(check) or not all(name in check.artifacts for name, _ in RENDER_PAIR):
            continue
        cells = []
        for name, caption in RENDER_PAIR:
            caption = _(caption)
            url = png_data_url(Path(check.artifacts[name]))
            if url is None:
                return ""
            cells.append(f'<img src="{url}" alt="{escape(caption)}" title="{escape(caption)}" width="256">')
        return (f"<h3>{escape(clean(check.title))}</h3>\n<p>"
                + escape(_("The render that differs most from the reference, beside the reference:"))
                + "</p>\n<p>" + " ".join(cells) + "</p>\n")
    return ""


def summary_html(result: GradeResult) -> str:
    """student_summary() as HTML (markdown-it, raw HTML off, so the student's
    text stays text), then the render pair."""
    from markdown_it import MarkdownIt
    page = MarkdownIt("commonmark", {"html": False}).enable("table").render(student_summary(result))
    return page + _render_pair_html(result)


def results_json(result: GradeResult, output_format: str = "md") -> dict:
    """results.json; output_format "html" is what Gradescope is given
    (the summary as HTML with the render pair), "md" what every report
    folder holds."""
    found = result.diagnoses
    built = result.status != BUILD_ERROR
    return {
        "score": _number(result.score),
        "execution_time": round(result.execution_time_s, 3),
        "output": summary_html(result) if output_format == "html" else student_summary(result),
        "output_format": output_format,
        "stdout_visibility": "hidden",
        "tests": [_test(c, built) for c in result.checks],
        "extra_data": {
            "submission": clean(result.submission),
            "status": result.status,
            "max_score": _number(result.max_score),
            "warnings": [clean(w) for w in result.warnings],
            "diagnoses": [{k: clean(v) for k, v in d.as_json().items()} for d in found],
            "source_sha256": result.source_sha256,
            "isolation": clean(str(getattr(result, "isolation", "unknown"))),
        },
    }


def render(result: GradeResult, output_format: str = "md") -> str:
    return json.dumps(results_json(result, output_format), indent=2, sort_keys=True,
                      ensure_ascii=False, allow_nan=False) + "\n"


def load_schema() -> dict:
    return json.loads(SCHEMA_PATH.read_text())
