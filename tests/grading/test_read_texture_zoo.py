"""The readTexture zoo (tests/submissions/footprint/, issue 29): readTextures
of the shapes students and engines write, each beside a right fetchColor.
Each file's truth was written from its code before grading, twice:

- X.json: the diagnoses the read_texture check must name (`causes`, ids
  exact), the ids its mistakes may also cause (`symptoms`), and that the
  check loses points;
- READS below: the same readTexture restated in numpy, which must give the
  compiled file's answers (the truth describes the code) and differ from the
  independent model tests/assignment_model.py (the code is wrong).

Measure (any version of the grader):
    PYTHONPATH=.:tests/helpers .venv/bin/python tests/grading/test_read_texture_zoo.py
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

import assignment_model
from grader.grading import catalogue
from grader.build import build_submission
from grader.grading.grade import GradeOptions
from grader.grading.results import GRADED
from grader.worker import sandbox
from grader.worker.lookups import open_lookups
from fake_bwrap import write_failing_bwrap
from grading_cache import grade_once
from project_paths import PROJECT_ROOT, SUBMISSIONS

ZOO = SUBMISSIONS / "footprint"
# blind/: shapes graded blind (truth committed before the first grading);
# attacks/: a motivated student's attacks on the footprint.
NAMES = sorted(p.relative_to(ZOO).with_suffix("").as_posix() for p in ZOO.rglob("*.cpp"))
ONLY = GradeOptions(quick=True, only=("read_texture",))


# ---- each file's readTexture, restated from its code -----------------------------

def _at(face, x, y):
    return face[y, x].astype(np.float64)


def _bilinear(face, px, py, x0, x1, y0, y1, a, b, at=_at):
    a, b = a[:, None], b[:, None]
    return (1 - b) * ((1 - a) * at(face, x0, y0) + a * at(face, x1, y0)) + b * ((1 - a) * at(face, x0, y1) + a * at(face, x1, y1))


def nearest_round_size_minus_one(face, u, v):
    h, w = face.shape[:2]
    # std::round rounds halves away from zero; u, v >= 0 here.
    return _at(face, np.floor(u * (w - 1) + 0.5).astype(int), np.floor(v * (h - 1) + 0.5).astype(int))


def box_quarter_weights_top_down(face, u, v):
    h, w = face.shape[:2]
    x0 = np.minimum(np.trunc(u * w).astype(int), w - 2)
    y0 = np.minimum(np.trunc(v * h).astype(int), h - 1)
    y1 = np.minimum(y0 + 1, h - 1)
    t = lambda x, y: _at(face, x, h - 1 - y)   # noqa: E731
    return 0.25 * (t(x0, y0) + t(x0 + 1, y0) + t(x0, y1) + t(x0 + 1, y1))


def single_texel_last_row_column(face, u, v):
    h, w = face.shape[:2]
    px, py = u * w, v * h
    x0, y0 = np.minimum(np.trunc(px).astype(int), w - 1), np.minimum(np.trunc(py).astype(int), h - 1)
    edge = (x0 == w - 1) | (y0 == h - 1)
    inner = _bilinear(face, px, py, x0, np.minimum(x0 + 1, w - 1), y0, np.minimum(y0 + 1, h - 1), px - x0, py - y0)
    return np.where(edge[:, None], _at(face, x0, y0), inner)


def transposed_index_clamped(face, u, v):
    """None where it reads past the face (the worker faults there)."""
    h, w = face.shape[:2]
    px, py = u * w, v * h
    x0 = np.clip(np.floor(px), 0, w - 1).astype(int)
    y0 = np.clip(np.floor(py), 0, h - 1).astype(int)
    x1, y1 = np.clip(x0 + 1, 0, w - 1), np.clip(y0 + 1, 0, h - 1)
    flat = face.reshape(-1, 3)

    def at(_face, x, y):
        k = x * w + y
        return np.where((k < len(flat))[:, None], flat[np.minimum(k, len(flat) - 1)].astype(np.float64), np.nan)
    return _bilinear(face, px, py, x0, x1, y0, y1, px - np.floor(px), py - np.floor(py), at)


def static_face_size(face, u, v):
    """In a fresh process (the first size it sees is this one): the handout's."""
    return assignment_model.read_bilinear(face[None], np.zeros(len(u), int), u, v)


