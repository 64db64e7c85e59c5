"""The audit of the grader (grader/course/audit): mutants made on tokens, their
truth decided against the reference, the figures, and a small seeded audit
that fails CI when a change lets a wrong mutant through or marks a correct one down."""
from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import CORRECT_SUBMISSION, PROJECT_ROOT, SUBMISSIONS
from grader.course.audit import Audited, AuditResult
from grader.course.audit.grading import Graded
from grader.course.audit.mutants import Mutant, all_mutants, mutants_of, sample, tokenize
from grader.course.audit.report import html_page, summarise, terminal_text
from grader.course.audit.truth import Truth, truth_of
from fake_bwrap import write_failing_bwrap
from cases import cases

PERFECT = PROJECT_ROOT / "examples" / "perfect" / "EnvironmentMap.cpp"


# ---- mutants: tokens, not text -------------------------------------------------------

TRICKY = r'''#include <cmath>
#define HALF (1 + 1)
// a comment: x < y + 1, u - v
const char* s = "a >= b + 1";   /* block: x * y */
char c = '-';
auto r = R"x(p + q < 2)x";
int f(int a, int b) { return a >= b ? a - 1 : -b; }
'''


def test_comments_strings_and_preprocessor_lines_are_never_mutated():
    protected = ["#include <cmath>", "#define HALF (1 + 1)", "// a comment: x < y + 1, u - v", '"a >= b + 1"',
                 "/* block: x * y */", "'-'", 'R"x(p + q < 2)x"']
    mutants = mutants_of(TRICKY, "tricky")
    assert mutants
    for m in mutants:
        for text in protected:
            assert text in m.source, (m.diff, text)
    assert {m.after for m in mutants if m.line == 7} >= {
        "int f(int a, int b) { return a > b ? a - 1 : -b; }", "int f(int a, int b) { return a >= b ? a + 1 : -b; }",
        "int f(int a, int b) { return a >= b ? a - 1 : b; }"}


def test_punctuators_are_whole_tokens():
    assert [t.text for t in tokenize("a>=b&&c->d::e<<=1")] == ["a", ">=", "b", "&&", "c", "->", "d", "::", "e",
                                                               "<<=", "1"]
    afters = {m.after for m in mutants_of("int f(int a, int b) { return a >= b; }", "t") if m.operator == "relation"}
    assert afters == {"int f(int a, int b) { return a > b; }", "int f(int a, int b) { return a <= b; }"}


def test_each_kind_of_change_is_made():
    src = PERFECT.read_text()
    afters = {(m.operator, m.after) for m in mutants_of(src, "perfect")}
    assert ("relation", "if (ax > ay && ax >= az) {") in afters
    assert ("logical", "if (ax >= ay || ax >= az) {") in afters
    assert ("name", "y = std::clamp(y, 0, m_FaceWidth - 1);") in afters
    assert ("constant", "x = std::clamp(x, 0, m_FaceWidth - 0);") in afters
    assert ("sign", ": FaceCoord{FACE_NEG_X, toUnit(d.z, ax), toUnit(d.y, ax)};") in afters
    assert ("arithmetic", "const double px = u / m_FaceWidth;") in afters
    # A template bracket is not a relation: static_cast<int> keeps its brackets.
    assert not any("static_cast<=" in a or "static_cast>" in a for _, a in afters)
    rounding = {a for op, a in afters if op == "rounding"}
    assert rounding == set()   # perfect uses no rounding function; helpers_std does:
    helpers = {m.after for m in mutants_of((CORRECT_SUBMISSION / "helpers_std.cpp").read_text(), "h")
               if m.operator == "rounding"}
    assert helpers and all(re.search(r"\b(ceil|round|trunc|floor)\b", a) for a in helpers)


def test_mutants_are_deduplicated_and_drawn_by_seed():
    # idiomatic.cpp is the same text as examples/perfect: its mutants are not made twice.
    every = all_mutants([PERFECT, CORRECT_SUBMISSION / "idiomatic.cpp"])
    assert len({m.source for m in every}) == len(every)
    assert {m.solution for m in every} == {"perfect"}
    a, b = sample(every, 20, seed=1), sample(every, 20, seed=1)
    assert [m.id for m in a] == [m.id for m in b]
    assert [m.id for m in a] != [m.id for m in sample(every, 20, seed=2)]


