"""The one comparison of a lookup with the reference, used by every check.

`Comparison` holds which inputs matched, the error of each, and a short
explanation of the worst mismatches (expected, actual, input) written for a
student. Tolerances come from float rounding (see `tolerance`), never from
eyeballing.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...envmap import oracle, library
from ...i18n import _
from .directions import tied_axes

FLOAT_EPS = 2.0 ** -24   # float32 unit roundoff
NUDGE = 2.0 ** -30       # makes a tied component strictly the largest

# Random inputs keep fixed ones honest (code that knows the public inputs
# gains nothing by it) but score nothing themselves: a score must not hinge
# on the draw (issue 30). A random share below the fixed one by more than
# STANDARD_ERRORS of its standard errors (chance: 1 in 10^9) is not chance:
# then it is the share.
STANDARD_ERRORS = 6.0


def chance_margin(count: int, fixed: float) -> float:
    """How far below `fixed` a share of `count` random cases may fall by
    chance: STANDARD_ERRORS standard errors."""
    n = max(count, 1)
    return float(STANDARD_ERRORS * np.sqrt(max(fixed * (1 - fixed), 1.0 / n) / n))


def below_by_more_than_chance(drawn: float, count: int, fixed: float) -> bool:
    """A share `drawn` of `count` random cases is lower than the fixed
    cases' share `fixed` by more than chance_margin."""
    return drawn < fixed - chance_margin(count, fixed)


def tolerance(face_width: int, face_height: int, magnitude: np.ndarray | float) -> np.ndarray | float:
    """Largest difference from the reference that float rounding explains.

    A student may compute in float rather than double. Then p = u*W carries an
    error up to W * 2^-24 texels, which moves the colour by at most that times
    the largest texel difference (<= 2 * magnitude); the three lerps of
    equations (1)-(3) add about 8 roundings of the magnitude. A factor 4 of
    margin covers -ffast-math reassociation. With magnitude 1 and W = 64 this
    is 3.3e-5: the mistakes the checks look for are at least 1e-2.
    """
    size = max(face_width, face_height)
    return 4.0 * (2.0 * size + 8.0) * FLOAT_EPS * np.maximum(magnitude, 1e-30) + 1e-12


def _nudged(dirs: np.ndarray, axis: int) -> np.ndarray:
    """`dirs` with component `axis` made strictly the largest in magnitude,
    so the reference alone decides the face; (u, v) move by ~1e-9 texel."""
    nudged = np.array(dirs, np.float64)
    # Scale by a power of two (exact, so (u, v) do not move) until the
    # largest component is in [0.5, 1): a denormal direction has too few
    # bits for a nudge to stay small.
    with np.errstate(invalid="ignore"):
        _, exponent = np.frexp(np.abs(nudged).max(axis=1))
    nudged = np.ldexp(nudged, -exponent[:, None])
    m = np.abs(nudged).max(axis=1)
    nudged[:, axis] = np.copysign(m * (1.0 + NUDGE), nudged[:, axis])
    return nudged


def tie_alternatives(cube, dirs: np.ndarray, filter: str = "bilinear") -> np.ndarray:
    """(n, 3, 3) acceptable colours for each direction: the reference colour on
    each face the direction touches (docs/assignment.md: at ties every touching face
    is correct). Rows for faces not touched are NaN. `cube`: a
    library.CubeMap or its (6, H, W, 3) texels."""
    dirs = np.asarray(dirs, np.float64)
    tied = tied_axes(dirs)
    out = np.full((len(dirs), 3, 3), np.nan)
    for axis in range(3):
        rows = np.flatnonzero(tied[:, axis])
        if len(rows):
            out[rows, axis] = oracle.current().fetch(getattr(cube, "faces", cube), _nudged(dirs[rows], axis), filter)
    return out