def wrap_u_clamp_v(face, u, v):
    h, w = face.shape[:2]
    px, py = u * w, v * h
    xi, yi = np.floor(px).astype(int), np.floor(py).astype(int)
    x0 = np.mod(xi, w)
    return _bilinear(face, px, py, x0, np.mod(x0 + 1, w), np.clip(yi, 0, h - 1), np.clip(yi + 1, 0, h - 1),
                     px - xi, py - yi)


def scaled_by_size_plus_one(face, u, v):
    h, w = face.shape[:2]
    px, py = u * (w + 1), v * (h + 1)
    x0, y0 = np.trunc(px).astype(int), np.trunc(py).astype(int)
    cx = lambda x: np.clip(x, 0, w - 1)   # noqa: E731
    cy = lambda y: np.clip(y, 0, h - 1)   # noqa: E731
    return _bilinear(face, px, py, cx(x0), cx(x0 + 1), cy(y0), cy(y0 + 1), px - x0, py - y0)


def columns_right_to_left(face, u, v):
    h, w = face.shape[:2]
    px, py = u * w, v * h
    x0, y0 = np.minimum(np.trunc(px).astype(int), w - 1), np.minimum(np.trunc(py).astype(int), h - 1)
    at = lambda f, x, y: _at(f, w - 1 - x, y)   # noqa: E731
    return _bilinear(face, px, py, x0, np.minimum(x0 + 1, w - 1), y0, np.minimum(y0 + 1, h - 1),
                     px - np.trunc(px), py - np.trunc(py), at)


def u_right_to_left(face, u, v):
    return assignment_model.read_bilinear(face[None], np.zeros(len(u), int), 1 - u, v)


def v_top_to_bottom(face, u, v):
    return assignment_model.read_bilinear(face[None], np.zeros(len(u), int), u, 1 - v)


def uv_for_rows_and_columns(face, u, v):
    h, w = face.shape[:2]
    col, row = v * w, u * h
    x0, y0 = np.clip(np.floor(col), 0, w - 1).astype(int), np.clip(np.floor(row), 0, h - 1).astype(int)
    return _bilinear(face, col, row, x0, np.minimum(x0 + 1, w - 1), y0, np.minimum(y0 + 1, h - 1),
                     col - np.floor(col), row - np.floor(row))


def brightest_of_four(face, u, v):
    h, w = face.shape[:2]
    x0 = np.clip(np.trunc(u * w), 0, w - 1).astype(int)
    y0 = np.clip(np.trunc(v * h), 0, h - 1).astype(int)
    xs, ys = (x0, np.minimum(x0 + 1, w - 1)), (y0, np.minimum(y0 + 1, h - 1))
    # The first of the four in the code's order wins ties (a strict >).
    texels = np.stack([_at(face, xs[i], ys[j]) for j in (0, 1) for i in (0, 1)], axis=1)   # (n, 4, 3)
    # The sums in float then double, as t[0] + t[1] + t[2] adds floats.
    sums = np.stack([face[ys[j], xs[i]].sum(axis=1, dtype=np.float32) for j in (0, 1) for i in (0, 1)], axis=1)
    return texels[np.arange(len(u)), np.argmax(sums, axis=1)]


def pbrt_bilerp(face, u, v):
    h, w = face.shape[:2]
    x = (u.astype(np.float32) * np.float32(w) - np.float32(0.5)).astype(np.float64)
    y = (v.astype(np.float32) * np.float32(h) - np.float32(0.5)).astype(np.float64)
    xi, yi = np.floor(x).astype(int), np.floor(y).astype(int)
    cx = lambda i: np.clip(i, 0, w - 1)   # noqa: E731
    cy = lambda i: np.clip(i, 0, h - 1)   # noqa: E731
    return _bilinear(face, x, y, cx(xi), cx(xi + 1), cy(yi), cy(yi + 1), x - xi, y - yi)


def engine_repeat_sampler(face, u, v):
    h, w = face.shape[:2]
    x, y = u * w - 0.5, v * h - 0.5
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    return _bilinear(face, x, y, np.mod(x0, w), np.mod(x0 + 1, w), np.mod(y0, h), np.mod(y0 + 1, h), x - x0, y - y0)


def bilinear_on_impulses_only(face, u, v):
    """On random texels (never exactly 0 or 1): the texel (x0, y0)."""
    return assignment_model.read_nearest(face[None], np.zeros(len(u), int), u, v)


