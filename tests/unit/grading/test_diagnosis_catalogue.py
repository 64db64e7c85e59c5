"""One catalogue of student text: every diagnosis id the grader can emit (a
check, the worker, the build) has its words in grader/grading/catalogue.py, and every
entry there can be emitted.

Ids are collected from the sources: string literals passed to Diagnosis(...),
SubmissionError(...), _refusal(...) or assigned to a `diagnosis_id`, plus the
ids behind the few Diagnosis(...) calls whose id is a variable: a module
that builds one declares every id it can hold in a module-level
`DIAGNOSIS_IDS` (or, for the modules below, DYNAMIC names the table). A new
Diagnosis(variable, ...) call fails this test until its ids are declared.
"""
from __future__ import annotations

import importlib
import re
import pytest

from grader import PROJECT_ROOT
from grader.grading import catalogue as diagnoses

SOURCES = sorted((PROJECT_ROOT / "grader").rglob("*.py"))
LITERAL_CALL = re.compile(r"\b(?:Diagnosis|SubmissionError|_refusal)\(\s*([\"'])([^\"']+)\1")
LITERAL_ASSIGN = re.compile(r"\bdiagnosis_id\s*(?::\s*str\s*)?=\s*([\"'])([^\"']+)\1")
VARIABLE_CALL = re.compile(r"\bDiagnosis\(\s*([A-Za-z_][\w.]*)\s*,")


def _read_texture_ids():
    from grader.checks import read_texture
    return set(read_texture.DIAGNOSIS_IDS)


def _mapping_ids():
    from grader.checks import fetch_faces as diagnosis
    return {i for ids, _ in diagnosis.TRANSFORMS for i in ids}


def _worker_ids():
    from grader.worker import failures
    return set(failures.KINDS)


def _face_recovery_ids():
    from grader.checks.instruments import face_recovery
    return {i for c in face_recovery.CANDIDATES for i in c.ids}


def _build_ids():
    from grader import build
    return set(build.DIAGNOSIS_IDS)  # grade.py also checks every build id against the catalogue


# (file relative to grader/, the variable passed as the id) -> the ids it can hold.
DYNAMIC = {
    ("checks/read_texture.py", "mistake"): _read_texture_ids,
    ("checks/fetch_faces.py", "mistake"): _mapping_ids,
    ("checks/context.py", "kind"): _worker_ids,
    ("grading/grade.py", "diagnosis_id"): _build_ids,
    ("checks/instruments/face_recovery.py", "mistake"): _face_recovery_ids,
}


def _dynamic_ids(rel: str, variable: str) -> set[str]:
    module = importlib.import_module("grader." + rel.removesuffix(".py").replace("/", "."))
    declared = getattr(module, "DIAGNOSIS_IDS", None)
    if declared is not None:
        return set(declared)
    assert (rel, variable) in DYNAMIC, (
        f"grader/{rel} builds a Diagnosis from the variable {variable!r}: declare every id it can hold in a "
        f"module-level DIAGNOSIS_IDS in grader/{rel}")
    return DYNAMIC[rel, variable]()


def emitted_ids() -> dict[str, set[str]]:
    """id -> where it comes from."""
    found: dict[str, set[str]] = {}
    for path in SOURCES:
        rel = path.relative_to(PROJECT_ROOT / "grader").as_posix()
        if rel in ("grading/results.py", "grading/catalogue.py"):
            continue
        text = path.read_text()
        for pattern in (LITERAL_CALL, LITERAL_ASSIGN):
            for m in pattern.finditer(text):
                found.setdefault(m.group(2), set()).add(rel)
        for m in VARIABLE_CALL.finditer(text):
            for i in _dynamic_ids(rel, m.group(1)):
                found.setdefault(i, set()).add(rel)
    return found


def test_every_emitted_id_is_in_the_catalogue():
    missing = {i: sorted(where) for i, where in emitted_ids().items() if i not in diagnoses.CATALOGUE}
    assert missing == {}, "add these ids to grader/grading/catalogue.py (then regenerate docs/diagnoses.md)"


def test_every_catalogue_entry_can_reach_a_student():
    unused = sorted(set(diagnoses.CATALOGUE) - set(diagnoses.ALIASES) - set(emitted_ids()))
    assert unused == [], "nothing emits these ids: emit them where the mistake is found, or delete them"


def test_the_collector_sees_the_ids_it_should():
    """Guards the regular expressions: ids from each kind of source are found."""
    ids = emitted_ids()
    for i in ("render-mismatch", "u-flipped", "nearest-neighbor", "load-error", "exited", "protocol",
              "crash", "build-error", "slow", "arrow-missing"):
        assert i in ids, i


def test_an_unknown_id_is_an_error_not_made_up_words():
    with pytest.raises(diagnoses.UnknownDiagnosis, match="made-up-thing"):
        diagnoses.describe("made-up-thing")
    with pytest.raises(diagnoses.UnknownDiagnosis):
        diagnoses.sort_key("made-up-thing")


def test_a_check_that_emits_an_unknown_id_is_a_harness_error_not_a_verdict():
    from grader.checks import check, run_checks
    from grader.grading.results import ERROR, Diagnosis

    @check(registry={})
    def inventive(ctx, result):
        """Invents an id."""
        result.diagnoses.append(Diagnosis("made-up-thing", "words nobody wrote"))

    [result] = run_checks([inventive.__check__], None).results
    assert result.status == ERROR and result.diagnoses == []
    assert "made-up-thing" in result.error_log and "made-up-thing" not in result.output
