"""What readTexture reads: its footprint, measured with impulse textures.

Honest readTexture code is linear in the texels: its answer at (u, v) is a
fixed blend sum_t w_t(u, v) T_t of the face's texels. An impulse texture
sets one texel to 1 and every other to 0, so the answer is that texel's
weight. The three channels carry three impulses at once (R on texel k, G on
k + 1, B on k + 2), so a face of n texels takes ceil(n / 3) textures, and one
batch per texture reads the weights at every probed (u, v): the footprint,
(n_probes, H, W), exact to float rounding, with no model of what readTexture
might be. The handout's footprint is measured the same way from the reference
(grader.oracle), so the two are compared like with like.

Weights measured this way only describe the code if it is linear. A random
texture tells: the answer must be the measured weights applied to its texels
(`predict`). Where it is not (code that looks at the values it reads, keeps
state between calls, mixes channels, or reads outside the face, which the
worker's guard pages make fault), the footprint is not believed there.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

# The face the impulses sit on: the worker hands readTexture that face alone,
# between guard pages (grader/worker/worker.c), so which one it is does not
# change what is read; the random textures check every face.
FACE = 0
# A weight below this is no tap: float rounding of a weight of 0 stays
# below 1e-6, and the smallest weight the probes give honest code is 1/64.
TAP = 1e-4
# Two footprints are equal when every weight is within this of the other's:
# a float-computed p moves a weight by at most W * 2**-24 (< 1e-5 here).
WEIGHT_TOL = 1e-4


@dataclass(frozen=True)
class Footprint:
    """readTexture's weights on a (W, H) face at each probed (u, v)."""
    size: tuple[int, int]        # (W, H)
    uv: np.ndarray               # (n, 2)
    weights: np.ndarray          # (n, H, W); NaN rows where a read failed

    @property
    def answered(self) -> np.ndarray:
        """(n,) every impulse read at this (u, v) gave a finite answer."""
        return np.isfinite(self.weights).all(axis=(1, 2))

    def taps(self, i: int) -> list[tuple[int, int, float]]:
        """(x, y, weight) of the texels probe i reads, largest weight first."""
        ys, xs = np.nonzero(np.abs(self.weights[i]) > TAP)
        return sorted(((int(x), int(y), float(self.weights[i, y, x])) for x, y in zip(xs, ys)),
                      key=lambda t: (-abs(t[2]), t[1], t[0]))

    def axis(self, which: int) -> np.ndarray:
        """(n, W) the weight per column (which = 0) or (n, H) per row (1):
        the footprint summed over the other axis."""
        return self.weights.sum(axis=1 if which == 0 else 2)

    @property
    def separable(self) -> np.ndarray:
        """(n,) the weights sum to 1 and are a column blend times a row blend,
        as in equations (1)-(3): nothing read outside the face, no texel of
        another row read as the memory lies."""
        weights = np.nan_to_num(self.weights)
        whole = np.abs(weights.sum(axis=(1, 2)) - 1) <= WEIGHT_TOL
        outer = self.axis(1)[:, :, None] * self.axis(0)[:, None, :]
        with np.errstate(invalid="ignore"):
            return self.answered & whole & (np.abs(weights - outer) <= WEIGHT_TOL).all(axis=(1, 2))

    def equals(self, other: "Footprint") -> np.ndarray:
        """(n,) both answered and every weight within WEIGHT_TOL."""
        with np.errstate(invalid="ignore"):
            close = (np.abs(self.weights - other.weights) <= WEIGHT_TOL).all(axis=(1, 2))
        return close & self.answered & other.answered


def impulse_textures(width: int, height: int):
    """Yield (first, faces): (6, H, W, 3) float32 zeros but texels first,
    first + 1, first + 2 of FACE (row-major, y = 0 the bottom row) set to 1
    in R, G and B."""
    n = width * height
    for first in range(0, n, 3):
        faces = np.zeros((6, height, width, 3), np.float32)
        flat = faces[FACE].reshape(-1, 3)
        for c in range(min(3, n - first)):
            flat[first + c, c] = 1.0
        yield first, faces


def measure(read: Callable[[np.ndarray], np.ndarray], size: tuple[int, int], uv: np.ndarray) -> Footprint:
    """The footprint of `read(faces) -> (n, 3)`, readTexture on FACE of
    `faces` at every point of `uv` (NaN rows where it failed)."""
    width, height = size
    uv = np.asarray(uv, np.float64).reshape(-1, 2)
    n = width * height
    flat = np.zeros((len(uv), n))
    for first, faces in impulse_textures(width, height):
        values = np.asarray(read(faces), np.float64)
        k = min(3, n - first)
        flat[:, first:first + k] = values[:, :k]
        # A failed read leaves the whole footprint of that (u, v) unknown.
        flat[~np.isfinite(values).all(axis=1)] = np.nan
    return Footprint((width, height), uv, flat.reshape(len(uv), height, width))


def predict(footprint: Footprint, texels: np.ndarray) -> np.ndarray:
    """(n, 3) the answers a linear readTexture with this footprint gives on
    one face's texels (H, W, 3)."""
    w = footprint.weights.reshape(len(footprint.uv), -1)
    return w @ np.asarray(texels, np.float64).reshape(-1, 3)


# The plastic number: i / g and i / g^2 (mod 1), i = 1, 2, ..., spread points
# over a square as evenly as any fixed sequence does (Roberts' R2 sequence),
# and over a line each.
PLASTIC = 1.324717957244746


def inside_texels(cells: np.ndarray, size: int, axis: int = 0) -> np.ndarray:
    """A point in each texel `cells` along an axis of `size` texels, 5% or
    more from its edges, at the `axis`-th coordinate of the R2 sequence (u
    and v of one point take axes 0 and 1). Fixed, not drawn: a mistake made
    in part of each texel costs the same share in every grading, the kit's
    included (issue 30: one random point per texel gave nan_inf_denormal.cpp
    24.52 in the kit and 24.63 in the grader). Answers still cannot be learnt
    by heart: the faces they are read from are drawn per grading."""
    cells = np.asarray(cells)
    offsets = (np.arange(1, len(cells) + 1) / PLASTIC ** (axis + 1)) % 1.0
    return (cells + 0.05 + 0.9 * offsets) / size


def probe_coordinates(n: int) -> np.ndarray:
    """Face parameters along an axis of n texels, where lookups differ: 0 and
    1, just below 1, every texel edge k/n, centre (k + 0.5)/n and quarter
    (k + 0.25)/n (a weight of 0.25 tells swapped weights from right ones),
    and one more point inside every texel (inside_texels)."""
    k = np.arange(n)
    return np.unique(np.concatenate([[0.0, 1.0, 1.0 - 2.0 ** -20], np.arange(1, n) / n, (k + 0.5) / n,
                                     (k + 0.25) / n, inside_texels(k, n)]))


def probe_points(width: int, height: int) -> np.ndarray:
    """(n, 2) every combination of the u and v probe coordinates."""
    u, v = np.meshgrid(probe_coordinates(width), probe_coordinates(height), indexing="ij")
    return np.stack([u.ravel(), v.ravel()], axis=1)