# ---- the truth, on mutants whose truth is stated by hand -------------------------------

def _variant(tmp_path: Path, before: str, after: str) -> Path:
    src = PERFECT.read_text()
    assert src.count(before) == 1, before
    path = tmp_path / f"v{abs(hash(after)) % 10**8}.cpp"
    path.write_text(src.replace(before, after))
    return path


# (change, its truth): each reasoned out from ASSIGNMENT.md, not taken from the audit.
STATED = [
    # A tie between x and y now goes to y: every touching face is correct.
    (("if (ax >= ay && ax >= az)", "if (ax > ay && ax >= az)"), "equivalent"),
    # v scaled by the width: the same on square faces, wrong on others (rows still clamped: no stray read).
    (("const double py = v * m_FaceHeight;", "const double py = v * m_FaceWidth;"), "wrong-non-square"),
    # Rows clamped to the width: the same on square faces; on 16 x 9 ones a row past the face is read.
    (("y = std::clamp(y, 0, m_FaceHeight - 1);", "y = std::clamp(y, 0, m_FaceWidth - 1);"), "crashing"),
    # x = W allowed: at u = 1 the read goes one texel past the face.
    (("x = std::clamp(x, 0, m_FaceWidth - 1);", "x = std::clamp(x, 0, m_FaceWidth);"), "crashing"),
    # 1/m overflows to infinity for m below 1/DBL_MAX (1e-310): NaN there only.
    (("return (s / m + 1.0) / 2.0;", "return (s * (1.0 / m) + 1.0) / 2.0;"), "wrong-extreme"),
    # The -X face's u runs the wrong way.
    (("FaceCoord{FACE_NEG_X, toUnit(-d.z, ax)", "FaceCoord{FACE_NEG_X, toUnit(d.z, ax)"), "wrong"),
    # Black exactly on the x-y edges (the tie's two faces both give a colour there): wrong at ties only.
    (("const auto [face, u, v] = directionToFace(direction);",
      "if (std::abs(direction.x) == std::abs(direction.y) && std::abs(direction.x) >= std::abs(direction.z))\n"
      "        return Color(0, 0, 0);\n    const auto [face, u, v] = directionToFace(direction);"), "wrong-ties"),
    # A misspelt name.
    (("const double beta = py - iy;", "const double beta = py - iyy;"), "not-compiling"),
]


@pytest.mark.sandbox
# slow: a mutant built and its truth decided per case (5-12 s); crashing0, wrong and not-compiling stay fast
@pytest.mark.parametrize("change,klass", cases(STATED, ids=lambda case: case[1], slow={
    "equivalent", "wrong-non-square", "crashing1", "wrong-extreme", "wrong-ties"}))
def test_truth_of_hand_reasoned_mutants(tmp_path, reference_library, change, klass):
    truth = truth_of(_variant(tmp_path, *change))
    assert truth.klass == klass, truth


# slow: truth decided densely for every zoo file (18 s), the quick study (12 s), the whole code scanned (9 s)
@pytest.mark.slow
@pytest.mark.sandbox
def test_truth_of_the_zoo(reference_library):
    # The zoo's files say what they are in their first lines.
    assert truth_of(SUBMISSIONS / "wrong" / "nan-huge.cpp").klass == "wrong-extreme"
    assert truth_of(SUBMISSIONS / "wrong" / "out-of-bounds-x1.cpp").klass == "crashing"
    assert truth_of(SUBMISSIONS / "wrong" / "nearest-neighbor.cpp").klass == "wrong"
    for path in sorted(CORRECT_SUBMISSION.glob("*.cpp")):
        assert truth_of(path).klass == "equivalent", path.name


@pytest.fixture
def failing_bwrap(monkeypatch):
    """A bwrap first on PATH that fails as it does without user namespaces
    (in a folder anyone can reach: the build's uid must run it)."""
    import os
    import shutil
    import tempfile
    from grader.worker import sandbox
    folder = write_failing_bwrap(Path(tempfile.mkdtemp(prefix="fake-bin-")))
    folder.chmod(0o755)
    monkeypatch.setenv("PATH", f"{folder}:{os.environ['PATH']}")
    sandbox.sandbox_problem.cache_clear()
    sandbox.privilege_drop_problem.cache_clear()
    yield
    sandbox.sandbox_problem.cache_clear()
    sandbox.privilege_drop_problem.cache_clear()
    shutil.rmtree(folder, ignore_errors=True)


