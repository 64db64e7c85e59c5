"""fetchColor judged through the submission's own readTexture, live.

A correct fetchColor over *this* readTexture returns the student's own
readTexture at the reference's face and (u, v) (docs/assignment.md's table). So
each judged direction's answer is compared with the student's readTexture
called directly at that face and (u, v): no model of readTexture is needed,
and nothing depends on whether one fits, so being hard to model buys nothing
(issue 18). Only float-level differences are allowed: the colour tolerance
of float rounding (compare.tolerance) and, where readTexture jumps at a texel
boundary, its answer at (u, v) moved by FLOAT_STEP; at ties, every face the
direction touches. No texel slack anywhere.

Where the student's readTexture crashes (or is never answered) at the
reference's (face, u, v), a correct fetchColor would crash too: the
direction is not earned (readTexture's own check names the cause), so a
student never gains by crashing.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...envmap import oracle
from ...worker.runner import Outcome
from .compare import Mismatches, compare, tied_face_uv

# A fetchColor computing (u, v) in float (or in another order) differs from
# the reference's by a few float ulps of 1: 4 * 2^-24.
FLOAT_STEP = 4.0 * 2.0 ** -24
MOVES = tuple((du, dv) for du in (-1, 0, 1) for dv in (-1, 0, 1) if (du, dv) != (0, 0))
# readTexture called on its own can tell the judge's calls from fetchColor's
# (a flag set in fetchColor) and the judge's faces from the read_texture
# check's (their size or texels). On each face, one that differs from the
# handout's on most of the judge's calls there, but on far fewer of the
# read_texture check's calls at like (u, v) on that face, is not believed
# there: fetchColor's directions on that face are judged against the
# handout's readTexture instead. A threshold on the check alone can be paid
# for (black on a few check calls, issue 18's red team); this one costs
# readTexture's points in proportion to what it buys. Honest mistakes
# differ about as often in both (nearest neighbour, swapped weights), or
# rarely in the judge's calls (an edge rule).
DIFFERS_HERE = 0.5        # the judge's calls on a face differ on more than this share
CHECK_SHARE = 0.5         # ... and the check's on that face on less than this share of the judge's share
# readTexture is given an address, not a face: honest code answers alike on
# every face (random texels, or coordinates that differ only in blue), so in
# the check each face differs about as often (~180 interior calls a face:
# +-0.04 by chance). One that differs more on some faces tells them by their
# texels (issue 18's red team: u and v swapped on +Y and -Y only) and is not
# believed there at all.
FACE_SPREAD = 0.2         # a face's check share above the least face's by more than this


@dataclass
class Judgement(Mismatches):
    """fetchColor's answers against the student's own readTexture."""
    ok: np.ndarray            # (n,) the answer is what a correct fetchColor gives over this readTexture
    expected: np.ndarray      # (n, 3) the student's readTexture at the reference's face and (u, v) (NaN: crashed)
    unreadable: np.ndarray    # (n,) the student's readTexture crashed (or gave NaN) on every face the direction touches
    error: np.ndarray         # (n,) distance to the nearest acceptable colour
    context_dependent: bool = False   # judged against the handout's readTexture: the live one was not believed


def _regions(uv: np.ndarray, width: int, height: int) -> np.ndarray:
    """0..8: which of the nine parts of the face (interior, four borders a
    texel wide, four corners) each (u, v) lies in. Each part is its own
    readTexture batch: crashes along one border (a missing clamp) cannot stop
    the rest of the face from being read (the runner gives a batch up after
    a few failures)."""
    part = []
    for c, n in ((uv[:, 0], width), (uv[:, 1], height)):
        with np.errstate(invalid="ignore"):
            part.append(np.where(c < 1.0 / n, 0, np.where(c > 1.0 - 1.0 / n, 2, 1)))
    return 3 * part[0] + part[1]


# The order read_at asks the parts of a face in (_regions' numbers): the
# interior, then the borders, then the corners.
PART_ORDER = (4, 1, 3, 5, 7, 0, 2, 6, 8)


def read_at(lookups, faces: np.ndarray, uv: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """(n, 3) the student's readTexture on face faces[i] at uv[i] (NaN where it
    failed or no face): one batch per face and part of the face, interior first."""
    out = np.full((len(uv), 3), np.nan)
    rows = np.flatnonzero((faces >= 0) & np.isfinite(uv).all(axis=1))
    if not len(rows):
        return out
    # Each batch in row order: one stable sort by (face, place of the part in PART_ORDER).
    part_rank = np.argsort(PART_ORDER)
    key = faces[rows].astype(np.int64) * 9 + part_rank[_regions(uv[rows], *size)]
    order = np.argsort(key, kind="stable")
    starts = np.flatnonzero(np.diff(key[order], prepend=-1))
    for sel in np.split(rows[order], starts[1:]):
        got = lookups.read_texture(int(faces[sel[0]]), uv[sel])
        values = np.asarray(got.values, np.float64)
        values[~np.asarray(got.evaluated, bool)] = np.nan
        out[sel] = values
    return out


def _handout(texels: np.ndarray, faces: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """The handout's readTexture (the reference's bilinear) at faces[i], uv[i]; NaN where no face."""
    out = np.full((len(uv), 3), np.nan)
    rows = faces >= 0
    if rows.any():
        out[rows] = oracle.current().read_texture(texels, faces[rows], uv[rows], "bilinear")
    return out


class HandoutReads:
    """The handout's readTexture over `texels` (6, H, W, 3), read as the judge
    reads the student's: for judging where the live one is not to be asked."""

    def __init__(self, texels: np.ndarray):
        self.texels = texels

    def read_texture(self, face: int, uv: np.ndarray, placement: str = "end") -> Outcome:
        uv = np.asarray(uv, np.float64).reshape(-1, 2)
        values = oracle.current().read_texture(self.texels, np.full(len(uv), face), uv, "bilinear")
        return Outcome(values=np.asarray(values, np.float64), evaluated=np.ones(len(uv), bool))


