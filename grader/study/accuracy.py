"""Direction sets and error statistics against the ground truth.

Errors are absolute, in the environment's radiance units (its mean is about
0.55, the sun 20): per direction the RMS over R, G, B of lookup - truth; over
a set, the RMS, the 99th percentile and the maximum of those.

"smooth" subsets keep only directions farther than SMOOTH_MARGIN_TEXELS texel
widths (2/N radians, the largest a texel spans) from the horizon and the sun
rim: there every method's footprint sees smooth radiance, so the error is the
method's own; near a hard edge every method is wrong by a share of the
contrast, whatever it does.
"""
from __future__ import annotations

import numpy as np

from ..envmap.geometry import face_uv_to_direction, normalize
from .ground_truth import AnalyticEnvironment

SMOOTH_MARGIN_TEXELS = 3


def uniform_directions(n: int, seed: int = 1) -> np.ndarray:
    """n unit directions uniform on the sphere."""
    return normalize(np.random.default_rng(seed).normal(size=(n, 3)))


def edge_directions(n: int, size: int, seed: int = 2) -> np.ndarray:
    """n directions within one texel of a cube edge: a random face, one of its
    four edges, a random point along it, at most 1/size from it in u or v
    (both sides of every edge are covered, from the two faces)."""
    rng = np.random.default_rng(seed)
    face = rng.integers(0, 6, n)
    along = rng.random(n)
    near = rng.random(n) / size
    edge = rng.integers(0, 4, n)     # u = 0, u = 1, v = 0, v = 1
    u = np.where(edge == 0, near, np.where(edge == 1, 1 - near, along))
    v = np.where(edge == 2, near, np.where(edge == 3, 1 - near, along))
    return normalize(face_uv_to_direction(face, u, v))


def corner_directions(n: int, size: int, seed: int = 3) -> np.ndarray:
    """n directions within one texel (in both u and v) of a cube corner."""
    rng = np.random.default_rng(seed)
    face = rng.integers(0, 6, n)
    du, dv = rng.random(n) / size, rng.random(n) / size
    right, top = rng.integers(0, 2, n).astype(bool), rng.integers(0, 2, n).astype(bool)
    u = np.where(right, 1 - du, du)
    v = np.where(top, 1 - dv, dv)
    return normalize(face_uv_to_direction(face, u, v))


def panorama_directions(n: int) -> np.ndarray:
    """About n directions of an equirectangular panorama (2:1) in scanline
    order: the coherent, image-order access a renderer makes."""
    height = max(2, int(round(np.sqrt(n / 2))))
    t = (np.arange(height) + 0.5) / height * np.pi
    s = (np.arange(2 * height) + 0.5) / (2 * height) * 2 * np.pi
    s, t = np.meshgrid(s, t)
    return np.stack([np.sin(t) * np.sin(s), np.cos(t), np.sin(t) * np.cos(s)], -1).reshape(-1, 3)


def per_direction_error(rgb: np.ndarray, truth: np.ndarray) -> np.ndarray:
    return np.sqrt(np.mean((np.asarray(rgb, float) - truth) ** 2, axis=1))


def error_stats(errors: np.ndarray) -> dict:
    """rms, p99, max of per-direction errors (NaN counts as infinitely wrong)."""
    errors = np.where(np.isfinite(errors), errors, np.inf)
    if errors.size == 0:
        return {"rms": np.nan, "p99": np.nan, "max": np.nan}
    return {"rms": float(np.sqrt(np.mean(errors ** 2))),
            "p99": float(np.percentile(errors, 99)),
            "max": float(errors.max())}


def smooth_mask(env: AnalyticEnvironment, dirs: np.ndarray, size: int) -> np.ndarray:
    return env.distance_to_features(dirs) > SMOOTH_MARGIN_TEXELS * 2.0 / size
