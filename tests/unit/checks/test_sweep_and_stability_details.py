"""fetch_sweep does not credit the directions where the student's own
readTexture crashes at the handout's face and (u, v); stability says when fetchColor is wrong
only next to the cube's edges, and its NaN detail blames no particular cause.

Fakes in-process (tests/helpers/fake_lookups.py), no compiler.
"""
from __future__ import annotations

import numpy as np
import pytest

from fake_lookups import FACES, FakeLookups
from grader.envmap import library
from grader.checks.instruments import texture_model as tm
from grader.grading.results import FAILED, PASSED
from test_checks_unit import ids, run

# x1 = x0 + 1 and y1 = y0 + 1 never clamped: reads the next row, or past the
# last face's end (where the worker's guard page faults).
UNCLAMPED = tm.TextureModel(x=tm.Axis(edge="none"), y=tm.Axis(edge="none"))


class UnclampedLookups(FakeLookups):
    """A correct fetchColor (or one with the given mistakes) over an
    unclamped readTexture, with memory laid out as the worker lays it out."""

    def read_texture(self, face, uv, placement="end"):
        uv = np.asarray(uv, np.float64).reshape(-1, 2)
        values, past = tm.evaluate(UNCLAMPED, self.faces[face], uv)
        return self._outcome(values, past, lambda i: f"readTexture(face {FACES[face]}, {uv[i]!r})", "readTexture")

    def _read(self, faces, uv):
        return tm.evaluate_in_buffer(UNCLAMPED, self.faces, faces, uv)


# slow: checks on fake lookups whose readTexture no model fits, or fits only after a long search (6-28 s each); the cheaper cases of each family stay fast
@pytest.mark.slow
def test_sweep_credits_fetch_color_over_a_read_texture_that_reads_past_the_faces(tmp_path):
    """A correct fetchColor over an unclamped readTexture earns every
    direction: it is judged on the (face, u, v) it asks for, as if its
    readTexture were the handout's (issue 29; issue 18 denied the directions
    where that readTexture reads past the face). readTexture loses its own."""
    results = run(UnclampedLookups(), tmp_path, "fetch_sweep")
    texture, sweep = results["read_texture"], results["fetch_sweep"]
    assert texture.status == FAILED and ("unclamped-edge", None) in ids(texture)
    assert sweep.fraction == 1.0, sweep.output[:300]


# slow: checks on fake lookups whose readTexture no model fits, or fits only after a long search (6-28 s each); the cheaper cases of each family stay fast
@pytest.mark.slow
def test_a_fetch_color_mistake_still_shows_through_an_unclamped_read_texture(tmp_path):
    sweep = run(UnclampedLookups(fetch={"+X": "u-flipped"}), tmp_path, "fetch_sweep")["fetch_sweep"]
    assert sweep.status == FAILED
    # +X is about a sixth of the sphere; the rest stays right.
    assert 0.75 < sweep.fraction < 0.9, sweep.fraction


class UnfittableUnclampedLookups(UnclampedLookups):
    """The unclamped readTexture, also wrong at (u, v) = (0.5, 0.5) called
    alone: no model fits, so nothing predicts its reads into the next face."""

    def read_texture(self, face, uv, placement="end"):
        out = super().read_texture(face, uv, placement)
        out.values[(np.asarray(uv).reshape(-1, 2) == 0.5).all(axis=1)] = 0.0
        return out


def test_an_edge_read_into_the_next_face_is_told_from_a_tie_sent_astray():
    """The rule itself: an answer from face k + 1's first row, in the column
    touched face k's u gives, is readTexture reading past k (faces one above
    the other in the buffer); another column, row or face is not."""
    from grader.checks.instruments.face_recovery import FACE_SIZE, _edge_read
    touched = np.zeros((5, 6), bool)
    touched[:, 0] = touched[:, 2] = True                  # an edge of +X and +Y
    column = np.full((5, 6), np.nan)
    column[:, 0], column[:, 2] = 7.0, 20.0
    faces = np.array([1, 1, 3, 1, 4])                     # -X, -X, -Y, -X, +Z
    px = np.array([7.0, 12.0, 20.0, 7.2, 7.0])
    py = np.array([0.0, 0.0, 0.0, FACE_SIZE - 1.0, 0.0])
    assert _edge_read(faces, px, py, touched, column).tolist() == [True, False, True, False, False]


