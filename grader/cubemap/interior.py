"""An interior: a box room lit by a few bright rectangular lights.

Three emitters (two ceiling panels and a window) are far brighter than the
walls (about 40 and 12 against walls of about 0.05 to 1): like a real
interior probe, most of the light comes from a small solid angle. Walls are
Lambertian, lit directly by the emitters (each integrated on a 4 x 4 grid,
cosine at both ends, no occlusion: a box is convex) plus a constant
ambient term standing in for interreflection.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .directions import average_over_texels
from .room import Room

FACE_SIZE = 128
SAMPLES = 3
ROOM = Room(low=(-3.0, -1.4, -5.0), high=(4.0, 1.6, 2.5))
ALBEDO = np.array([
    [0.45, 0.60, 0.45],   # +x wall: pale green
    [0.50, 0.55, 0.70],   # -x wall: pale blue (holds the window)
    [0.80, 0.80, 0.78],   # ceiling
    [0.35, 0.22, 0.12],   # floor: wood
    [0.60, 0.55, 0.45],   # +z wall: beige
    [0.70, 0.65, 0.55],   # -z wall: warm white
])
AMBIENT_IRRADIANCE = 0.4
LIGHT_GRID = 4


@dataclass(frozen=True)
class RectangleLight:
    """An emitting rectangle on a wall: its centre, two half-edge vectors, RGB radiance."""
    centre: tuple[float, float, float]
    half_u: tuple[float, float, float]
    half_v: tuple[float, float, float]
    radiance: tuple[float, float, float]

    def contains(self, p: np.ndarray) -> np.ndarray:
        q = p - np.asarray(self.centre)
        inside = np.ones(p.shape[:-1], bool)
        for half in (np.asarray(self.half_u), np.asarray(self.half_v)):
            inside &= np.abs(q @ half) <= half @ half
        # On the light's plane (within a thin slab).
        normal = np.cross(self.half_u, self.half_v)
        return inside & (np.abs(q @ (normal / np.linalg.norm(normal))) < 1e-6)

    def irradiance(self, p: np.ndarray, n: np.ndarray) -> np.ndarray:
        """Irradiance (..., 3) at points p with normals n (midpoint rule over the rectangle)."""
        hu, hv = np.asarray(self.half_u), np.asarray(self.half_v)
        normal = np.cross(hu, hv)
        area = 4.0 * np.linalg.norm(normal)
        normal /= np.linalg.norm(normal)
        offsets = (np.arange(LIGHT_GRID) + 0.5) / LIGHT_GRID * 2.0 - 1.0
        total = np.zeros(p.shape[:-1])
        for a in offsets:
            for b in offsets:
                to_light = np.asarray(self.centre) + a * hu + b * hv - p
                r2 = np.sum(to_light ** 2, axis=-1)
                w = to_light / np.sqrt(r2)[..., None]
                cos_receiver = np.maximum(np.sum(w * n, axis=-1), 0.0)
                cos_emitter = np.abs(w @ normal)
                total += cos_receiver * cos_emitter / r2
        return total[..., None] * (area / LIGHT_GRID ** 2) * np.asarray(self.radiance)


LIGHTS = (
    RectangleLight((0.0, 1.6, -2.0), (0.6, 0.0, 0.0), (0.0, 0.0, 0.3), (40.0, 38.0, 34.0)),
    RectangleLight((1.8, 1.6, 0.8), (0.3, 0.0, 0.0), (0.0, 0.0, 0.6), (40.0, 38.0, 34.0)),
    RectangleLight((-3.0, 0.35, -2.2), (0.0, 0.65, 0.0), (0.0, 0.0, 1.0), (10.0, 11.5, 13.5)),
)


def radiance(d: np.ndarray) -> np.ndarray:
    """Linear RGB at unit directions d (..., 3) seen from the origin."""
    p, wall = ROOM.hit(d)
    n = ROOM.inward_normal(wall)
    irradiance = AMBIENT_IRRADIANCE + sum(light.irradiance(p, n) for light in LIGHTS)
    rgb = ALBEDO[wall] * irradiance / np.pi
    for light in LIGHTS:
        rgb = np.where(light.contains(p)[..., None], np.asarray(light.radiance), rgb)
    return rgb


def generate(face_size: int = FACE_SIZE) -> np.ndarray:
    """The interior's faces (6, N, N, 3) float32, texels averaged over solid angle."""
    return average_over_texels(radiance, face_size, face_size, SAMPLES)
