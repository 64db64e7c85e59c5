"""Bake an analytic environment into a cube map: each texel is the radiance
averaged over the texel's solid angle (not a point sample at its centre).

On a face plane at distance 1 the solid angle is dOmega = J(a, b) da db with
J = 1 / (1 + a^2 + b^2)^(3/2) (grader.envmap.geometry.solid_angle_density, which is
dOmega / (du dv) = 4 J), so a texel's
value is  sum w_i J_i L_i / sum w_i J_i  over quadrature points in the texel.

Texels where the radiance is smooth use Gauss-Legendre quadrature (4 x 4 by
default: exact for polynomials of degree 7, so its error falls as h^8 and is
negligible). Texels that a discontinuity (horizon, sun rim) may cross, found
by a conservative cone test, use a dense midpoint grid (48 x 48 by default),
whose error is a fraction of the feature's contrast of order 1/48^2 per
crossing cell. bake_error() measures both against a finer bake.

Baked maps are cached as .npy under build/study/, keyed by a hash of the
environment and the quadrature.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import PROJECT_ROOT
from ..envmap.geometry import face_plane_to_direction, normalize, solid_angle_density
from .ground_truth import AnalyticEnvironment

CACHE_DIR = PROJECT_ROOT / "build" / "study"
SMOOTH_ORDER = 4       # Gauss-Legendre points per axis, smooth texels
EDGE_SAMPLES = 48      # midpoint samples per axis, texels crossed by a feature
CHUNK = 1 << 20        # quadrature points per numpy step (bounds memory)


def _texel_average(env: AnalyticEnvironment, face: int, x: np.ndarray, y: np.ndarray,
                   size: int, nodes: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Solid-angle averages (len(x), 3) of texels (x, y) of `face`, with
    quadrature nodes/weights given on [0, 1]."""
    out = np.empty((len(x), 3))
    per_texel = len(nodes) ** 2
    step = max(1, CHUNK // per_texel)
    na, nb = np.meshgrid(nodes, nodes, indexing="xy")
    wab = np.outer(weights, weights).ravel()
    for s in range(0, len(x), step):
        xs, ys = x[s:s + step, None], y[s:s + step, None]
        a = (xs + na.ravel()) / size * 2 - 1
        b = (ys + nb.ravel()) / size * 2 - 1
        w = wab * solid_angle_density((a + 1) / 2, (b + 1) / 2)     # the factor 4 cancels below
        radiance = env.radiance(face_plane_to_direction(np.full(a.shape, face), a, b))
        out[s:s + step] = np.einsum("tk,tkc->tc", w, radiance) / w.sum(axis=1)[:, None]
    return out


def _gauss_legendre(order: int):
    nodes, weights = np.polynomial.legendre.leggauss(order)
    return (nodes + 1) / 2, weights / 2


def _midpoints(count: int):
    return (np.arange(count) + 0.5) / count, np.full(count, 1.0 / count)


def feature_texels(env: AnalyticEnvironment, face: int, size: int) -> np.ndarray:
    """Boolean (size, size) [y, x]: texels a cap boundary may cross.

    Conservative: the angle from the cap axis varies over a texel by at most
    the texel's angular radius (centre to farthest corner), padded by 5%."""
    edges = np.arange(size + 1) / size * 2 - 1
    centres = (edges[:-1] + edges[1:]) / 2
    bc, ac = np.meshgrid(centres, centres, indexing="ij")
    centre = normalize(face_plane_to_direction(np.full(ac.shape, face), ac, bc))
    radius = np.zeros(ac.shape)
    for dx in (0, 1):
        for dy in (0, 1):
            bk, ak = np.meshgrid(edges[dy:size + dy], edges[dx:size + dx], indexing="ij")
            corner = normalize(face_plane_to_direction(np.full(ak.shape, face), ak, bk))
            cos = np.clip(np.einsum("...c,...c->...", centre, corner), -1, 1)
            radius = np.maximum(radius, np.arccos(cos))
    crossed = np.zeros(ac.shape, bool)
    for cap in env.caps():
        angle = np.arccos(np.clip(centre @ cap.unit_axis(), -1, 1))
        crossed |= np.abs(angle - np.arccos(cap.cos_radius)) <= 1.05 * radius + 1e-12
    return crossed


def bake_uncached(env: AnalyticEnvironment, size: int, smooth_order: int = SMOOTH_ORDER,
                  edge_samples: int = EDGE_SAMPLES) -> np.ndarray:
    """Cube map (6, size, size, 3) float32 of solid-angle texel averages."""
    faces = np.empty((6, size, size, 3), np.float32)
    smooth_rule = _gauss_legendre(smooth_order)
    edge_rule = _midpoints(edge_samples)
    for face in range(6):
        crossed = feature_texels(env, face, size)
        for mask, rule in ((~crossed, smooth_rule), (crossed, edge_rule)):
            y, x = np.nonzero(mask)
            if len(x):
                faces[face, y, x] = _texel_average(env, face, x, y, size, *rule)
    return faces


def bake(env: AnalyticEnvironment, size: int, smooth_order: int = SMOOTH_ORDER,
         edge_samples: int = EDGE_SAMPLES, cache_dir: Path | None = CACHE_DIR) -> np.ndarray:
    """bake_uncached, cached under cache_dir (None: no cache)."""
    if cache_dir is None:
        return bake_uncached(env, size, smooth_order, edge_samples)
    path = Path(cache_dir) / f"bake-{env.key()}-{size}-gl{smooth_order}-e{edge_samples}.npy"
    if path.exists():
        return np.load(path)
    faces = bake_uncached(env, size, smooth_order, edge_samples)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".{np.random.randint(1 << 30)}.tmp.npy")
    np.save(tmp, faces)
    tmp.replace(path)   # atomic: parallel test workers may bake the same map
    return faces


def bake_error(env: AnalyticEnvironment, size: int, cache_dir: Path | None = CACHE_DIR) -> dict:
    """The bake's own error, estimated against a bake with twice the edge
    samples and 8 x 8 Gauss-Legendre points: max and RMS over texels, for the
    smooth texels and the feature texels separately."""
    coarse = bake(env, size, cache_dir=cache_dir).astype(np.float64)
    fine = bake(env, size, smooth_order=8, edge_samples=2 * EDGE_SAMPLES,
                cache_dir=cache_dir).astype(np.float64)
    crossed = np.stack([feature_texels(env, f, size) for f in range(6)])
    diff = np.abs(coarse - fine).max(axis=-1)
    out = {"size": size}
    for name, mask in (("smooth", ~crossed), ("feature", crossed)):
        d = diff[mask]
        out[f"max_{name}"] = float(d.max()) if d.size else 0.0
        out[f"rms_{name}"] = float(np.sqrt(np.mean(d ** 2))) if d.size else 0.0
    return out
