"""Where directions land in lat-long (equirectangular) and angular (light-probe) images.

Image coordinates are (s, t) in [0, 1]: s from the left edge, t from the top
edge of the image (pixel (i, j) covers s in [i/W, (i+1)/W]).

Lat-long (this project's convention; docs/cubemap.md): the centre of the
image looks along -z (the cube's front face), +x is at s = 3/4, -x at 1/4,
+y is the top row; longitude runs once round the image. That is the view
from inside the sphere, so text drawn on the map reads correctly.

Angular map (Debevec's light-probe format): the disc inscribed in the
square; the centre looks along -z, the rim is +z, the distance from the
centre is proportional to the angle from -z: r = arccos(-z) / pi, with +x
to the right and +y up (pinned against rnl_probe.hdr and rnl_cross.hdr,
docs/cubemap.md).
"""
from __future__ import annotations

import numpy as np


def latlong_to_direction(s: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Unit directions (..., 3) of lat-long image coordinates."""
    longitude = 2.0 * np.pi * (np.asarray(s, np.float64) - 0.5)
    latitude = np.pi * (0.5 - np.asarray(t, np.float64))
    c = np.cos(latitude)
    return np.stack([c * np.sin(longitude), np.sin(latitude), -c * np.cos(longitude)], axis=-1)


def direction_to_latlong(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lat-long image coordinates (s, t) of unit directions (..., 3)."""
    x, y, z = np.moveaxis(np.asarray(d, np.float64), -1, 0)
    s = 0.5 + np.arctan2(x, -z) / (2.0 * np.pi)
    t = 0.5 - np.arcsin(np.clip(y, -1.0, 1.0)) / np.pi
    return s, t


def angular_to_direction(s: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(unit directions (..., 3), inside (...) bool) of angular-map image coordinates."""
    a = 2.0 * np.asarray(s, np.float64) - 1.0
    b = 1.0 - 2.0 * np.asarray(t, np.float64)
    r = np.hypot(a, b)
    angle = np.pi * np.minimum(r, 1.0)                  # from -z
    scale = np.where(r > 0, np.sin(angle) / np.where(r > 0, r, 1.0), 0.0)
    d = np.stack([a * scale, b * scale, -np.cos(angle)], axis=-1)
    return d, r <= 1.0


def direction_to_angular(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Angular-map image coordinates (s, t) of unit directions (..., 3)."""
    x, y, z = np.moveaxis(np.asarray(d, np.float64), -1, 0)
    planar = np.hypot(x, y)
    r = np.arccos(np.clip(-z, -1.0, 1.0)) / np.pi
    scale = np.where(planar > 0, r / np.where(planar > 0, planar, 1.0), 0.0)
    return 0.5 + 0.5 * x * scale, 0.5 - 0.5 * y * scale