@pytest.mark.sandbox
def test_truth_in_bubblewrap_and_privilege_drop_mode(tmp_path, reference_library, request):
    # The audit runs mutants where grading runs them: as root without bubblewrap too.
    change, klass = STATED[3]          # a read past the face: the guard pages must see it in both modes
    path = _variant(tmp_path, *change)
    truth = truth_of(path)
    from grader.worker import sandbox
    # Where bubblewrap cannot run (Gradescope's image, a CI container), the
    # first half is already privilege-drop mode; the second half still holds.
    here = "bubblewrap" if sandbox.sandbox_problem() is None else "privilege-drop"
    assert (truth.klass, truth.isolation) == (klass, here)
    request.getfixturevalue("failing_bwrap")
    path.write_text(path.read_text() + "// rebuilt without bubblewrap\n")
    truth = truth_of(path)
    assert (truth.klass, truth.isolation) == (klass, "privilege-drop")


# ---- the figures, on results made by hand ----------------------------------------------

def _audited(name: str, klass: str, score: float, lost: list[str]) -> Audited:
    m = Mutant("perfect", "relation", 3, "a < b", "a <= b", f"// {name}\n")
    return Audited(m, name, Truth(klass), Graded(score, 100.0, "graded", {}, lost))


def test_figures_count_escapes_false_fails_and_what_each_check_alone_catches():
    result = AuditResult(
        mutants=[_audited("w1", "wrong", 40, ["read_texture", "renders"]),
                 _audited("w2", "wrong-ties", 90, ["stability"]),
                 _audited("w3", "wrong", 100, []),                  # escaped
                 _audited("e1", "equivalent", 100, []),
                 _audited("e2", "equivalent", 95, ["speed"]),       # falsely failed
                 _audited("n1", "not-compiling", 0, []),
                 Audited(Mutant("perfect", "sign", 4, "x", "-x", "// u1\n"), "u1", Truth("unjudged", example="boom"))],
        controls=[Audited(None, "control-perfect", Truth("equivalent"), Graded(100, 100, "graded"))],
        rubric=Path("rubric.toml"),
        checks={"read_texture": 25, "stability": 10, "renders": 20, "speed": 5},
        settings={"seed": 0, "requested": 6, "available": 6, "sampled": 6, "solutions": ["perfect"],
                  "quick": True, "jobs": 1, "cpus": 2})
    data = summarise(result)
    assert data["behaviour_changing"] == 3 and data["killed"] == 2
    assert data["kill_rate"] == pytest.approx(2 / 3)
    assert data["false_fail_rate"] == pytest.approx(1 / 2)
    assert [r["id"] for r in data["escaped"]] == ["w3"]
    assert [r["id"] for r in data["false_fails"]] == ["e2"]
    assert data["checks"]["stability"]["alone"] == ["w2"]
    assert data["checks"]["read_texture"]["alone"] == [] and data["checks"]["read_texture"]["catches"] == 1
    assert data["checks"]["speed"]["marks_down_equivalent"] == ["e2"]
    assert data["caught_by_two_only"] == {"read_texture + renders": ["w1"]}
    assert [r["id"] for r in data["unjudged"]] == ["u1"]   # listed, and in no rate
    text = terminal_text(data)
    assert "ESCAPED" in text and "perfect:3: a < b  =>  a <= b" in text
    assert "FALSELY FAILED" in text and "NOT JUDGED" in text and "boom" in text
    page = html_page(data)   # diffs are C++: their < and & are escaped
    assert "perfect:3: a &lt; b  =&gt;  a &lt;= b" in page and "a < b" not in page


def test_command_refuses_bad_arguments():
    run = subprocess.run([sys.executable, "-m", "grader", "audit", "--mutants", "-1"], cwd=PROJECT_ROOT,
                         capture_output=True, text=True)
    assert run.returncode == 2 and "--mutants" in run.stderr
    run = subprocess.run([sys.executable, "-m", "grader", "audit", "--rubric", "/nonexistent.toml"],
                         cwd=PROJECT_ROOT, capture_output=True, text=True)
    assert run.returncode == 2 and "nonexistent" in run.stderr


# ---- the small audit CI runs ---------------------------------------------------------

