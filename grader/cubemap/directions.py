"""Directions through cube-map texels, and texel averages weighted by solid angle.

The face parameterisation is ASSIGNMENT.md's (u, v) table ("Conventions"),
inverted: with a = 2u - 1 and b = 2v - 1 the point (u, v) of a face is the
direction below (not normalised; the major component is +-1).

    +X: ( 1,  b,  a)    -X: (-1,  b, -a)
    +Y: ( a,  1,  b)    -Y: ( a, -1, -b)
    +Z: ( a, -b,  1)    -Z: ( a,  b, -1)

Texel (x, y) of a W x H face has its centre at u = (x + 0.5) / W,
v = (y + 0.5) / H, y = 0 the bottom row; cube maps are (6, H, W, 3) float32
indexed [face, y, x, channel], faces +X -X +Y -Y +Z -Z (ARCHITECTURE.md).
"""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

FACE_NAMES = ("+X", "-X", "+Y", "-Y", "+Z", "-Z")

# Per face: (axis index, sign) of the direction's x, y, z components as
# functions of (a, b, 1): component c = sign * [a, b, 1][axis].
_FACE_COMPONENTS = (
    ((2, +1), (1, +1), (0, +1)),   # +X: ( 1,  b,  a)
    ((2, -1), (1, +1), (0, -1)),   # -X: (-1,  b, -a)
    ((0, +1), (2, +1), (1, +1)),   # +Y: ( a,  1,  b)
    ((0, +1), (2, -1), (1, -1)),   # -Y: ( a, -1, -b)
    ((0, +1), (1, -1), (2, +1)),   # +Z: ( a, -b,  1)
    ((0, +1), (1, +1), (2, -1)),   # -Z: ( a,  b, -1)
)


def face_uv_to_direction(face: int, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Unit directions (..., 3) float64 of points (u, v) on one face."""
    a = 2.0 * np.asarray(u, np.float64) - 1.0
    b = 2.0 * np.asarray(v, np.float64) - 1.0
    abc = (a, b, np.ones_like(a))
    d = np.stack([sign * abc[axis] for axis, sign in _FACE_COMPONENTS[face]], axis=-1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def texel_centre_uv(width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """(u, v) of every texel centre, each (H, W), row 0 the bottom row."""
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    return np.meshgrid(u, v)


def texel_directions(width: int, height: int | None = None) -> np.ndarray:
    """Unit direction through every texel centre: (6, H, W, 3) float32."""
    height = width if height is None else height
    u, v = texel_centre_uv(width, height)
    return np.stack([face_uv_to_direction(f, u, v) for f in range(6)]).astype(np.float32)


def solid_angle_density(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """d(omega) / (du dv) on a face: 4 / (1 + a^2 + b^2)^(3/2), a = 2u-1, b = 2v-1.

    The face is the square [-1, 1]^2 at distance 1 from the centre, and
    (a, b) = (2u - 1, 2v - 1) scales areas by 4.
    """
    a = 2.0 * u - 1.0
    b = 2.0 * v - 1.0
    return 4.0 / (1.0 + a * a + b * b) ** 1.5


def texel_solid_angles(width: int, height: int | None = None) -> np.ndarray:
    """Exact solid angle of every texel of one face, (H, W) float64 (the same on all faces).

    The solid angle of the face rectangle from (0, 0) to (a, b) is
    atan(a b / sqrt(1 + a^2 + b^2)); texels are differences of corners.
    """
    height = width if height is None else height
    a = np.linspace(-1.0, 1.0, width + 1)[None, :]
    b = np.linspace(-1.0, 1.0, height + 1)[:, None]
    corner = np.arctan2(a * b, np.sqrt(1.0 + a * a + b * b))
    return corner[1:, 1:] - corner[1:, :-1] - corner[:-1, 1:] + corner[:-1, :-1]


DirectionFunction = Callable[[np.ndarray], np.ndarray]


def average_over_texels(radiance: DirectionFunction, width: int, height: int | None = None,
                        samples: int | Sequence[int] = 4) -> np.ndarray:
    """Faces (6, H, W, C) float32 whose texels are solid-angle-weighted means of radiance.

    radiance maps unit directions (..., 3) to values (..., C). Each texel is
    integrated on a samples x samples grid of sub-texel points (cell centres),
    each weighted by the solid angle it stands for, so that features smaller
    than a texel are averaged rather than point-sampled (no aliasing).
    samples may be one count per face.
    """
    height = width if height is None else height
    per_face = [samples] * 6 if np.isscalar(samples) else list(samples)
    faces = []
    for face, samples in enumerate(per_face):
        total = None
        weight_sum = np.zeros((height, width))
        for j in range(samples):
            for i in range(samples):
                u = (np.arange(width)[None, :] + (i + 0.5) / samples) / width
                v = (np.arange(height)[:, None] + (j + 0.5) / samples) / height
                u, v = np.broadcast_arrays(u, v)
                weight = solid_angle_density(u, v)
                value = np.asarray(radiance(face_uv_to_direction(face, u, v)), np.float64)
                term = value * weight[..., None]
                total = term if total is None else total + term
                weight_sum += weight
        faces.append(total / weight_sum[..., None])
    return np.stack(faces).astype(np.float32)
