"""The record zoo (issue 29): fetchColor mistakes the record sees exactly.

Each submission in tests/submissions/record/ says on line 1 what it does.
Its truth is written here from the code, in the terms of the independent
model (tests/assignment_model.py), before any grading: what (face, u, v) it
asks readTexture for, per direction. The tests check (1) that truth against
the model (it differs from the handout's table exactly where the mistake
is), (2) the record of the real C++ against the truth, call by call, and (3)
the grading: the checks that lose and keep points, and no false diagnosis.
"""
from __future__ import annotations

import numpy as np
import pytest

import assignment_model as model
from grader.build import build_submission
from grader.checks.instruments import fetch_record
from grader.checks.instruments.directions import edges, fibonacci_sphere
from grader.checks.instruments.textures import coordinate_faces
from grader.worker.runner import SubmissionRunner
from project_paths import SUBMISSIONS

RECORD = SUBMISSIONS / "record"
FIRST, SECOND = (32, 32), (24, 16)     # face sizes, in one process, in this order
DIRS = np.concatenate([fibonacci_sphere(3_000), edges(16)])


def handout(dirs):
    """The table's request: the first touching face in x, y, z order (as the
    zoo's code breaks ties) and the model's (u, v)."""
    faces = np.argmax(model.touching_faces(dirs), axis=1)
    u, v = model.face_uv(dirs, faces)
    return faces, u, v


def static_face_size(dirs, size):
    faces, u, v = handout(dirs)
    stride = size[0] * size[1] * 3
    offset = faces * (FIRST[0] * FIRST[1] * 3)          # the first call's size, kept
    # A face starts there if the offset is a whole number of this size's faces, and one of the six.
    start = (offset % stride == 0) & (offset // stride < 6)
    return np.where(start, offset // stride, -1), u, v


def clamped(dirs, size):
    faces, u, v = handout(dirs)
    return faces, np.clip(u, 0.001, 0.999), np.clip(v, 0.001, 0.999)


def wraps_at_one(dirs, size):
    faces, u, v = handout(dirs)
    return faces, np.where(u == 1.0, 0.0, u), np.where(v == 1.0, 0.0, v)


# name: (truth, checks that lose points, checks that keep them, ids that would be false)
READ_IDS = {"nearest-neighbor", "half-texel-offset", "weights-swapped", "out-of-bounds-read", "unclamped-edge"}
MAPPING_IDS = {"u-flipped", "v-flipped", "uv-swapped", "wrong-face", "uv-mismatch", "face-order", "uv-rotated",
               "float-precision", "not-divided-by-m", "fetch-not-returned", "asks-otherwise"}
ZOO = {
    # Every check that asks fetchColor on faces of a second size in one process sees it: the
    # sweep's second size, and stability, arrows and renders after a first call on larger faces
    # (there the student's readTexture, given an address past the buffer, reads outside it).
    "static-face-size_switch": (static_face_size, {"fetch_sweep", "stability", "arrows", "renders"}, {"read_texture"},
                                (READ_IDS - {"out-of-bounds-read"}) | MAPPING_IDS),
    "clamped-uv_switch": (clamped, {"fetch_sweep"}, {"read_texture"}, READ_IDS | MAPPING_IDS | {"address-not-face-start"}),
    "wraps-at-one_switch": (wraps_at_one, {"fetch_sweep"}, {"read_texture"},
                            READ_IDS | MAPPING_IDS | {"address-not-face-start"}),
    "swapped-corners-read_switch": (lambda dirs, size: handout(dirs), {"read_texture"},
                                    {"fetch_sweep", "diagnosis", "stability", "arrows"},
                                    MAPPING_IDS | {"address-not-face-start", "discontinuous-seam"}),
}


# name: the id the record proves (issue 29: "ids exact"), said by the check that loses points.
NAMED = {
    "static-face-size_switch": ("address-not-face-start", "fetch_sweep"),
    "clamped-uv_switch": ("uv-clamped-inward", "fetch_sweep"),
    "wraps-at-one_switch": ("coordinate-wraps", "fetch_sweep"),
    "swapped-corners-read_switch": ("fractions-exchanged", "read_texture"),
}


def test_every_record_submission_has_its_truth():
    assert {p.stem for p in RECORD.glob("*.cpp")} == set(ZOO)


@pytest.mark.parametrize("name", sorted(ZOO))
def test_the_truth_differs_from_the_table_only_where_the_mistake_is(name):
    truth = ZOO[name][0]
    faces, u, v = handout(DIRS)
    for size in (FIRST, SECOND):
        f, tu, tv = truth(DIRS, size)
        wrong = (f != faces) | (tu != u) | (tv != v)
        if name.startswith("static"):
            assert not wrong.any() if size == FIRST else (wrong == (faces != 0)).all()
        elif name.startswith("clamped"):
            assert (wrong == ((u < 0.001) | (u > 0.999) | (v < 0.001) | (v > 0.999))).all() and wrong.any()
        elif name.startswith("wraps"):
            assert (wrong == ((u == 1) | (v == 1))).all() and wrong.any()
        else:
            assert not wrong.any()


@pytest.mark.parametrize("name", sorted(ZOO))
def test_the_record_is_the_truth_call_by_call(name, tmp_path):
    truth = ZOO[name][0]
    build = build_submission(RECORD / f"{name}.cpp")
    assert build.ok, build.log
    with SubmissionRunner(build.library, coordinate_faces(*FIRST), timeout_s=5.0) as runner:
        for size in (FIRST, SECOND):
            runner.set_faces(coordinate_faces(*size), same_process=True)
            rec = fetch_record.record(runner, DIRS)
            faces, u, v = truth(DIRS, size)
            assert (rec.calls == 1).all() and (rec.returned == 0).all()
            assert (rec.faces[:, 0] == faces).all(), (size, np.flatnonzero(rec.faces[:, 0] != faces)[:5])
            # The C++ computes 0.5 * (s / m + 1): the model's (1 + s/m) / 2 to a rounding or two.
            assert np.allclose(rec.uv[:, 0, 0], u, rtol=0, atol=1e-15) and np.allclose(rec.uv[:, 0, 1], v, rtol=0, atol=1e-15)


@pytest.mark.parametrize("name", sorted(ZOO))
def test_record_submission_is_graded_on_what_it_asks(name, tmp_path):
    from grader.grading.grade import GradeOptions
    from grader.grading.results import GRADED
    from grading_cache import grade_once
    _, loses, keeps, false = ZOO[name]
    result = grade_once(RECORD / f"{name}.cpp", tmp_path, GradeOptions(quick=True), write_reports=False)
    assert result.status == GRADED
    by_name = {c.name: c for c in result.checks}
    assert all(by_name[c].score < by_name[c].max_score for c in loses), {c: by_name[c].score for c in loses}
    assert all(by_name[c].score == by_name[c].max_score for c in keeps), {c: by_name[c].score for c in keeps}
    said = {d.id for d in result.diagnoses}
    assert not said & false, said & false
    named, where = NAMED[name]
    assert named in {d.id for d in by_name[where].diagnoses}, by_name[where].output
    # What to fix first (catalogue order, reports.view.group_diagnoses) leads with it.
    from grader.grading import catalogue
    assert sorted(said, key=catalogue.sort_key)[0] == named, sorted(said, key=catalogue.sort_key)