def judge(lookups, dirs: np.ndarray, values: np.ndarray, tol, size: tuple[int, int],
          texels: np.ndarray | None = None, texture_mismatch=None, differs_here: float = DIFFERS_HERE) -> Judgement:
    """fetchColor's answers `values` (n, 3) for `dirs` (n, 3) against the
    student's readTexture, on the faces currently set (of `size` (W, H)).
    With `texels` (those faces) and `texture_mismatch` ((6,): per face, the
    share of the read_texture check's calls that differed from the handout,
    ReadTextureFinding.face_mismatch), a live readTexture that differs far
    more often here is not believed on that face (`differs_here`, CHECK_SHARE)."""
    dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
    values = np.asarray(values, np.float64).reshape(-1, 3)
    faces, uv = tied_face_uv(dirs)                     # (n, k) faces, (n, k, 2): the reference's first
    n, k = faces.shape
    flat_faces, flat_uv = faces.reshape(-1), uv.reshape(-1, 2)
    exact = read_at(lookups, flat_faces, flat_uv, size).reshape(n, k, 3)
    disbelieved = np.zeros(n, bool)
    if texels is not None and texture_mismatch is not None:
        handout = _handout(texels, flat_faces, flat_uv).reshape(n, k, 3)
        seen = np.isfinite(exact[:, 0]).all(axis=1)
        with np.errstate(invalid="ignore"):
            differs = ~(np.abs(exact[:, 0] - handout[:, 0]) <= tol).all(axis=1)
        checked = np.broadcast_to(np.asarray(texture_mismatch, np.float64), (6,))
        # Like with like: the check's share is over (u, v) inside the border
        # texels (read_texture.generic), so the judge's is too.
        p = uv[:, 0] * np.asarray(size, np.float64)
        inside = ((p >= 1) & (p < np.asarray(size, np.float64) - 1)).all(axis=1)
        for face in range(6):
            here = seen & inside & (faces[:, 0] == face)
            share = float(differs[here].mean()) if here.any() else 0.0
            if (share > differs_here and checked[face] < CHECK_SHARE * share) or \
                    checked[face] > checked.min() + FACE_SPREAD:
                disbelieved |= faces[:, 0] == face
    cmp = compare(values, exact, tol)
    ok, error = cmp.ok.copy(), cmp.error.copy()
    # Where the answer differs: readTexture may jump at a texel boundary the
    # float-level difference crosses. Read it there too, for those rows only.
    retry = np.flatnonzero(~ok & np.isfinite(values).all(axis=1))
    if len(retry):
        moved_faces = np.repeat(faces[retry][:, None, :], len(MOVES), axis=1)        # (r, m, k)
        steps = FLOAT_STEP * np.array(MOVES, np.float64)                             # (m, 2)
        moved_uv = np.clip(uv[retry][:, None, :, :] + steps[None, :, None, :], 0.0, 1.0)
        moved = read_at(lookups, moved_faces.reshape(-1), moved_uv.reshape(-1, 2), size)
        moved = moved.reshape(len(retry), len(MOVES) * k, 3)
        again = compare(values[retry], moved, tol)
        ok[retry] = again.ok
        error[retry] = np.minimum(error[retry], again.error)
    unreadable = ~np.isfinite(exact).all(axis=2).any(axis=1)
    expected = exact[:, 0].copy()
    if disbelieved.any():
        rows = np.flatnonzero(disbelieved)
        against = compare(values[rows], handout[rows], tol)
        ok[rows], error[rows], expected[rows], unreadable[rows] = against.ok, against.error, handout[rows, 0], False
    return Judgement(ok=ok, expected=expected, unreadable=unreadable, error=error,
                     context_dependent=bool(disbelieved.any()))


def reference_faces(dirs: np.ndarray) -> np.ndarray:
    """The face the reference picks for each direction (-1: none)."""
    return oracle.current().direction_to_face(np.asarray(dirs, np.float64).reshape(-1, 3))[0]
