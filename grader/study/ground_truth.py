"""An analytic environment whose exact radiance is known for every direction.

A smooth, band-limited sky (a constant, a gradient and a few broad lobes)
over a hard horizon (a smooth ground below a slightly tilted plane) and a
bright sun disc. The horizon and the disc rim are the only discontinuities;
both are circles on the sphere (caps), so whether a texel straddles one is a
cheap test and the bake can supersample exactly those texels. The tilt and the
sun's direction are generic on purpose, so no feature lines up with texel rows
or cube edges.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass, field

import numpy as np

from ..envmap.geometry import normalize


@dataclass(frozen=True)
class Lobe:
    axis: tuple[float, float, float]
    sharpness: float                  # exp(k (cos - 1)); k <= 8 keeps it band-limited
    rgb: tuple[float, float, float]


@dataclass(frozen=True)
class Cap:
    """The directions d with d . axis > cos_radius (a disc on the sphere)."""
    axis: tuple[float, float, float]
    cos_radius: float

    def unit_axis(self) -> np.ndarray:
        return normalize(np.array(self.axis, float))


@dataclass(frozen=True)
class AnalyticEnvironment:
    sky_base: tuple[float, float, float] = (0.35, 0.45, 0.65)
    sky_gradient: tuple[float, float, float] = (0.15, 0.1, -0.1)   # times d . up
    lobes: tuple[Lobe, ...] = (
        Lobe((0.3, 0.8, -0.5), 2.0, (0.6, 0.5, 0.3)),
        Lobe((-0.7, 0.2, 0.6), 4.0, (0.2, 0.35, 0.5)),
        Lobe((0.5, -0.3, 0.8), 6.0, (0.4, 0.15, 0.1)),
        Lobe((-0.2, 0.5, -0.9), 8.0, (0.1, 0.3, 0.2)),
    )
    up: tuple[float, float, float] = (0.0, 1.0, 0.0)
    # Above the horizon is d . normal > 0: tilted ~4.6 degrees from +Y.
    horizon: Cap = Cap((0.06, 1.0, 0.05), 0.0)
    ground_rgb: tuple[float, float, float] = (0.3, 0.24, 0.18)
    ground_gradient: tuple[float, float, float] = (0.08, 0.06, 0.04)  # times d . x
    sun: Cap = Cap((0.45, 0.55, -0.70), float(np.cos(np.radians(4.0))))
    sun_rgb: tuple[float, float, float] = (20.0, 18.0, 15.0)
    # Set False for an environment with no discontinuity at all (tests of the bake's rate).
    sharp: bool = field(default=True)

    def caps(self) -> list[Cap]:
        """The discontinuities, as cap boundaries."""
        return [self.horizon, self.sun] if self.sharp else []

    def key(self) -> str:
        """A short hash of every parameter (the bake cache is keyed by it)."""
        text = json.dumps(asdict(self), sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def smooth_sky(self, d: np.ndarray) -> np.ndarray:
        out = np.empty(d.shape[:-1] + (3,))
        out[...] = self.sky_base
        out += (d @ np.array(self.up))[..., None] * np.array(self.sky_gradient)
        for lobe in self.lobes:
            c = d @ normalize(np.array(lobe.axis, float))
            out += np.exp(lobe.sharpness * (c - 1))[..., None] * np.array(lobe.rgb)
        return out

    def radiance(self, dirs: np.ndarray) -> np.ndarray:
        """Exact radiance (..., 3) float64 for directions (..., 3) (any length > 0)."""
        d = normalize(np.asarray(dirs, float))
        sky = self.smooth_sky(d)
        if not self.sharp:
            return sky
        above = (d @ self.horizon.unit_axis()) > self.horizon.cos_radius
        ground = np.array(self.ground_rgb) + (d[..., :1]) * np.array(self.ground_gradient)
        out = np.where(above[..., None], sky, ground)
        in_sun = (d @ self.sun.unit_axis()) > self.sun.cos_radius
        out += in_sun[..., None] * np.array(self.sun_rgb)
        return out

    def distance_to_features(self, dirs: np.ndarray) -> np.ndarray:
        """Angle (radians) from each direction to the nearest discontinuity (inf if none)."""
        d = normalize(np.asarray(dirs, float))
        dist = np.full(d.shape[:-1], np.inf)
        for cap in self.caps():
            angle = np.arccos(np.clip(d @ cap.unit_axis(), -1, 1))
            dist = np.minimum(dist, np.abs(angle - np.arccos(cap.cos_radius)))
        return dist


DEFAULT_ENVIRONMENT = AnalyticEnvironment()
SMOOTH_ENVIRONMENT = AnalyticEnvironment(sharp=False)