# slow: a mutant built and its truth decided per case (5-12 s); crashing0, wrong and not-compiling stay fast
@pytest.mark.slow
def test_reads_past_the_face_at_ties_are_not_blamed_on_the_tie_rule(tmp_path):
    """A correct fetchColor (>= at ties) over an unclamped readTexture no model
    fits: no tie is said to be sent to an untouched face (a guard on the
    whole path; the rule is tested above)."""
    results = run(UnfittableUnclampedLookups(), tmp_path, "diagnosis")
    from grader.checks.instruments import texture_model
    assert not texture_model.fit(UnfittableUnclampedLookups()).fits     # what diagnosis reads through
    assert "tie-untouched-face" not in {i for i, _ in ids(results["diagnosis"])}, results["diagnosis"].output


class BorderClampedLookups(FakeLookups):
    """fetchColor clamps (u, v) to [1/W, 1 - 1/W]: wrong only within one
    texel of each face's border."""

    def fetch(self, dirs, placement="end"):
        dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
        faces, uv = library.direction_to_face(dirs)
        h, w = self.faces.shape[1:3]
        uv = np.clip(uv, [1.0 / w, 1.0 / h], [1.0 - 1.0 / w, 1.0 - 1.0 / h])
        values, failed = self._read(faces.copy(), uv)
        values[~np.isfinite(dirs).all(axis=1) | ~dirs.any(axis=1)] = 0.0
        return self._outcome(values, failed, lambda i: f"fetchColor({dirs[i]!r})", "fetchColor")


def test_wrong_only_next_to_the_edges_gets_the_seam_hint(tmp_path):
    r = run(BorderClampedLookups(), tmp_path, "stability")["stability"]
    seams = [d for d in r.diagnoses if d.id == "discontinuous-seam"]
    assert len(seams) == 1, ids(r)
    assert "only directions within one texel of a face's border are wrong" in seams[0].detail


def test_a_mistake_inside_the_faces_gets_no_seam_only_hint(tmp_path):
    r = run(FakeLookups(fetch={"+X": "u-flipped"}), tmp_path, "stability")["stability"]
    assert ("discontinuous-seam", None) in ids(r)
    assert all("within one texel" not in d.detail for d in r.diagnoses)


class FloatComponentsLookups(FakeLookups):
    """Converts the components to float first: tiny ones become 0, and the
    projection divides 0 by 0."""

    def fetch(self, dirs, placement="end"):
        dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
        out = super().fetch(dirs, placement)
        with np.errstate(over="ignore"):
            as_float = dirs.astype(np.float32)
        lost = np.isfinite(dirs).all(axis=1) & dirs.any(axis=1) & ~as_float.any(axis=1)
        out.values[lost] = np.nan
        return out


def test_nan_detail_does_not_blame_a_squared_length(tmp_path):
    r = run(FloatComponentsLookups(), tmp_path, "stability")["stability"]
    nan = [d for d in r.diagnoses if d.id == "nan-output"]
    assert len(nan) == 1, ids(r)
    assert "squared" not in nan[0].detail and "finite and not zero" in nan[0].detail


# slow: checks on fake lookups whose readTexture no model fits, or fits only after a long search (6-28 s each); the cheaper cases of each family stay fast
@pytest.mark.slow
@pytest.mark.sandbox
def test_honestly_wrong_everywhere_is_not_timed_output_wrong(tmp_path):
    """+Y and -Y swapped over a nearest readTexture: wrong the same way timed
    or not, on the timing faces as in the sweep. Speed times it; neither
    timed-output-wrong nor timing-faces-wrong (issue 19: one id, one meaning)."""
    fake = FakeLookups(fetch={"+Y": "wrong-face:-Y", "-Y": "wrong-face:+Y"}, texture="nearest")
    results = run(fake, tmp_path, "speed")
    assert 0.5 <= results["fetch_sweep"].fraction < 0.9
    speed = results["speed"]
    assert not {"timed-output-wrong", "timing-faces-wrong"} & {i for i, _ in ids(speed)}, speed.output
    assert speed.metrics["timed_agrees_with_untimed"] == 1.0
