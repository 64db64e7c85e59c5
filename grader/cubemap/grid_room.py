"""A checker room: a box room tiled in squares with dark grout lines.

The room is turned 20 degrees about y and the viewer is off centre, so its
straight lines cross the cube's face edges at angles: with a correct lookup
they stay straight in any perspective view; a seam error bends or breaks
them. Each wall has its own pair of tile colours, so a face taken from the
wrong wall shows. Unlit: every surface has its colour as radiance.
"""
from __future__ import annotations

import numpy as np

from .directions import average_over_texels
from .room import Room

FACE_SIZE = 256
SAMPLES = 3
ROOM = Room(low=(-3.3, -1.2, -4.1), high=(4.7, 2.8, 3.9))   # viewer at the origin
TURN_DEGREES = 20.0     # the room is turned by this about +y
TILE = 0.5              # metres
GROUT_HALF_WIDTH = 0.02
GROUT = np.array([0.02, 0.02, 0.02])
TILE_COLOURS = np.array([   # per wall: (light, dark)
    [[0.80, 0.30, 0.25], [0.85, 0.82, 0.78]],   # +x: red
    [[0.25, 0.60, 0.30], [0.85, 0.82, 0.78]],   # -x: green
    [[0.90, 0.90, 0.90], [0.60, 0.60, 0.60]],   # ceiling: greys
    [[0.45, 0.45, 0.45], [0.15, 0.15, 0.15]],   # floor: dark greys
    [[0.25, 0.35, 0.80], [0.85, 0.82, 0.78]],   # +z: blue
    [[0.85, 0.70, 0.20], [0.85, 0.82, 0.78]],   # -z: yellow
])


def _turn(d: np.ndarray, degrees: float) -> np.ndarray:
    """Rotate directions about +y."""
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    x, y, z = np.moveaxis(d, -1, 0)
    return np.stack([c * x + s * z, y, -s * x + c * z], axis=-1)


def radiance(d: np.ndarray) -> np.ndarray:
    """Linear RGB at unit directions d (..., 3) seen from the viewer."""
    p, wall = ROOM.hit(_turn(d, -TURN_DEGREES))      # into the room's frame
    cell = p / TILE
    in_plane = np.ones(p.shape, bool)
    np.put_along_axis(in_plane, (wall // 2)[..., None], False, axis=-1)
    grout = np.any(in_plane & (np.abs(cell - np.round(cell)) * TILE <= GROUT_HALF_WIDTH), axis=-1)
    parity = np.sum(np.where(in_plane, np.floor(cell), 0.0), axis=-1).astype(np.int64) % 2
    rgb = TILE_COLOURS[wall, parity]
    return np.where(grout[..., None], GROUT, rgb)


def generate(face_size: int = FACE_SIZE) -> np.ndarray:
    """The checker room's faces (6, N, N, 3) float32, texels averaged over solid angle."""
    return average_over_texels(radiance, face_size, face_size, SAMPLES)
