"""Where fetchColor read, told without any model of readTexture.

The faces encode their own position smoothly (textures.coordinate_faces:
R = x + 1, G = y + 1, B = face + 1). The student's readTexture is called
directly on a fine grid of known (u, v) (the calibration); any readTexture
that blends nearby texels, however it rounds, blends or extrapolates, maps
(u, v) to an (R, G) that can be looked up the other way: an answer of
fetchColor is read back as the (u, v) whose calibrated colour it is (the
centroid of all grid points giving that colour, so a readTexture that
returns whole texels reads back as the texel's centre). B tells the face.

Per face, an affine map from the reference's (u, v) to the (u, v) read back
is fitted (`fit_affine`) and named (`AffineMap`): orientation (swap, flips),
scale and offset, so an inset, an offset or a remapping is told apart from a
flip, and each is told under the others.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .textures import decode_sample_coordinates
from .own_read import read_at

GRID = 4                  # calibration points per texel along each axis
CALIBRATION_FACE = 2      # any face: readTexture is the same code on each
SCALE_TOLERANCE = 0.02    # |scale - 1| below this is no scale mistake
EXPLAINED = 0.9           # share of a face's directions the fitted map must explain
RADIUS = 0.5              # farther than this (texels of colour) from every calibrated colour: not one readTexture gives
TIE = 1e-6                # grid points this much farther than the closest are as close (float noise)
CELL = RADIUS + 2 * TIE   # the search grid's cell: every point within RADIUS + TIE is in the 3 x 3 cells around


@dataclass
class Calibration:
    uv: np.ndarray            # (k, 2) grid points answered
    colour: np.ndarray        # (k, 2) R, G readTexture returned there
    size: tuple[int, int]

    def __post_init__(self):
        # A fixed-radius search (numpy only, so the student kit needs no
        # scipy): the calibrated colours sorted by the grid cell they fall in,
        # with a margin of empty cells so that no neighbour wraps to another row.
        self.colour = np.asarray(self.colour, np.float64)
        self._origin = self.colour.min(axis=0) - 2 * CELL
        cells = self._cells(self.colour)
        self._rows = int(cells[:, 1].max()) + 4
        keys = cells[:, 0] * self._rows + cells[:, 1]
        self._order = np.argsort(keys, kind="stable")
        self._keys = keys[self._order]

    def _cells(self, points: np.ndarray) -> np.ndarray:
        return np.floor((points - self._origin) / CELL).astype(np.int64)

    def _candidates(self, points: np.ndarray):
        """(query row, calibration index) of every calibrated colour in the
        3 x 3 cells around each point that can be within RADIUS of one."""
        low, high = self.colour.min(axis=0) - CELL, self.colour.max(axis=0) + CELL
        queries = np.flatnonzero(np.isfinite(points).all(axis=1) & (points >= low).all(axis=1)
                                 & (points <= high).all(axis=1))
        cells = self._cells(points[queries])
        around = np.array([(dx, dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1)])
        keys = ((cells[:, None, 0] + around[:, 0]) * self._rows + cells[:, None, 1] + around[:, 1]).ravel()
        start = np.searchsorted(self._keys, keys, "left")
        count = np.searchsorted(self._keys, keys, "right") - start
        first = np.cumsum(count) - count
        position = np.arange(int(count.sum())) - np.repeat(first - start, count)
        return np.repeat(np.repeat(queries, len(around)), count), self._order[position]

    def read_back(self, answers: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(face (n,), uv (n, 2)) each answer was read at; -1 / NaN where it
        is no colour readTexture gives (black, a crash, a mix of faces)."""
        answers = np.asarray(answers, np.float64).reshape(-1, 3)
        face, _, _ = decode_sample_coordinates(answers)
        uv = np.full((len(answers), 2), np.nan)
        rows = np.flatnonzero(face >= 0)
        if not len(rows):
            return face, uv
        query, index = self._candidates(answers[rows, :2])
        delta = answers[rows[query], :2] - self.colour[index]
        dist = np.sqrt(delta[:, 0] * delta[:, 0] + delta[:, 1] * delta[:, 1])
        closest = np.full(len(rows), np.inf)
        np.minimum.at(closest, query, dist)
        # Every grid point as close as the closest (within float noise): the
        # whole flat region of a readTexture that returns one texel.
        near = (dist <= closest[query] + TIE) & (closest[query] <= RADIUS)
        n = np.bincount(query[near], minlength=len(rows))
        found = n > 0
        for axis in range(2):
            total = np.bincount(query[near], weights=self.uv[index[near], axis], minlength=len(rows))
            uv[rows[found], axis] = total[found] / n[found]
        return face, uv


