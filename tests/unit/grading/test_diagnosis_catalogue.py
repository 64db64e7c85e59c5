"""One catalogue of student text: every diagnosis id has its words in
grader/grading/catalogue.py, and each entry names the modules that emit it
(`emitted_by`). The tests hold the two to each other, module by module:

- a named emitter can really emit the id: its code constructs it, as the
  first argument of Diagnosis(...), SubmissionError(...) or _refusal(...)
  (read from the module's syntax tree), or, where the id is a variable,
  the module's DIAGNOSIS_IDS declares it;
- and everything a named emitter emits is in the catalogue, naming it.

An id emitted anywhere else without a catalogue entry is caught when it is
emitted: the check runner turns it into a harness error (the last test),
grading.grade warns of a build's.
"""
from __future__ import annotations

import ast
import importlib
import inspect
from pathlib import Path

import pytest

import grader
from grader.grading import catalogue
from grader.grading.catalogue import CATALOGUE, UnknownDiagnosis, describe, sort_key

# The calls whose first argument is a diagnosis id.
EMITTING_CALLS = ("Diagnosis", "SubmissionError", "_refusal")
ENTRIES = sorted({e.id: e for e in CATALOGUE.values()}.values(), key=lambda e: e.id)
EMITTERS = sorted({m for e in ENTRIES for m in e.emitted_by})


def _module(name: str):
    return importlib.import_module(f"grader.{name}")


def _called(node: ast.Call) -> str:
    f = node.func
    return f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else ""


def ids_emitted_by(name: str) -> set[str]:
    """What the module grader.<name> can emit: the literal ids its code
    passes to an emitting call, and its DIAGNOSIS_IDS (ids held in variables)."""
    module = _module(name)
    return _literal_ids(inspect.getsource(module)) | set(getattr(module, "DIAGNOSIS_IDS", ()))


def _literal_ids(source: str) -> set[str]:
    return {node.args[0].value for node in ast.walk(ast.parse(source))
            if isinstance(node, ast.Call) and _called(node) in EMITTING_CALLS and node.args
            and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)}


@pytest.mark.parametrize("entry", ENTRIES, ids=lambda e: e.id)
def test_each_entry_names_an_emitter_that_can_emit_it(entry):
    assert entry.emitted_by, f"{entry.id}: name the module that emits it"
    for name in entry.emitted_by:
        assert entry.id in ids_emitted_by(name), f"{entry.id}: grader.{name} does not emit it"


@pytest.mark.parametrize("name", EMITTERS)
def test_each_emitter_emits_only_ids_the_catalogue_gives_it(name):
    unnamed = {i for i in ids_emitted_by(name) if i not in CATALOGUE or name not in CATALOGUE[i].emitted_by}
    assert unnamed == set(), f"grader.{name} emits these: add them to grader/grading/catalogue.py, naming it"


def test_every_module_that_constructs_an_id_is_named_for_it():
    """The other way round: a module of the grader whose code constructs a
    diagnosis with a literal id is among that id's emitters (ids it holds in
    variables are its DIAGNOSIS_IDS, held above once it is named)."""
    root = Path(grader.__file__).parent
    unnamed = {}
    for path in sorted(root.rglob("*.py")):
        name = ".".join(path.relative_to(root).with_suffix("").parts).removesuffix(".__init__")
        for i in _literal_ids(path.read_text()):
            if i not in CATALOGUE or name not in CATALOGUE[i].emitted_by:
                unnamed.setdefault(name, set()).add(i)
    assert unnamed == {}, "name these modules as the ids' emitters in grader/grading/catalogue.py"


def test_the_emitters_are_found_in_each_kind_of_source():
    """Guards the reading above: ids from a literal call, a refusal, an
    exception and a declared table are each seen."""
    assert "render-mismatch" in ids_emitted_by("checks.renders")          # Diagnosis("...")
    assert "refused-include" in ids_emitted_by("build")                    # _refusal("...")
    assert "unknown-format" in ids_emitted_by("intake")                    # SubmissionError("...")
    assert "crash" in ids_emitted_by("checks.context")                     # DIAGNOSIS_IDS
    assert "render-mismatch" not in ids_emitted_by("checks.arrows")


def test_aliases_read_as_their_entry():
    for old, new in catalogue.ALIASES.items():
        assert CATALOGUE[old] is CATALOGUE[new]


def test_an_unknown_id_is_an_error_not_made_up_words():
    with pytest.raises(UnknownDiagnosis, match="made-up-thing"):
        describe("made-up-thing")
    with pytest.raises(UnknownDiagnosis):
        sort_key("made-up-thing")


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
