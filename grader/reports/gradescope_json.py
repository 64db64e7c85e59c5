"""results.json in Gradescope's format (gradescope-autograders.readthedocs.io,
"Autograder Specifications"); schema/results.schema.json describes it.

- tests[] holds every check, hidden ones included: Gradescope hides each
  entry by its `visibility`, so a hidden check's output belongs there.
- The top-level `output` is shown to students whatever the tests'
  visibility, so it is built from the students' ReportView (view.py) and
  never mentions a hidden check.
- extra_data is stored for instructors and not shown to students; its
  `diagnoses` list every finding (the gradebook's diagnosis ids), as
  {"id", "face" (where it applies), "detail"}.
- stdout is hidden from students: a submission's own printing must not
  reach them through the harness's log.
- output_format is "md" on purpose: Gradescope renders it as Markdown, so
  every output is the same inert Markdown as report.md (student text
  escaped, a check's output shown literally when it would form more than
  paragraphs, lists, tables, emphasis and code). "text" would be safe too,
  but would show the tables and diagnoses as raw pipes and stars.
- A check worth no points reports "passed": it informs, it does not fail.

Deterministic: keys sorted, no timestamps; only execution_time varies
between runs.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

from ..results import PASSED, CheckResult, GradeResult
from . import markdown
from .text import clean, inert_markdown, truncate_middle
from .view import (build_view, check_output, group_diagnoses, is_informational,
                   is_visible)

SCHEMA_PATH = Path(__file__).with_name("schema") / "results.schema.json"

# Gradescope's test statuses are only these two.
GS_PASSED, GS_FAILED = "passed", "failed"


def _number(value: float) -> float:
    # Rounded so that sums like 0.1 + 0.2 do not print as 0.30000000000000004.
    return round(float(value), 4) if math.isfinite(value) else 0.0


def _test(check: CheckResult) -> dict:
    output = "\n".join([inert_markdown(truncate_middle(check_output(check))), "",
                        *markdown.worst_cases(check)]).strip()
    if not is_visible(check) and check.diagnoses:
        # The top-level output lists visible checks' diagnoses only; a hidden
        # check carries its own, shown when Gradescope shows the check.
        sections = [line for g in group_diagnoses(check.diagnoses)
                    for line in markdown.diagnosis_section(g, "####")]
        output = "\n".join([output, "", "### What to fix", "", *sections]).strip()
    entry = {
        "name": clean(check.title) or check.name,
        "score": _number(check.score),
        "max_score": _number(check.max_score),
        "status": GS_PASSED if check.status == PASSED or is_informational(check) else GS_FAILED,
        "output": output,
        "output_format": "md",
        "visibility": check.visibility,
        "tags": sorted(set(check.tags)),
        "extra_data": {"check": check.name, "status": check.status},
    }
    if check.number:
        entry["number"] = check.number
    return entry


def results_json(result: GradeResult) -> dict:
    found = result.diagnoses
    return {
        "score": _number(result.score),
        "execution_time": round(result.execution_time_s, 3),
        "output": markdown.summary(build_view(result, include_hidden=False)),
        "output_format": "md",
        "stdout_visibility": "hidden",
        "tests": [_test(c) for c in result.checks],
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


def render(result: GradeResult) -> str:
    return json.dumps(results_json(result), indent=2, sort_keys=True,
                      ensure_ascii=False, allow_nan=False) + "\n"


def load_schema() -> dict:
    return json.loads(SCHEMA_PATH.read_text())