def tied_face_uv(dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(faces (n, 4), uv (n, 4, 2)): the reference's face and (u, v) for each
    direction first, then each face a tied direction also touches (found as
    in tie_alternatives); -1 (and NaN) where there is none."""
    dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
    faces = np.full((len(dirs), 4), -1, np.int64)
    uv = np.full((len(dirs), 4, 2), np.nan)
    f, fuv = oracle.current().direction_to_face(dirs)
    faces[:, 0], uv[:, 0] = f, np.where((f >= 0)[:, None], fuv, np.nan)
    tied = tied_axes(dirs)
    tied &= (tied.sum(axis=1) >= 2)[:, None]          # only real ties: elsewhere it is the first face again
    for axis in range(3):
        rows = np.flatnonzero(tied[:, axis])
        if len(rows):
            f, fuv = oracle.current().direction_to_face(_nudged(dirs[rows], axis))
            faces[rows, axis + 1], uv[rows, axis + 1] = f, np.where((f >= 0)[:, None], fuv, np.nan)
    return faces, uv


class Mismatches:
    """What a verdict per case (`ok`, with each case's `error`) says as a
    whole: shared by Comparison and the fetchColor judge's Judgement."""
    ok: np.ndarray
    error: np.ndarray

    @property
    def fraction(self) -> float:
        return float(self.ok.mean()) if len(self.ok) else 1.0

    @property
    def failures(self) -> np.ndarray:
        """Indices of mismatches, worst first."""
        bad = np.flatnonzero(~self.ok)
        return bad[np.argsort(-np.nan_to_num(self.error[bad], nan=np.inf), kind="stable")]


@dataclass
class Comparison(Mismatches):
    ok: np.ndarray          # (n,) bool
    error: np.ndarray       # (n,) distance to the nearest acceptable colour
    tolerance: np.ndarray   # (n,)


def compare(actual: np.ndarray, acceptable: np.ndarray, tol: np.ndarray | float) -> Comparison:
    """Match actual (n, 3) against acceptable colours (n, 3) or (n, k, 3)
    (NaN rows ignored). A NaN or infinite actual value never matches."""
    actual = np.asarray(actual, np.float64)
    acceptable = np.asarray(acceptable, np.float64)
    if acceptable.ndim == 2:
        acceptable = acceptable[:, None, :]
    with np.errstate(invalid="ignore"):
        gap = np.abs(actual[:, None, :] - acceptable)
        # (n, k): two maximums are 4-8x faster than a max over an axis of three, and keep NaN as it does
        diff = np.maximum(np.maximum(gap[..., 0], gap[..., 1]), gap[..., 2])
    # NaN from a NaN on either side or from inf - inf; an infinite actual value is inf from any finite colour
    diff[np.isnan(diff)] = np.inf
    error = diff.min(axis=1)
    tol = np.broadcast_to(np.asarray(tol, np.float64), error.shape)
    return Comparison(ok=error <= tol, error=error, tolerance=np.array(tol))


def format_vector(v) -> str:
    return "(" + ", ".join(f"{x:.6g}" for x in np.asarray(v, np.float64)) + ")"


def explain(cmp: Comparison, describe_input, actual: np.ndarray, expected: np.ndarray, limit: int = 5) -> str:
    """Markdown lines for the worst mismatches: input, expected, got."""
    lines = []
    for i in cmp.failures[:limit]:
        lines.append("- " + _("%(call)s: expected %(expected)s, got %(got)s") % {
            "call": describe_input(i), "expected": format_vector(expected[i]), "got": format_vector(actual[i])})
    more = len(cmp.failures) - limit
    if more > 0:
        lines.append("- " + _("... and %(more)d more") % {"more": more})
    return "\n".join(lines)


def describe_direction(d) -> str:
    """A fetchColor call as a student would write it, exact to the last digit that matters."""
    return "fetchColor(Vector3(" + ", ".join(f"{x:.9g}" for x in d) + "))"


def worst_cases(cmp: Comparison, describe_input, actual: np.ndarray, expected: np.ndarray, group: str = "",
                limit: int = 3, face_size: tuple[int, int] | None = None, hits=None) -> list:
    """The worst mismatches as data (grader.grading.results.Mismatch; reports word
    them). With face_size (W, H), the colours came from a texture that
    encodes texel positions (textures.coordinate_faces): each case also says
    where the reference and the submission sampled. `hits(i)` gives those
    places directly instead ((expected, got) TexelHits, e.g. from a record)."""
    from ...grading.results import Mismatch, TexelHit
    from .textures import decode_sample_coordinates

    def hit(rgb, w, h):
        face, px, py = decode_sample_coordinates(np.asarray(rgb, np.float64)[None])
        if face[0] < 0:
            return TexelHit("", (float("nan"), float("nan")), (float("nan"), float("nan")))
        return TexelHit(library.FACE_NAMES[face[0]], (float(px[0]), float(py[0])),
                        (float(px[0]) / w, float(py[0]) / h))

    out = []
    for i in cmp.failures[:limit]:
        expected_at = got_at = None
        if hits is not None:
            expected_at, got_at = hits(i)
        elif face_size is not None and decode_sample_coordinates(np.asarray(expected[i], np.float64)[None])[0][0] >= 0:
            expected_at, got_at = hit(expected[i], *face_size), hit(actual[i], *face_size)
        out.append(Mismatch(describe_input(i), tuple(float(x) for x in expected[i]), tuple(float(x) for x in actual[i]),
                            expected_at=expected_at, got_at=got_at, group=group))
    return out
