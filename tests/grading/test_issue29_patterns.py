"""Issue 29's patterns 2, 6, 8, 10 (its guard) and 11 (tests/submissions/offmodel/, their
verdicts asserted with the rest of that zoo by test_offmodel_zoo.py) and
pattern 13, the sentences a report's own tables contradict.

Each file's request is restated here in numpy from its code (what it asks
readTexture for, per direction), held against the independent model
(tests/assignment_model.py: it differs exactly where the file's header says)
and against the compiled file's record, call by call. Then what a student
reads: "What to fix first" shows the observation that leads to the fix.
"""
from __future__ import annotations

import re

import numpy as np
import pytest

import assignment_model as model
from grader.build import build_submission
from grader.checks.instruments import fetch_record
from grader.checks.instruments.directions import edges, fibonacci_sphere
from grader.checks.instruments.textures import coordinate_faces
from grader.grading import catalogue
from grader.grading.grade import GradeOptions
from grader.grading.results import GRADED
from grader.reports import render_all
from grader.worker.runner import SubmissionRunner
from grading_cache import grade_once
from project_paths import SUBMISSIONS

ZOO = SUBMISSIONS / "offmodel"
MIN_NORMAL = 2.0 ** -1022
TINY = 5e-324


def directions() -> np.ndarray:
    """Unit, long, short and denormal directions, edges and exact multiples."""
    sphere = fibonacci_sphere(1_500)
    scaled = np.concatenate([np.ldexp(sphere[:200], k) for k in (-1070, -1060, -1000, -40, -20, 10, 30, 600, 1000)])
    small = np.array([[TINY, TINY, TINY], [TINY, 0, 0], [0, TINY, 0], [3 * TINY, -TINY, 2 * TINY],
                      [1e-310, -2e-310, 3e-310], [1, 1e-300, 1e-300], [1.5, 1.9, 0.2], [7.5, -7.9, 3.0]])
    return np.concatenate([sphere, edges(8), scaled, small])


def first_touching(dirs):
    """The face an if-chain in x, y, z order with >= picks: the first touching face."""
    touched = model.touching_faces(dirs)
    return np.where(touched.any(axis=1), np.argmax(touched, axis=1), -1)


def table(dirs):
    faces = first_touching(dirs)
    u, v = model.face_uv(dirs, faces)
    return faces, u, v


# ---- each file's request, restated from its code ----------------------------------

def row_below_at_v0(dirs):
    return table(dirs)                          # its fetchColor is the table's; readTexture is its mistake


def half_before_divide(dirs):
    """0.5 * s / c + 0.5 in IEEE double, in the code's order (numpy rounds as C does)."""
    faces = first_touching(dirs)
    x, y, z = dirs.T
    ax, ay, az = np.abs(dirs).T
    axis = faces // 2
    with np.errstate(all="ignore"):
        u = np.select([axis == 0, axis == 1], [0.5 * z / x + 0.5, 0.5 * x / ay + 0.5], 0.5 * x / az + 0.5)
        v = np.select([axis == 0, axis == 1], [0.5 * y / ax + 0.5, 0.5 * z / y + 0.5], 0.5 - 0.5 * y / z)
    return faces, u, v


def epsilon_guard(dirs):
    faces, u, v = table(dirs)
    guarded = np.abs(dirs).max(axis=1) <= 1e-9
    return np.where(guarded, -2, faces), u, v   # -2: no readTexture call


def int_abs_axis(dirs):
    """The axis by whole parts of |c| held in an int (x86 gives INT_MIN past 2^31), first of x, y, z on ties."""
    a = np.abs(dirs)
    whole = np.where(a < 2.0 ** 31, np.trunc(a), -(2.0 ** 31))
    axis = np.where((whole[:, 0] >= whole[:, 1]) & (whole[:, 0] >= whole[:, 2]), 0,
                    np.where(whole[:, 1] >= whole[:, 2], 1, 2))
    c = dirs[np.arange(len(dirs)), axis]
    faces = 2 * axis + (c > 0).choose(1, 0)
    m = np.abs(c)
    x, y, z = dirs.T
    s = np.choose(faces, [z, -z, x, x, x, x])
    t = np.choose(faces, [y, y, z, -z, -y, y])
    with np.errstate(all="ignore"):
        return faces, (1 + s / m) / 2, (1 + t / m) / 2


