"""readTexture's measured footprint (grader/checks/instruments/footprint.py)
and the read_texture check that judges and describes it, on in-process
fakes (tests/fake_lookups.py): milliseconds, no compiler. Expected weights
are worked out here by hand from the handout's equations (1)-(3)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fake_lookups import FakeLookups
from grader.envmap import library
from grader.checks import read_texture as rt
from grader.checks.context import CheckContext
from grader.checks.instruments import footprint as fp
from grader.grading.results import FAILED, PASSED, CheckResult


def reference_read(uv):
    return lambda faces: library.CubeMap(faces).read_texture(fp.FACE, uv, "bilinear")


def test_impulses_measure_the_handouts_weights():
    # 4 x 3 face. u = 1.5/4: p.x = 1.5, columns 1 and 2, half each; v = 1.25/3:
    # p.y = 1.25, rows 1 and 2 with 0.75 and 0.25. u = 1, v = 0: the clamped corner.
    uv = np.array([[1.5 / 4, 1.25 / 3], [1.0, 0.0]])
    print_ = fp.measure(reference_read(uv), (4, 3), uv)
    expected = np.zeros((2, 3, 4))
    expected[0, 1, 1:3], expected[0, 2, 1:3] = 0.375, 0.125
    expected[1, 0, 3] = 1.0
    np.testing.assert_allclose(print_.weights, expected, atol=1e-6)
    assert print_.taps(1) == [(3, 0, 1.0)]
    assert print_.separable.all() and print_.answered.all()


def test_a_linear_read_is_predicted_on_any_texels(rng):
    uv = fp.probe_points(5, 4)
    print_ = fp.measure(reference_read(uv), (5, 4), uv)
    texels = rng.random((6, 4, 5, 3), dtype=np.float32)
    np.testing.assert_allclose(fp.predict(print_, texels[fp.FACE]), reference_read(uv)(texels), atol=1e-6)


def test_probes_include_where_lookups_differ():
    c = fp.probe_coordinates(4)
    for want in (0.0, 1.0, 1 - 2.0 ** -20, 0.25, 0.75, 0.125, 0.875, 0.0625):
        assert np.isclose(c, want, rtol=0, atol=1e-12).any(), want


def run_check(lookups) -> tuple[CheckResult, rt.ReadTextureFinding]:
    ctx = CheckContext(lookups=lookups, seed=11, artifacts=Path("/nonexistent"), quick=True)
    result = CheckResult(name="read_texture", title="")
    finding = rt.read_texture(ctx, result)
    return result, finding


def test_the_handouts_read_passes_with_every_probe():
    result, finding = run_check(FakeLookups())
    assert (result.status, result.fraction, result.diagnoses) == (PASSED, 1.0, []) and finding.ok


def test_the_starting_codes_nearest_texel_scores_nothing():
    result, finding = run_check(FakeLookups(texture="nearest"))
    assert result.status == FAILED and result.fraction == 0.0
    assert [d.id for d in result.diagnoses] == ["nearest-neighbor"] and finding.mistake == "nearest-neighbor"


@pytest.mark.parametrize("texture, ids", [
    ("half-texel", ["half-texel-offset"]),
    ("size-minus-one", ["scaled-by-size-minus-one"]),
    ("u-flipped", ["texture-u-flipped"]),
    ("v-flipped", ["texture-v-flipped"]),
    ("uv-swapped", ["texture-uv-swapped"]),      # the fake reads at (v, u): x = vW, y = uH
    ("out-of-bounds", ["unclamped-edge", "out-of-bounds-read"]),
])
def test_a_mistake_is_named_from_its_footprint(texture, ids):
    result, _finding = run_check(FakeLookups(texture=texture))
    assert sorted(d.id for d in result.diagnoses) == sorted(ids), result.output


class ContentDependent(FakeLookups):
    """The handout's read, except that an answer above 0.5 in red is halved:
    a test on the colour, invisible on impulses whose 1 is in G or B."""

    def read_texture(self, face, uv, placement="end"):
        out = super().read_texture(face, uv, placement)
        values = out.values.copy()
        values[values[:, 0] > 0.5, 0] *= 0.5
        out.values = values
        return out


def test_answers_that_are_no_blend_of_the_texels_are_said_to_be_none():
    result, _finding = run_check(ContentDependent())
    assert [d.id for d in result.diagnoses][:1] == ["not-a-blend"], result.output
    assert result.fraction < 1.0


class SizeKept(FakeLookups):
    """The face size of the first call kept, as a static would."""

    def __init__(self):
        super().__init__()
        self.kept = None

    def set_faces(self, faces, same_process: bool = False):
        # A new texel count: a new worker process, a fresh static. (The
        # runner keeps a worker for smaller faces asked with same_process,
        # as readTexture in context is; the fake's fetchColor reads without
        # this readTexture, so there a kept size would tell the two apart,
        # which the real code, one readTexture for both, never does.)
        if self.kept is None or faces.shape[1] * faces.shape[2] != self.faces.shape[1] * self.faces.shape[2]:
            self.kept = faces.shape[1:3]
        super().set_faces(faces)

    def read_texture(self, face, uv, placement="end"):
        h, w = self.faces.shape[1:3]
        kh, kw = self.kept
        flat = self.faces[face].reshape(-1, 3)
        uv = np.asarray(uv, np.float64).reshape(-1, 2)
        # The handout's bilinear with (kw, kh) for (W, H), indexing the flat face with kw.
        px, py = uv[:, 0] * kw, uv[:, 1] * kh
        x0, y0 = np.floor(px), np.floor(py)
        a, b = (px - x0)[:, None], (py - y0)[:, None]
        cx = lambda x: np.clip(x, 0, kw - 1).astype(int)   # noqa: E731
        cy = lambda y: np.clip(y, 0, kh - 1).astype(int)   # noqa: E731
        at = lambda x, y: flat[np.minimum(cy(y) * kw + cx(x), w * h - 1)].astype(np.float64)   # noqa: E731
        values = (1 - b) * ((1 - a) * at(x0, y0) + a * at(x0 + 1, y0)) + b * ((1 - a) * at(x0, y0 + 1) + a * at(x0 + 1, y0 + 1))
        return self._outcome(values, np.zeros(len(uv), bool), None, "readTexture")


def test_a_size_kept_from_an_earlier_call_shows_on_the_second_size_in_a_process():
    result, finding = run_check(SizeKept())
    assert [d.id for d in result.diagnoses] == ["kept-between-calls"], result.output
    # Right on the first size of each process, wrong on 3 x 4 after 4 x 3: scored there.
    assert finding.by_size[0] == 1.0 and finding.by_size[1] < 0.5 and result.fraction == min(finding.by_size)


# ---- three readTextures that blend, but not as the handout does (issue 29, patterns 4, 7, 13) ----
# Each is written from what it is, on the face the fake hands over; the
# read_texture check must name it from the footprint alone.

def _blend(face: np.ndarray, x0, y0, x1, y1, wx, wy) -> np.ndarray:
    """sum of the four texels (clamped to the face) with weights (1 - wx, wx) x (1 - wy, wy)."""
    h, w = face.shape[:2]
    cx0, cx1 = np.clip(x0, 0, w - 1), np.clip(x1, 0, w - 1)
    cy0, cy1 = np.clip(y0, 0, h - 1), np.clip(y1, 0, h - 1)
    wx, wy = wx[:, None], wy[:, None]
    f = face.astype(np.float64)
    return ((1 - wy) * ((1 - wx) * f[cy0, cx0] + wx * f[cy0, cx1])
            + wy * ((1 - wx) * f[cy1, cx0] + wx * f[cy1, cx1]))


class BlendLookups(FakeLookups):
    """A readTexture given as read(face (H, W, 3), u, v) -> (n, 3)."""

    def __init__(self, read):
        super().__init__()
        self.read = read

    def read_texture(self, face, uv, placement="end"):
        uv = np.asarray(uv, np.float64).reshape(-1, 2)
        values = self.read(self.faces[face], uv[:, 0], uv[:, 1])
        return self._outcome(values, np.zeros(len(uv), bool), lambda i: "readTexture", "readTexture")

    def _read(self, faces, uv):
        """fetchColor's calls go through the same readTexture."""
        values = np.full((len(uv), 3), np.nan)
        for f in np.unique(faces[faces >= 0]):
            rows = faces == f
            values[rows] = self.read(self.faces[f], uv[rows, 0], uv[rows, 1])
        return values, np.zeros(len(uv), bool)


