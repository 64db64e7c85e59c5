"""The read-back instrument's nearest-colour search (numpy, so the student
kit needs no scipy) gives the answers scipy's cKDTree gave it, exactly.

`kd_tree_read_back` is the code readback.Calibration.read_back ran before
(cKDTree, the 64 nearest calibrated colours), kept here on purpose as the
comparison; scipy stays in the grader's development environment for it.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from fake_lookups import FakeLookups
from grader.checks.instruments import readback
from grader.checks.instruments.directions import fibonacci_sphere
from grader.checks.instruments.textures import coordinate_faces, decode_sample_coordinates

FACE = 32      # face_recovery.FACE_SIZE: the faces the diagnosis reads back on


def kd_tree_read_back(cal: readback.Calibration, answers: np.ndarray):
    """(face, uv, how many answers had 64 tied neighbours): the earlier code."""
    tree = cKDTree(cal.colour)
    answers = np.asarray(answers, np.float64).reshape(-1, 3)
    face, _, _ = decode_sample_coordinates(answers)
    uv = np.full((len(answers), 2), np.nan)
    rows = np.flatnonzero(face >= 0)
    if not len(rows):
        return face, uv, 0
    k = min(64, len(cal.uv))
    dist, idx = tree.query(answers[rows, :2], k=k)
    dist, idx = dist.reshape(len(rows), k), idx.reshape(len(rows), k)
    near = dist <= dist[:, :1] + 1e-6
    centroid = (cal.uv[idx] * near[..., None]).sum(axis=1) / near.sum(axis=1)[:, None]
    found = dist[:, 0] <= 0.5
    uv[rows[found]] = centroid[found]
    return face, uv, int((near.all(axis=1) & found).sum())


def calibrated(texture: str, fetch):
    lookups = FakeLookups(texture=texture, fetch=fetch)
    faces = coordinate_faces(FACE, FACE)
    lookups.set_faces(faces)
    cal = readback.calibrate(lookups, faces)
    assert cal is not None
    return lookups, cal


@pytest.mark.parametrize("texture, fetch", [
    ("correct", None), ("correct", "inset"), ("nearest", {"+X": "u-flipped"}), ("half-texel", "inset"),
    ("uv-swapped", None), ("scrambled", "inset"), ("one-point", {"-Y": "uv-swapped"}),
])
def test_read_back_equals_the_kd_tree_search(texture, fetch):
    lookups, cal = calibrated(texture, fetch)
    answers = np.asarray(lookups.fetch(fibonacci_sphere(4000)).values, np.float64)
    # Answers off the calibrated colours too: between them, and beyond RADIUS.
    noise = np.random.default_rng(20261202).normal(0.0, 0.4, answers.shape) * [1, 1, 0]
    for values in (answers, answers + noise):
        face, uv = cal.read_back(values)
        kd_face, kd_uv, tied_64 = kd_tree_read_back(cal, values)
        assert tied_64 == 0            # the earlier code's 64-neighbour cap was never reached here
        np.testing.assert_array_equal(face, kd_face)
        np.testing.assert_array_equal(uv, kd_uv)          # bit for bit, NaN where not found
        assert np.isfinite(uv).any() and np.isnan(uv).any() == np.isnan(kd_uv).any()


def test_an_answer_far_from_every_calibrated_colour_is_not_read_back():
    _, cal = calibrated("correct", None)
    face, uv = cal.read_back(np.array([[5.0, 5.0, 3.0], [5.0, 40.0, 3.0], [1e30, -1e30, 3.0], [np.inf, 1, 3.0]]))
    assert face.tolist()[0] == 2 and np.isfinite(uv[0]).all()
    assert np.isnan(uv[1:]).all()


def test_every_tied_grid_point_counts_past_64():
    """A readTexture flat over many grid points (here 9 x 9 = 81 give one
    colour) reads back as the centroid of all of them, as the docstring says;
    the tree's 64-neighbour query took 64 of them in its own order."""
    g = np.linspace(0.0, 1.0, 33)
    uu, vv = np.meshgrid(g, g, indexing="ij")
    uv = np.stack([uu.ravel(), vv.ravel()], axis=1)
    colour = uv * 32 + 1
    flat = (uv[:, 0] <= 0.25 + 1e-9) & (uv[:, 1] <= 0.25 + 1e-9)
    colour[flat] = [2.0, 2.0]
    cal = readback.Calibration(uv, colour, (32, 32))
    face, got = cal.read_back(np.array([[2.0, 2.0, 3.0]]))
    assert flat.sum() == 81
    np.testing.assert_allclose(got[0], uv[flat].mean(axis=0), rtol=0, atol=1e-15)
    _, kd_uv, tied_64 = kd_tree_read_back(cal, np.array([[2.0, 2.0, 3.0]]))
    assert tied_64 == 1
