"""An axis-aligned box room seen from a point inside it: where a direction meets a wall.

Walls are numbered like cube faces: 0 +x, 1 -x, 2 +y (ceiling), 3 -y
(floor), 4 +z, 5 -z; each wall's inward normal is minus its axis.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Room:
    low: tuple[float, float, float]     # corner with the smallest x, y, z (the viewer at 0)
    high: tuple[float, float, float]

    def hit(self, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(points (..., 3), wall (...) int) where rays from the origin along unit d leave the box."""
        low, high = np.asarray(self.low), np.asarray(self.high)
        with np.errstate(divide="ignore"):
            # Distance to the wall each component heads for; inf along a zero component.
            bound = np.where(d > 0, high, low)
            distance = np.where(d != 0, bound / np.where(d != 0, d, 1.0), np.inf)
        axis = np.argmin(distance, axis=-1)
        t = np.take_along_axis(distance, axis[..., None], axis=-1)
        heading = np.take_along_axis(d, axis[..., None], axis=-1)[..., 0]
        wall = 2 * axis + (heading < 0)
        return d * t, wall

    def inward_normal(self, wall: np.ndarray) -> np.ndarray:
        """(..., 3) unit normals pointing into the room."""
        normal = np.zeros(np.shape(wall) + (3,))
        axis = np.asarray(wall) // 2
        sign = np.where(np.asarray(wall) % 2 == 0, -1.0, 1.0)
        np.put_along_axis(normal, axis[..., None], sign[..., None], axis=-1)
        return normal