def _lattice(face, u, v, lower=np.floor):
    """(p.x, p.y, x0, y0): p = (uW, vH) and its lattice point, `lower` of p."""
    h, w = face.shape[:2]
    px, py = u * w, v * h
    return px, py, lower(px).astype(int), lower(py).astype(int)


def rounded_lattice(face, u, v):
    """x0 = round(uW) (half up), alpha = uW - x0 (in [-0.5, 0.5)), the blend of x0 and x0 + 1; the same in y."""
    px, py, x0, y0 = _lattice(face, u, v, lambda p: np.floor(p + 0.5))
    return _blend(face, x0, y0, x0 + 1, y0 + 1, px - x0, py - y0)


def rounded_half_to_even(face, u, v):
    """As rounded_lattice, with nearbyint's ties: p exactly halfway goes to the even lattice point."""
    px, py, x0, y0 = _lattice(face, u, v, np.rint)
    return _blend(face, x0, y0, x0 + 1, y0 + 1, px - x0, py - y0)


def fractions_exchanged(face, u, v):
    """The handout's lattice points, the columns weighed by beta and the rows by alpha (c01 and c10 exchanged)."""
    px, py, x0, y0 = _lattice(face, u, v)
    return _blend(face, x0, y0, x0 + 1, y0 + 1, py - y0, px - x0)


