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
from grader.grading.results import FAILED, PASSED
from test_checks_unit import ids, run


def unclamped(buffer: np.ndarray, faces: np.ndarray, uv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(values, past) of the handout's bilinear with x0 = (int)(uW), x1 = x0 + 1
    (and y) never clamped, on `buffer` (k, H, W, 3) of k faces one after the
    other: a read past a row's end reads the next row, past the buffer's end
    faults (the worker's guard page)."""
    k, h, w = buffer.shape[:3]
    flat = buffer.reshape(-1, 3).astype(np.float64)
    px, py = uv[:, 0] * w, uv[:, 1] * h
    x0, y0 = np.floor(px).astype(np.int64), np.floor(py).astype(np.int64)
    a, b = (px - x0)[:, None], (py - y0)[:, None]
    index = [(faces * h + y) * w + x for y in (y0, y0 + 1) for x in (x0, x0 + 1)]
    past = np.zeros(len(uv), bool)
    for i in index:
        past |= (i < 0) | (i >= len(flat))
    c00, c10, c01, c11 = (flat[np.clip(i, 0, len(flat) - 1)] for i in index)
    values = (1 - b) * ((1 - a) * c00 + a * c10) + b * ((1 - a) * c01 + a * c11)
    return values, past


class UnclampedLookups(FakeLookups):
    """A correct fetchColor (or one with the given mistakes) over an
    unclamped readTexture, with memory laid out as the worker lays it out."""

    def read_texture(self, face, uv, placement="end"):
        uv = np.asarray(uv, np.float64).reshape(-1, 2)
        values, past = unclamped(self.faces[face][None], np.zeros(len(uv), np.int64), uv)
        return self._outcome(values, past, lambda i: f"readTexture(face {FACES[face]}, {uv[i]!r})", "readTexture")

    def _read(self, faces, uv):
        return unclamped(self.faces, np.asarray(faces, np.int64), uv)


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


# slow: the diagnosis check's recordings on fake lookups (several seconds)
@pytest.mark.slow
def test_reads_past_the_face_at_ties_are_not_blamed_on_the_tie_rule(tmp_path):
    """A correct fetchColor (>= at ties) over an unclamped readTexture: no
    tie is said to be sent to an untouched face (the record says what
    fetchColor asked, whatever readTexture reads)."""
    results = run(UnclampedLookups(), tmp_path, "diagnosis")
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


# ---- faces' borders, as the record shows them (issue 29, patterns 5 and 10) ----

@pytest.mark.parametrize("mistake, named", [("wraps-at-one", "coordinate-wraps"), ("clamped-inward", "uv-clamped-inward"),
                                            ("clamped-to-texel-centres", "uv-clamped-inward")])
def test_a_mistake_only_at_faces_borders_is_named_from_the_record(mistake, named, tmp_path):
    sweep = run(FakeLookups(fetch=mistake), tmp_path, "fetch_sweep")["fetch_sweep"]
    said = [d for d in sweep.diagnoses if d.id == named]
    assert sweep.status == FAILED and said, sweep.output[:500]
    other = {"coordinate-wraps", "uv-clamped-inward"} - {named}
    assert not other & {d.id for d in sweep.diagnoses}
    # With the faces where it is every mistake (ties go to X, then Y: +Z and -Z never
    # ask for a coordinate of 1), and one direction in numbers.
    assert "+X, -X, +Y, -Y" in said[0].detail and "fetchColor(Vector3(" in said[0].detail


def test_a_flipped_face_is_not_called_a_wrap_or_a_clamp(tmp_path):
    """u flipped on +X asks 0 where the table gives 1 on that face's border
    too, but its inside is wrong as well: no border statement for it."""
    sweep = run(FakeLookups(fetch={"+X": "u-flipped"}), tmp_path, "fetch_sweep")["fetch_sweep"]
    assert sweep.status == FAILED
    assert not {"coordinate-wraps", "uv-clamped-inward"} & {d.id for d in sweep.diagnoses}


def test_a_clamp_to_the_border_texels_centres_is_said_with_its_range_on_each_face_size(tmp_path):
    """Half a texel is 1/64 on the sweep's 32 x 32 faces and 1/48, 1/32 on the
    second size's 24 x 16: the range is read per face size and coordinate."""
    sweep = run(FakeLookups(fetch="clamped-to-texel-centres"), tmp_path, "fetch_sweep")["fetch_sweep"]
    said = [d for d in sweep.diagnoses if d.id == "uv-clamped-inward"][0]
    for side in ("u at least 0.015625 (0.5 texels", "v at least 0.015625 (0.5 texels", "u at most 0.984375 (0.5 texels",
                 "v at most 0.984375 (0.5 texels"):
        assert side in said.detail, said.detail