def bilinear_on_small_faces_only(face, u, v):
    h, w = face.shape[:2]
    read = assignment_model.read_nearest if w >= 32 or h >= 32 else assignment_model.read_bilinear
    return read(face[None], np.zeros(len(u), int), u, v)


READS = {
    "blind/pbrt-bilerp_switch": pbrt_bilerp,
    "blind/engine-repeat-sampler_table": engine_repeat_sampler,
    "attacks/bilinear-on-impulses-only_if-chain": bilinear_on_impulses_only,
    "attacks/bilinear-on-small-faces-only_switch": bilinear_on_small_faces_only,
    "nearest-round-size-minus-one_if-chain": nearest_round_size_minus_one,
    "box-quarter-weights-top-down_table": box_quarter_weights_top_down,
    "single-texel-last-row-column_switch": single_texel_last_row_column,
    "transposed-index-clamped_if-chain": transposed_index_clamped,
    "static-face-size_table": static_face_size,
    "wrap-u-clamp-v_switch": wrap_u_clamp_v,
    "scaled-by-size-plus-one_if-chain": scaled_by_size_plus_one,
    "columns-right-to-left_table": columns_right_to_left,
    "u-right-to-left_switch": u_right_to_left,
    "v-top-to-bottom_if-chain": v_top_to_bottom,
    "uv-for-rows-and-columns_table": uv_for_rows_and_columns,
    "brightest-of-four_switch": brightest_of_four,
}


def truth(name: str) -> dict:
    return json.loads((ZOO / f"{name}.json").read_text())


def test_every_file_has_both_truths():
    assert set(NAMES) == set(READS) == {p.relative_to(ZOO).with_suffix("").as_posix() for p in ZOO.rglob("*.json")}


# (W, H): square and not; one size per worker process, so a static is fresh.
SIZES = ((7, 5), (4, 10), (6, 6), (40, 33))


@pytest.mark.parametrize("name", NAMES)
def test_the_restated_read_is_the_code_and_is_wrong(name, rng):
    """The numpy truth gives the compiled file's answers (float rounding
    aside), and the independent model of the handout gives others."""
    build = build_submission(ZOO / f"{name}.cpp")
    assert build.ok, build.log
    differs = False
    with open_lookups(build.library) as lookups:
        for w, h in SIZES:
            faces = rng.random((6, h, w, 3), dtype=np.float32)
            k = np.arange(w + 1)
            u = np.concatenate([rng.random(200), k / w, (k[:-1] + 0.5) / w, [1.0, 1 - 2.0 ** -20]])
            v = np.concatenate([rng.random(200), rng.random(len(u) - 200)])
            uv = np.stack([np.concatenate([u, v]), np.concatenate([v, u])], axis=1)
            lookups.set_faces(faces)
            got = lookups.read_texture(2, uv).values
            want = READS[name](faces[2], uv[:, 0], uv[:, 1])
            known = np.isfinite(want).all(axis=1)
            assert np.allclose(got[known], want[known], atol=2e-5), name
            assert not np.isfinite(got[~known]).any(), "reads past the face where the truth says it does"
            handout = assignment_model.read_bilinear(faces, np.full(len(uv), 2), uv[:, 0], uv[:, 1])
            differs |= not np.allclose(got[known], handout[known], atol=1e-4)
    assert differs or name == "static-face-size_table", name   # a static is right in a fresh process


@pytest.mark.parametrize("name", [n for n in NAMES if n.startswith("attacks/")])
def test_an_attack_on_the_footprint_earns_no_more_than_the_starting_code(name, tmp_path):
    attack = grade_once(ZOO / f"{name}.cpp", tmp_path / "a", ONLY, write_reports=False)
    template = grade_once(PROJECT_ROOT / "student_template" / "EnvironmentMap.cpp",
                          tmp_path / "b", ONLY, write_reports=False)
    assert attack.checks[0].score <= template.checks[0].score == 0.0, attack.checks[0].output


def filtering(ids) -> set:
    return {i for i in ids if catalogue.describe(i).kind == "filtering"}