def calibrate(lookups, faces: np.ndarray) -> Calibration | None:
    """The student's readTexture on a grid over one face of `faces` (already
    set in the worker); None when nothing can be read back: it crashes on
    most of the face or returns one colour wherever it reads."""
    h, w = faces.shape[1:3]
    gu, gv = np.linspace(0.0, 1.0, GRID * w + 1), np.linspace(0.0, 1.0, GRID * h + 1)
    uu, vv = np.meshgrid(gu, gv, indexing="ij")
    uv = np.stack([uu.ravel(), vv.ravel()], axis=1)
    values = read_at(lookups, np.full(len(uv), CALIBRATION_FACE), uv, (w, h))
    ok = np.isfinite(values).all(axis=1)
    if ok.sum() < 0.5 * len(uv):
        return None
    colour = values[ok, :2]
    if np.ptp(colour, axis=0).max() < 0.5:      # less than half a texel of change anywhere
        return None
    return Calibration(uv[ok], colour, (w, h))


@dataclass(frozen=True)
class AffineMap:
    """read = F(scale * source + offset) per coordinate, F the flip (1 - x)
    where flipped; source (u, v) of the reference, swapped when `swap`."""
    swap: bool
    flip_u: bool
    flip_v: bool
    scale: tuple[float, float]
    offset: tuple[float, float]
    explained: float          # share of the face's directions within a texel of the map
    size: tuple[int, int]

    @property
    def orientation_ids(self) -> list[str]:
        return [i for i, on in (("uv-swapped", self.swap), ("u-flipped", self.flip_u), ("v-flipped", self.flip_v)) if on]

    def _texels(self, which: int) -> float:
        return self.offset[which] * self.size[which]

    @property
    def kind(self) -> str | None:
        """What is wrong beyond orientation: None, "uv-inset", "uv-offset",
        "uv-range" (not mapped to [0, 1] as the handout says) or "uv-mismatch"."""
        s, o = np.array(self.scale), np.array(self.offset)
        quarter = 0.25 / np.array(self.size, np.float64)
        if (np.abs(s - 1) < SCALE_TOLERANCE).all() and (np.abs(o) < quarter).all():
            return None
        for rs, ro in ((2.0, -1.0), (2.0, 0.0), (1.0, -0.5)):        # face_recovery.REMAPS' mistakes
            if (np.abs(s - rs) < SCALE_TOLERANCE * rs).all() and (np.abs(o - ro) < quarter).all():
                return "uv-range"
        centre_kept = (np.abs(s * 0.5 + o - 0.5) < quarter).all()
        if (s < 1 - SCALE_TOLERANCE).all() and centre_kept:
            return "uv-inset"
        if (np.abs(s - 1) < SCALE_TOLERANCE).all():
            return "uv-offset"
        return "uv-mismatch"

    def words(self) -> str:
        """The map in numbers a student can compare with their formula."""
        names = ("v", "u") if self.swap else ("u", "v")
        parts = []
        for which, (target, source) in enumerate(zip(("u", "v"), names)):
            s, o = self.scale[which], self.offset[which]
            expr = f"{s:.3g} {source} {'+' if o >= 0 else '-'} {abs(o):.3g}"
            flipped = self.flip_u if which == 0 else self.flip_v
            parts.append(f"{target} = {'1 - (' + expr + ')' if flipped else expr}")
        return ", ".join(parts)

    def inset_texels(self) -> tuple[float, float]:
        return self._texels(0), self._texels(1)


def fit_affine(ref_uv: np.ndarray, read_uv: np.ndarray, size: tuple[int, int]) -> AffineMap | None:
    """The affine map from the reference's (u, v) to the (u, v) read back,
    fitted where neither is within two texels of the border (a clamped
    readTexture reads flat there); None with too few points."""
    w, h = size
    margin = np.array([2.0 / w, 2.0 / h])
    ok = (np.isfinite(read_uv).all(axis=1) & (ref_uv > margin).all(axis=1) & (ref_uv < 1 - margin).all(axis=1)
          & (read_uv > margin / 2).all(axis=1) & (read_uv < 1 - margin / 2).all(axis=1))
    if ok.sum() < 20:
        return None
    x = np.column_stack([ref_uv[ok], np.ones(int(ok.sum()))])
    coef, *_ = np.linalg.lstsq(x, read_uv[ok], rcond=None)          # (3, 2): read = x @ coef
    a, b, c, d = coef[0, 0], coef[1, 0], coef[0, 1], coef[1, 1]      # du/du, du/dv, dv/du, dv/dv
    swap = abs(b) + abs(c) > abs(a) + abs(d)
    slope_u, slope_v = (b, c) if swap else (a, d)
    flip_u, flip_v = slope_u < 0, slope_v < 0
    icpt = coef[2]
    offset = (1 - icpt[0] if flip_u else icpt[0], 1 - icpt[1] if flip_v else icpt[1])
    residual = np.abs(x @ coef - read_uv[ok]) * (w, h)
    explained = float(np.mean((residual <= 0.75).all(axis=1)))
    return AffineMap(bool(swap), bool(flip_u), bool(flip_v), (float(abs(slope_u)), float(abs(slope_v))),
                     (float(offset[0]), float(offset[1])), explained, size)