SMALL = [PERFECT, CORRECT_SUBMISSION / "float_math.cpp", CORRECT_SUBMISSION / "switch_on_face.cpp",
         CORRECT_SUBMISSION / "helpers_std.cpp"]
# Beside the seeded sample, the mutants the audit of 300 found nearest to
# escaping (docs/audit.md): each is caught by one or two checks only, so a
# change that weakens those checks lets it through.
SENTINELS = (
    ("float_math", "const double m = std::max(std::fabs(direction.y), std::max(std::fabs(direction.y), "
                   "std::fabs(direction.z)));"),                              # the sweep and stability only
    ("helpers_std", "const double py = v * m_FaceWidth;"),                    # wrong on non-square faces only
    ("helpers_std", "const int x0 = std::clamp(static_cast<int>(fx), 0, m_FaceWidth - 2);"),  # read_texture alone
)


@pytest.mark.slow
@pytest.mark.sandbox
def test_small_audit_no_escape_and_no_false_fail(tmp_path, reference_library):
    from grader.course.audit import run_audit
    drawn = sample(all_mutants(SMALL), 20, seed=23)
    sentinels = [m for m in all_mutants(SMALL) if (m.solution, m.after) in SENTINELS]
    assert len(sentinels) == len(SENTINELS)
    chosen = drawn + [m for m in sentinels if m not in drawn]
    result = run_audit(SMALL, chosen=chosen, jobs=2, out=tmp_path, quick=True, progress=False)
    data = json.loads((tmp_path / "audit.json").read_text())
    assert data["controls_ok"], data["controls"]
    # The sample must hold both kinds, or the test could not fail.
    assert data["behaviour_changing"] >= 10 and data["equivalent"] >= 1, data["classes"]
    assert data["escaped"] == [], terminal_text(data)
    assert data["false_fails"] == [], terminal_text(data)
    assert (tmp_path / "audit.html").read_text().count("<tr>") > len(result.mutants)


# ---- a weakened rubric lets mutants through, and the audit names them -----------------------

FLOAT_MATH = CORRECT_SUBMISSION / "float_math.cpp"
# float_math scales the direction by m, its largest component, first. With a
# wrong m (stated by hand: along some axes m is 0, and the solution returns
# black there; elsewhere the answer is right) only a few directions are
# wrong, which the sweep and the stability check find.
WRONG_M = ("std::max(std::fabs(direction.y), std::max(std::fabs(direction.y), std::fabs(direction.z)))",
           "std::max(std::fabs(direction.x), std::min(std::fabs(direction.y), std::fabs(direction.z)))")


def _wrong_m_mutants() -> list[Mutant]:
    chosen = [m for m in mutants_of(FLOAT_MATH.read_text(), "float_math") if any(w in m.after for w in WRONG_M)]
    assert len(chosen) == 2, [m.diff for m in chosen]
    return chosen


@pytest.mark.slow
@pytest.mark.sandbox
def test_weakened_rubric_lets_mutants_through_and_the_audit_names_them(tmp_path, reference_library):
    from grader.course.audit import run_audit
    weak = tmp_path / "rubric-without-sweep-and-stability.toml"
    text = (PROJECT_ROOT / "grader" / "grading" / "rubric.toml").read_text()
    for check in ("fetch_sweep", "stability"):
        text, n = re.subn(rf"(\[checks\.{check}\]\npoints = )\d+", r"\g<1>0", text)
        assert n == 1
    weak.write_text(text)
    chosen = _wrong_m_mutants()
    diffs = sorted(m.diff for m in chosen)
    strong = run_audit([FLOAT_MATH], chosen=chosen, jobs=2, out=tmp_path / "strong", quick=True, progress=False)
    weakened = run_audit([FLOAT_MATH], chosen=chosen, jobs=2, out=tmp_path / "weak", rubric=weak, quick=True,
                         progress=False)
    assert [a.truth.klass for a in strong.mutants] == ["wrong", "wrong"]
    data = summarise(strong)
    assert data["escaped"] == [] and data["controls_ok"]
    weak_data = json.loads((tmp_path / "weak" / "audit.json").read_text())
    assert weak_data["controls_ok"]
    assert sorted(r["diff"] for r in weak_data["escaped"]) == diffs
    assert weak_data["kill_rate"] == 0.0
    text = terminal_text(summarise(weakened))
    assert all(d in text for d in diffs)
