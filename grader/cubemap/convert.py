"""Converters between lat-long, angular and cube maps, filtered so they do not alias.

Into a cube map: every texel is the solid-angle-weighted mean of bilinear
lookups in the source image on a k x k grid inside the texel
(directions.average_over_texels), k chosen so that neighbouring sub-samples
are at most about 2/3 of a source pixel apart: a box filter over the
texel's footprint, however many source pixels it covers.

Out of a cube map (for viewing): every lat-long pixel is the mean of the
reference's bilinear lookups (grader.envmap.library.CubeMap.fetch, the one
implementation of the lookup) on a k x k grid inside the pixel, weighted by
cos(latitude), the solid angle each sub-sample stands for.
"""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..envmap import library
from ..envmap.imaging import read_image
from .directions import average_over_texels
from .projections import (direction_to_angular, direction_to_latlong, latlong_to_direction)


def read_environment(path: str | os.PathLike) -> np.ndarray:
    """An .hdr or .exr image as (H, W, 3) float32; negatives (lossy EXR, PROVENANCE.md) become 0."""
    return np.maximum(read_image(path), 0.0)


def bilinear(image: np.ndarray, s: np.ndarray, t: np.ndarray, wrap_s: bool = False) -> np.ndarray:
    """image (H, W, C) at coordinates s, t in [0, 1] (pixel centres at (i + 0.5) / W).

    Edges clamp, except s wraps round when wrap_s (the longitude of a lat-long map).
    """
    height, width = image.shape[:2]
    x = np.asarray(s) * width - 0.5
    y = np.asarray(t) * height - 0.5
    x0 = np.floor(x).astype(np.int64)
    y0 = np.floor(y).astype(np.int64)
    fx = (x - x0)[..., None]
    fy = (y - y0)[..., None]

    def column(i):
        return np.mod(i, width) if wrap_s else np.clip(i, 0, width - 1)

    def row(j):
        return np.clip(j, 0, height - 1)

    c00 = image[row(y0), column(x0)]
    c10 = image[row(y0), column(x0 + 1)]
    c01 = image[row(y0 + 1), column(x0)]
    c11 = image[row(y0 + 1), column(x0 + 1)]
    return (1 - fy) * ((1 - fx) * c00 + fx * c10) + fy * ((1 - fx) * c01 + fx * c11)


# Sub-samples per source pixel, along each side: 1.5 matched rnl_cross.hdr
# as well as 2 did (docs/cubemap.md) in 3/4 of the time.
SAMPLES_PER_SOURCE_PIXEL = 1.5


def _samples_per_side(source_pixels_per_texel: float) -> int:
    """Sub-samples per texel (or pixel) side, at least 2."""
    return max(2, math.ceil(SAMPLES_PER_SOURCE_PIXEL * source_pixels_per_texel))


def latlong_to_faces(latlong: np.ndarray, face_size: int) -> np.ndarray:
    """Faces (6, N, N, 3) float32 from a lat-long image (H, 2H, 3) (projections.py's convention)."""
    width = latlong.shape[1]
    # A texel spans about 2 / N radians; a lat-long pixel 2 pi / width radians
    # at the equator (less in longitude towards the poles).
    samples = _samples_per_side((2.0 / face_size) / (2.0 * np.pi / width))

    def radiance(d):
        s, t = direction_to_latlong(d)
        return bilinear(latlong, s, t, wrap_s=True)

    return average_over_texels(radiance, face_size, face_size, samples)


# How much the angular map stretches round the circle of directions at angle
# a from -z (a / sin a pixels per radian of arc, relative to the centre),
# per face: the worst case over -Z (54.7 deg) and the side faces (125.3 deg);
# for +Z, taken at 150 deg, since towards +z the whole rim of the map closes
# on one point and no finite grid resolves it.
_ANGULAR_STRETCH = (2.7, 2.7, 2.7, 2.7, 5.2, 1.2)
_MAX_SAMPLES = 16


def angular_to_faces(angular: np.ndarray, face_size: int) -> np.ndarray:
    """Faces (6, N, N, 3) float32 from a Debevec angular map (square, disc inscribed)."""
    pixels_per_radian = angular.shape[0] / 2.0 / np.pi
    base = (2.0 / face_size) * pixels_per_radian
    samples = [min(_MAX_SAMPLES, _samples_per_side(base * stretch)) for stretch in _ANGULAR_STRETCH]

    def radiance(d):
        s, t = direction_to_angular(d)
        return bilinear(angular, s, t)

    return average_over_texels(radiance, face_size, face_size, samples)


def faces_to_latlong(faces: np.ndarray, width: int, filter: str = "seamless") -> np.ndarray:
    """A lat-long image (width/2, width, 3) float32 of a cube map, looked up with the reference."""
    height = width // 2
    cube = library.CubeMap(faces)
    face_size = faces.shape[2]
    samples = _samples_per_side((2.0 * np.pi / width) / (2.0 / face_size))
    offsets = (np.arange(samples) + 0.5) / samples
    total = np.zeros((height, width, 3))
    weight_sum = np.zeros((height, 1))
    for dj in offsets:
        t = (np.arange(height)[:, None] + dj) / height
        weight = np.cos(np.pi * (0.5 - t))      # solid angle per unit (s, t) ~ cos(latitude)
        for di in offsets:
            s = (np.arange(width)[None, :] + di) / width
            d = latlong_to_direction(*np.broadcast_arrays(s, t))
            rgb = cube.fetch(d.reshape(-1, 3), filter).reshape(height, width, 3)
            total += rgb * weight[..., None]
            weight_sum += weight
    return (total / weight_sum[..., None]).astype(np.float32)


def write_cross(path: str | os.PathLike, faces: np.ndarray) -> None:
    """Write faces (6, N, N, 3) as a vertical-cross .hdr (the reference's layout and writer)."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    library.write_hdr(path, library.faces_to_cross(faces))


def read_cross(path: str | os.PathLike) -> np.ndarray:
    """Faces (6, N, N, 3) of a vertical-cross .hdr or .exr."""
    return library.cross_to_faces(read_environment(path))
