"""Texel averages weighted by solid angle, for the map generators.

Directions, (u, v) and solid angles are grader/envmap/geometry.py's (the face table
of docs/assignment.md, read off the reference library): with a = 2u - 1 and
b = 2v - 1 the point (u, v) of a face is the direction below (major
component +-1), as tests/unit/cubemap/test_cubemap.py checks against the handout.

    +X: ( 1,  b,  a)    -X: (-1,  b, -a)
    +Y: ( a,  1,  b)    -Y: ( a, -1, -b)
    +Z: ( a, -b,  1)    -Z: ( a,  b, -1)
"""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

# The geometry lives in grader/envmap/geometry.py (on the reference library); these
# names are re-exported for the map generators and figures.
from ..envmap.geometry import (FACE_NAMES, face_uv_to_direction, solid_angle_density, texel_centre_uv,
                               texel_directions, texel_solid_angles)  # noqa: F401


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