def edge_guard(dirs):
    """The table's request, none (-2) where its u or v is not below 1."""
    faces, u, v = table(dirs)
    return np.where((u < 1) & (v < 1), faces, -2), u, v


REQUESTS = {
    "edge-guard-black_array": edge_guard,
    "row-below-at-v0_face-table": row_below_at_v0,
    "half-before-divide_signed-if-chain": half_before_divide,
    "epsilon-guard-black_lambdas": epsilon_guard,
    "int-abs-axis_c-style": int_abs_axis,
}


def test_each_restated_request_differs_from_the_model_exactly_where_its_header_says():
    dirs = directions()
    faces, u, v = table(dirs)
    valid = faces >= 0
    for name, request in REQUESTS.items():
        f, ru, rv = request(dirs)
        with np.errstate(invalid="ignore"):
            wrong = valid & ((f != faces) | ~np.isclose(ru, u, rtol=0, atol=1e-12) | ~np.isclose(rv, v, rtol=0, atol=1e-12))
        if name.startswith("row-below"):
            assert not wrong.any()
        elif name.startswith("half-before"):
            # Only where a component is a denormal, and there at (TINY, TINY, TINY) at least.
            denormal = ((np.abs(dirs) < MIN_NORMAL) & (dirs != 0)).any(axis=1)
            assert wrong.any() and not (wrong & ~denormal).any()
            k = np.flatnonzero((dirs == TINY).all(axis=1))[0]
            assert (f[k], ru[k], rv[k]) == (0, 0.5, 0.5) and (u[k], v[k]) == (1, 1)
        elif name.startswith("edge-guard"):
            # No call exactly where the table's u or v is 1 (faces' right and top borders, edges, corners).
            assert (wrong == (valid & ((u == 1) | (v == 1)))).all() and wrong.any()
        elif name.startswith("epsilon"):
            assert (wrong == (valid & (np.abs(dirs).max(axis=1) <= 1e-9))).all() and wrong.any()
        else:
            unit = np.abs(np.linalg.norm(dirs, axis=1) - 1) < 1e-9
            toward_x = unit & (faces // 2 == 0)
            # Every unit direction picks +X or -X: right toward X, wrong toward Y and Z ...
            assert (f[unit] // 2 == 0).all() and not wrong[toward_x].any() and wrong[unit & ~toward_x].all()
            # ... and the same directions at 2^10 are mostly right: the length changes the face.
            long = np.ldexp(dirs[unit], 10)
            lf, _, _ = int_abs_axis(long)
            assert np.mean(lf == table(long)[0]) > 0.9


@pytest.mark.parametrize("name", sorted(REQUESTS))
def test_the_record_of_the_compiled_file_is_the_restated_request(name):
    dirs = directions()
    build = build_submission(ZOO / f"{name}.cpp")
    assert build.ok, build.log
    faces, u, v = REQUESTS[name](dirs)
    with SubmissionRunner(build.library, coordinate_faces(32, 32), timeout_s=5.0) as runner:
        rec = fetch_record.record(runner, dirs)
    assert (rec.calls >= 0).all()
    no_call = faces == -2
    assert (rec.calls[no_call] == 0).all() and (rec.calls[~no_call] == 1).all()
    asked = ~no_call
    assert (rec.faces[asked, 0] == faces[asked]).all(), np.flatnonzero(rec.faces[asked, 0] != faces[asked])[:5]
    assert np.allclose(rec.uv[asked, 0, 0], u[asked], rtol=0, atol=1e-15, equal_nan=True)
    assert np.allclose(rec.uv[asked, 0, 1], v[asked], rtol=0, atol=1e-15, equal_nan=True)


# ---- what a student reads -----------------------------------------------------------

def what_to_fix(md: str) -> str:
    return md.split("## What to fix first", 1)[1].split("## Checks", 1)[0] if "## What to fix first" in md else ""


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    out = {}

    def get(name):
        if name not in out:
            result = grade_once(ZOO / f"{name}.cpp", tmp_path_factory.mktemp("p29"), GradeOptions(quick=True),
                                write_reports=False)
            assert result.status == GRADED
            out[name] = (result, render_all(result)["report.md"])
        return out[name]
    return get


@pytest.mark.slow
@pytest.mark.sandbox
def test_pattern_2_a_read_below_the_face_is_readTextures_not_a_tie(graded):
    result, md = graded("row-below-at-v0_face-table")
    fix = what_to_fix(md)
    assert fix.index("readTexture read outside the face") < fix.index("readTexture's lattice points are not clamped")
    assert "Clamp both lattice points" in fix and "y = -1" in fix
    assert not re.search(r"tie|>=", fix), fix            # nothing about ties or comparisons
    assert "On every face, fetchColor samples the right face" in md


@pytest.mark.slow
@pytest.mark.sandbox
def test_pattern_6_the_denormal_call_is_shown_beside_the_same_direction_at_length_one_half(graded):
    result, md = graded("half-before-divide_signed-if-chain")
    fix = what_to_fix(md)
    assert "The same direction gives another answer at another length" in fix
    assert ("fetchColor(Vector3(4.94065646e-324, 4.94065646e-324, 4.94065646e-324)) asks readTexture for face +X "
            "at (u, v) = (0.5, 0.5); the same direction at another length, fetchColor(Vector3(0.5, 0.5, 0.5)), "
            "asks readTexture for face +X at (u, v) = (1, 1)") in fix
    assert "divide by m before anything else" in fix


@pytest.mark.slow
@pytest.mark.sandbox
def test_pattern_8_a_short_direction_is_shown_making_no_call(graded):
    result, md = graded("epsilon-guard-black_lambdas")
    fix = what_to_fix(md)
    assert re.search(r"fetchColor\(Vector3\([-0-9.e, ]+\)\) makes no readTexture call and returns \(0, 0, 0\); "
                     r"the same direction at another length, fetchColor\(Vector3\([-0-9.e, ]+\)\), asks readTexture "
                     r"for face [-+][XYZ]", fix), fix
    assert "treat only a zero, NaN or infinite direction as having no face" in fix


@pytest.mark.slow
@pytest.mark.sandbox
def test_pattern_10_a_guard_at_u_or_v_one_is_shown_on_the_border(graded):
    result, md = graded("edge-guard-black_array")
    fix = what_to_fix(md)
    assert "fetchColor returns black without calling readTexture" in fix
    assert re.search(r"For (\d+) of (\d+) directions fetchColor made no readTexture call and returned black", fix)
    assert "Each of them lies on a face's border" in fix and "reads the texels itself" not in md


@pytest.mark.slow
@pytest.mark.sandbox
def test_pattern_8_is_not_called_float_precision(graded):
    result, md = graded("epsilon-guard-black_lambdas")
    assert "float-precision" not in {d.id for d in result.diagnoses} and "through float" not in md


@pytest.mark.slow
@pytest.mark.sandbox
def test_pattern_11_the_face_is_shown_changing_with_the_length_and_speed_is_not_blamed(graded):
    result, md = graded("int-abs-axis_c-style")
    ids = {d.id for d in result.diagnoses}
    assert "length-dependent" in ids and "timing-faces-wrong" not in ids and "no cheaper path" not in md
    [detail] = [d.detail for d in result.diagnoses if d.id == "length-dependent"]
    faces = re.findall(r"for face ([-+][XYZ])", detail)
    assert len(faces) == 2 and faces[0] != faces[1], detail     # the same direction, two faces


# ---- pattern 13: no report says what its own tables contradict -------------------------

PER_FACE_MAPPING = {"wrong-face", "u-flipped", "v-flipped", "uv-swapped", "uv-mismatch", "face-order", "uv-rotated",
                    "signed-major", "opengl-table", "uv-inset", "uv-offset", "uv-range"}


def contradictions(result, md: str) -> list[str]:
    """Each sentence of issue 29's pattern 13 that `md` prints while its own
    results say otherwise."""
    found = []
    ids = {d.id for d in result.diagnoses}
    by_name = {c.name: c for c in result.checks}
    if "On every face, fetchColor samples the right face" in md and ids & PER_FACE_MAPPING:
        found.append(f"every face right, beside {sorted(ids & PER_FACE_MAPPING)}")
    sweep = by_name.get("fetch_sweep")
    if "still looks like the starting code" in md and sweep is not None and sweep.metrics.get("matched", 0) > 0:
        found.append(f"the starting code, while {sweep.metrics['matched']} sweep directions match")
    beside = ids - {"nan-output"} - catalogue.CONSEQUENCES
    if "Fix the cause named beside this one first" in what_to_fix(md) and not beside:
        found.append("a cause beside nan-output, with nothing beside it")
    for same in re.finditer(r"([^.;:\n]{3,60}?) instead of \1(?![\w(])", md):
        found.append(f"'{same.group(0)}'")
    return found


def test_the_contradiction_finder_finds_each_sentence():
    class R:
        def __init__(self, ids, matched=0):
            self.diagnoses = [type("D", (), {"id": i})() for i in ids]
            self.checks = [type("C", (), {"name": "fetch_sweep", "metrics": {"matched": matched}})()]
    fix = "## What to fix first\n\n{}\n\n## Checks\n"
    assert contradictions(R({"uv-swapped"}), "On every face, fetchColor samples the right face with u")
    assert contradictions(R({"not-implemented"}, 500), "it still looks like the starting code.")
    assert contradictions(R({"nan-output"}), fix.format("Fix the cause named beside this one first."))
    assert contradictions(R(set()), "uses p = (uW, vH) instead of p = (uW, vH).")
    assert not contradictions(R({"nan-output", "length-overflow"}), fix.format("Fix the cause named beside this one first."))
    assert not contradictions(R(set()), "uses p = (u(W+1), v(H+1)) instead of p = (uW, vH).")


# The pattern files and the zoos graded in full elsewhere (the cache shares their gradings).
SCANNED = ([f"offmodel/{p.stem}" for p in sorted(ZOO.glob("*.cpp"))]
           + [f"patterns/{p.stem}" for p in sorted((SUBMISSIONS / "patterns").glob("*.cpp"))]
           + [f"compound/{p.stem}" for p in sorted((SUBMISSIONS / "compound").glob("*.cpp"))])


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.parametrize("name", SCANNED)
def test_no_zoo_report_says_what_its_tables_contradict(name, tmp_path):
    result = grade_once(SUBMISSIONS / f"{name}.cpp", tmp_path, GradeOptions(quick=True), write_reports=False)
    assert contradictions(result, render_all(result)["report.md"]) == []


# ---- pattern 12: a face size kept from the first call, in every instrument ------------------

@pytest.mark.slow
@pytest.mark.sandbox
def test_a_read_texture_that_keeps_the_first_face_size_loses_the_end_to_end_checks(tmp_path):
    """footprint/static-face-size_table (readTexture keeps W and H in statics;
    fetchColor right): read_texture (sizes in one process), arrows and renders
    (their faces set after a first call on larger faces) lose points;
    fetchColor's own checks, judged on its record, keep theirs.
    record/static-face-size_switch (the fetch side) is asserted in test_record_zoo."""
    result = grade_once(SUBMISSIONS / "footprint" / "static-face-size_table.cpp", tmp_path, GradeOptions(quick=True),
                        write_reports=False)
    by_name = {c.name: c for c in result.checks}
    assert all(by_name[c].score < by_name[c].max_score for c in ("read_texture", "arrows", "renders"))
    assert all(by_name[c].score == by_name[c].max_score for c in ("fetch_sweep", "stability"))
    assert "kept-between-calls" in {d.id for d in result.diagnoses}


@pytest.mark.slow
@pytest.mark.parametrize("name, kept", [("footprint/static-face-size_table", False), ("record/static-face-size_switch", False),
                                        ("correct/idiomatic", True)])
def test_the_arrows_see_a_kept_face_size_in_both_isolation_modes(isolation_mode, name, kept, tmp_path):
    """The arrows' faces follow a first call on larger faces in the same
    worker, in bubblewrap and in privilege-drop mode alike."""
    from grader.grading.grade import grade
    result = grade(SUBMISSIONS / f"{name}.cpp", tmp_path, GradeOptions(quick=True, only=("arrows",)), write_reports=False)
    assert result.isolation == isolation_mode
    arrows = {c.name: c for c in result.checks}["arrows"]
    assert (arrows.score == arrows.max_score) == kept, arrows.output