def alpha_for_both_axes(face, u, v):
    """The handout's lattice points, both axes weighed by alpha (beta never computed)."""
    px, py, x0, y0 = _lattice(face, u, v)
    return _blend(face, x0, y0, x0 + 1, y0 + 1, px - x0, px - x0)


def _single_texel_where(face, u, v, alone):
    """The handout's blend, except texel (x0, y0) alone where alone(x0, y0, W, H)."""
    h, w = face.shape[:2]
    px, py, x0, y0 = _lattice(face, u, v)
    x0, y0 = np.minimum(x0, w - 1), np.minimum(y0, h - 1)
    out = _blend(face, x0, y0, x0 + 1, y0 + 1, px - x0, py - y0)
    edge = alone(x0, y0, w, h)
    out[edge] = face[y0[edge], x0[edge]]
    return out


def single_texel_at_edges(face, u, v):
    """Texel (x0, y0) alone on the last column and the last row."""
    return _single_texel_where(face, u, v, lambda x0, y0, w, h: (x0 == w - 1) | (y0 == h - 1))


def single_texel_on_the_last_column(face, u, v):
    """Texel (x0, y0) alone where x0 + 1 >= W (the last row blends)."""
    return _single_texel_where(face, u, v, lambda x0, y0, w, h: x0 + 1 >= w)


@pytest.mark.parametrize("read, ids", [
    (rounded_lattice, ["lattice-rounded"]),
    (rounded_half_to_even, ["lattice-rounded"]),
    (single_texel_on_the_last_column, ["edge-single-texel"]),
    (fractions_exchanged, ["fractions-exchanged"]),
    (alpha_for_both_axes, ["fractions-exchanged"]),
    (single_texel_at_edges, ["edge-single-texel"]),
])
def test_a_blend_that_is_not_the_handouts_is_named_from_its_footprint(read, ids):
    result, finding = run_check(BlendLookups(read))
    assert result.status == FAILED and [d.id for d in result.diagnoses] == ids, result.output
    assert finding.mistake == ids[0]
    # Its evidence goes with it: the footprint in words, or a probe in numbers.
    assert "Measured on every face size" in result.output or "At u = " in result.output
    if read is single_texel_on_the_last_column:
        # Said of the border where it happens only (the blind2 zoo's last-column file).
        assert "On the last column (x0 = W - 1) readTexture returns" in result.output
        assert "last row (y0" not in result.output.split("What the measurements prove:")[1], result.output
    if read is alpha_for_both_axes:
        # Which axis, in the measured words: x as the handout, y by u's fraction.
        assert ("along x it blends the two texels around uW with weights that follow it; along y it blends the two "
                "texels around vH with weights that follow the fraction of uW") in result.output, result.output


def test_single_texels_at_the_edges_beside_another_mistake_inside_are_not_called_edge_single_texel():
    """The edge rule needs every probe that differs to be a single texel on
    the last row or column: with texel (0, 0) read alone inside texel (1, 1)
    too (still a fixed blend), nothing is named for the edges."""
    def also_inside(face, u, v):
        out = single_texel_at_edges(face, u, v)
        h, w = face.shape[:2]
        inside = (np.floor(u * w) == 1) & (np.floor(v * h) == 1)
        out[inside] = face[0, 0]
        return out
    result, _finding = run_check(BlendLookups(also_inside))
    assert result.status == FAILED and "edge-single-texel" not in [d.id for d in result.diagnoses], result.output