@pytest.mark.parametrize("name", NAMES)
def test_the_read_texture_check_names_exactly_what_the_code_does(name, tmp_path):
    t = truth(name)
    result = grade_once(ZOO / f"{name}.cpp", tmp_path, ONLY, write_reports=False)
    assert result.status == GRADED
    check = {c.name: c for c in result.checks}["read_texture"]
    found = [d.id for d in check.diagnoses]
    causes = [i for i, _ in t["causes"]]
    assert set(causes) <= set(found) and set(found) <= set(causes) | set(t["symptoms"]), (found, check.output)
    assert check.score < check.max_score
    # What to fix first: the first readTexture entry is a cause, in the catalogue's order.
    named = sorted(filtering(found), key=catalogue.sort_key)
    assert (named[:1] == sorted(causes, key=catalogue.sort_key)[:1]), named
    # Nothing proved: one call in numbers.
    if not causes:
        assert "At u = " in check.output and "yours " in check.output, check.output


def exact_share(names=NAMES) -> list[str]:
    """A line per file, graded now: exact or what is missing and false."""
    from grader.grading.grade import grade
    import tempfile
    lines = []
    for name in names:
        t = truth(name)
        with tempfile.TemporaryDirectory() as out:
            result = grade(ZOO / f"{name}.cpp", Path(out), ONLY, write_reports=False)
        check = {c.name: c for c in result.checks}["read_texture"]
        found = {d.id for d in check.diagnoses}
        causes = {i for i, _ in t["causes"]}
        missing, false = causes - found, found - causes - set(t["symptoms"])
        lines.append(f"{'exact' if not missing and not false else 'WRONG'}  {name}  {check.score:.2f}/25"
                     + (f"  missing {sorted(missing)}" if missing else "") + (f"  false {sorted(false)}" if false else ""))
    return lines


if __name__ == "__main__":
    print("\n".join(exact_share()))


# ---- both production isolation modes -------------------------------------------

@pytest.fixture(params=["bubblewrap", "privilege-drop"])
def mode(request, tmp_path, monkeypatch):
    """Bubblewrap as it runs here, and privilege-drop (root with a failing
    `bwrap` first on PATH, as in a container without user namespaces)."""
    if request.param == "bubblewrap" and sandbox.sandbox_problem() is not None:
        pytest.skip(f"bubblewrap does not run here: {sandbox.sandbox_problem()}")
    if request.param == "privilege-drop":
        if os.geteuid() != 0:
            pytest.skip("privilege-drop mode needs root")
        monkeypatch.setenv("PATH", f"{write_failing_bwrap(tmp_path / 'fakebin')}:{os.environ.get('PATH', '/usr/bin:/bin')}")
    sandbox.sandbox_problem.cache_clear()
    yield request.param
    sandbox.sandbox_problem.cache_clear()


# What depends on the worker: state kept across sizes in one process, reads
# past the face caught by guard pages, and the attacks.
IN_BOTH_MODES = ("static-face-size_table", "transposed-index-clamped_if-chain",
                 "attacks/bilinear-on-impulses-only_if-chain", "attacks/bilinear-on-small-faces-only_switch")


@pytest.mark.parametrize("name", IN_BOTH_MODES)
def test_the_verdict_is_the_same_in_both_isolation_modes(name, mode, tmp_path):
    result = grade_once(ZOO / f"{name}.cpp", tmp_path, ONLY, write_reports=False)
    assert result.isolation == mode
    check = result.checks[0]
    causes = {i for i, _ in truth(name)["causes"]}
    assert causes <= {d.id for d in check.diagnoses} <= causes | set(truth(name)["symptoms"]), check.output
    assert check.score < check.max_score and (check.score == 0.0 or not name.startswith("attacks/"))


# ---- the same behaviour, the same score (issue 30) --------------------------------

@pytest.mark.parametrize("name", ["single-texel-last-row-column_switch", "wrap-u-clamp-v_switch"])
def test_a_mistake_in_the_border_texels_scores_the_same_whatever_the_draw(name, tmp_path):
    """Mistakes made in some texels only: the random probes fall one per
    texel, so the share does not hinge on the seed (2.4 of 25 points apart
    over five seeds when two random points per axis were drawn)."""
    from grader.grading.grade import grade
    scores = {grade(ZOO / f"{name}.cpp", tmp_path / str(seed), GradeOptions(quick=True, only=("read_texture",), seed=seed),
                    write_reports=False).checks[0].score for seed in (1, 2, 3)}
    assert len(scores) == 1 and 0 < scores.pop() < 25, scores
