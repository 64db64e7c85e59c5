"""The debugging map `Cubemap/test_environment_map.hdr`, defined on the sphere of directions.

docs/assignment.md ("The scene and the test map"): a red, a green and a blue arrow
pointing along +x, +y and +z; when the arrows on the rendered sphere point
the same ways as the axes, fetchColor is done. The design (docs/cubemap.md):

- arrow a (red x, green y, blue z) is a band along the great circle from
  -a to +a through a chosen `via` direction: solid from 105 deg to 32 deg
  away from +a, then a head (a triangle) whose tip stops 12 deg short of +a;
  a dashed line continues the shaft back to -a;
- a flag on one side of each shaft (towards via x axis: the arrow's left as
  seen in a mirror), so a mirrored or transposed face shows;
- a filled disc of the arrow's colour at +a and a hollow ring at -a, so a
  face taken from the wrong sign shows;
- a neutral grey background with a faint grid in face coordinates (lines
  every quarter face, stronger at the face edges), so seams show.

The three via directions put the arrows in the +z hemisphere (an axes
triad on a mirror sphere seen from +z), with no two arrows crossing and no
arrow along a cube edge. `feature_at` is the exact description the grader's
arrow check uses.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .directions import average_over_texels

FACE_SIZE = 256

BACKGROUND = 0
GRID = 1
SEAM = 2
# Features of arrow k (0 red x, 1 green y, 2 blue z) are 3 + PARTS k + part.
SHAFT, HEAD, FLAG, DASH, DISC, RING = range(6)
PART_NAMES = ("shaft", "head", "flag", "dash", "disc", "ring")
PARTS = len(PART_NAMES)
ARROW_NAMES = ("red", "green", "blue")


def arrow_feature(arrow: int, part: int) -> int:
    """The feature code of one part of one arrow."""
    return 3 + PARTS * arrow + part


def feature_name(code: int) -> str:
    if code < 3:
        return ("background", "grid", "seam")[code]
    arrow, part = divmod(code - 3, PARTS)
    return f"{ARROW_NAMES[arrow]} {PART_NAMES[part]}"


FEATURE_COUNT = 3 + PARTS * 3

ARROW_COLOURS = np.array([
    [0.90, 0.05, 0.04],   # red: +x
    [0.05, 0.75, 0.06],   # green: +y
    [0.06, 0.12, 0.95],   # blue: +z
])
BACKGROUND_COLOUR = np.array([0.18, 0.18, 0.18])
GRID_COLOUR = np.array([0.26, 0.26, 0.26])
SEAM_COLOUR = np.array([0.40, 0.40, 0.40])


def feature_colours() -> np.ndarray:
    """Canonical linear RGB of every feature code: (FEATURE_COUNT, 3)."""
    colours = np.empty((FEATURE_COUNT, 3))
    colours[BACKGROUND], colours[GRID], colours[SEAM] = BACKGROUND_COLOUR, GRID_COLOUR, SEAM_COLOUR
    for arrow in range(3):
        for part in range(PARTS):
            colours[arrow_feature(arrow, part)] = ARROW_COLOURS[arrow]
    return colours


@dataclass(frozen=True)
class Arrow:
    """An arrow along the great circle from -axis to +axis through `via` (unit, perpendicular to axis)."""
    axis: np.ndarray
    via: np.ndarray

    @property
    def flag_side(self) -> np.ndarray:
        """via x axis: the arrow's left seen in a mirror (its right seen from the centre)."""
        return np.cross(self.via, self.axis)

    def point(self, theta_degrees: float) -> np.ndarray:
        """The point of the arrow's great circle theta degrees from +axis, towards via."""
        t = np.radians(theta_degrees)
        return np.cos(t) * self.axis + np.sin(t) * self.via


def _unit(v) -> np.ndarray:
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v)


_E = np.eye(3)
ARROWS = (
    # Seen in a mirror sphere from +z (the sphere's centre shows +z), red
    # runs left to right just below the centre, green bottom to top just left
    # of the centre (an axes corner at the lower left), and blue comes in from
    # the upper right rim to the centre: +z points at the viewer.
    Arrow(_E[0], _unit([0.0, -0.5, np.sqrt(3) / 2])),
    Arrow(_E[1], _unit([-0.5, 0.0, np.sqrt(3) / 2])),
    Arrow(_E[2], _unit([np.cos(np.radians(55)), np.sin(np.radians(55)), 0.0])),
)

# Geometry, in degrees on the sphere; theta is measured from +axis towards via.
TIP = 12.0            # head tip
HEAD_BASE = 32.0      # where the head meets the shaft
HEAD_HALF_WIDTH = 8.0
SHAFT_END = 105.0     # the solid shaft runs from HEAD_BASE to here
SHAFT_HALF_WIDTH = 2.5
FLAG_FROM, FLAG_TO = 84.0, 100.0          # a rectangle on the shaft's flag side
FLAG_HEIGHT = 6.0     # beyond the shaft's edge
DASH_END = 170.0      # a dashed line continues the shaft to the ring at -axis
DASH_ON, DASH_PERIOD = 6.0, 10.0
DASH_HALF_WIDTH = 1.2
DISC_RADIUS = 9.0     # around +axis
RING_INNER, RING_OUTER = 6.0, 10.0        # around -axis

GRID_STEP = 0.25      # face coordinates in [-1, 1]: lines every quarter face
GRID_HALF_WIDTH = 0.008
SEAM_HALF_WIDTH = 0.012


def _arrow_part(arrow: Arrow, d: np.ndarray) -> np.ndarray:
    """Part (SHAFT..RING) of arrow at unit directions d (..., 3); -1 where none."""
    along_axis = d @ arrow.axis
    along_via = d @ arrow.via
    offset = np.degrees(np.arcsin(np.clip(d @ arrow.flag_side, -1.0, 1.0)))  # + on the flag side
    theta = np.degrees(np.arctan2(along_via, along_axis))
    from_pos = np.degrees(np.arccos(np.clip(along_axis, -1.0, 1.0)))
    from_neg = 180.0 - from_pos

    part = np.full(d.shape[:-1], -1, np.int32)
    dash_phase = np.mod(theta - SHAFT_END, DASH_PERIOD)
    dash = ((theta > SHAFT_END) & (theta <= DASH_END) & (dash_phase <= DASH_ON)
            & (np.abs(offset) <= DASH_HALF_WIDTH))
    shaft = (theta >= HEAD_BASE) & (theta <= SHAFT_END) & (np.abs(offset) <= SHAFT_HALF_WIDTH)
    head_half = HEAD_HALF_WIDTH * (theta - TIP) / (HEAD_BASE - TIP)
    head = (theta >= TIP) & (theta < HEAD_BASE) & (np.abs(offset) <= head_half)
    flag = ((theta >= FLAG_FROM) & (theta <= FLAG_TO) & (offset > 0)
            & (offset <= SHAFT_HALF_WIDTH + FLAG_HEIGHT))
    part[dash] = DASH
    part[flag] = FLAG
    part[shaft] = SHAFT
    part[head] = HEAD
    part[from_pos <= DISC_RADIUS] = DISC
    part[(from_neg >= RING_INNER) & (from_neg <= RING_OUTER)] = RING
    return part


def _grid_feature(d: np.ndarray) -> np.ndarray:
    """BACKGROUND, GRID or SEAM from the face coordinates of d."""
    m = np.abs(d)
    major = np.argmax(m, axis=-1)
    m_major = np.take_along_axis(m, major[..., None], axis=-1)
    coords = np.abs(d) / m_major                   # the two minor ones are in [0, 1]
    minor = np.ones(d.shape, bool)
    np.put_along_axis(minor, major[..., None], False, axis=-1)
    q = coords / GRID_STEP
    off_line = np.abs(q - np.round(q)) * GRID_STEP
    on_grid = np.any(minor & (off_line <= GRID_HALF_WIDTH), axis=-1)
    on_seam = np.any(minor & (coords >= 1.0 - SEAM_HALF_WIDTH), axis=-1)
    feature = np.full(d.shape[:-1], BACKGROUND, np.int32)
    feature[on_grid] = GRID
    feature[on_seam] = SEAM
    return feature


def feature_at(directions: np.ndarray) -> np.ndarray:
    """Feature code (int32, shape (...)) of the test map at directions (..., 3), any length.

    Arrows are drawn over the grid; where two arrows' parts overlap (they do
    not, by design) the later arrow wins.
    """
    d = np.asarray(directions, np.float64)
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    feature = _grid_feature(d)
    for k, arrow in enumerate(ARROWS):
        part = _arrow_part(arrow, d)
        feature = np.where(part >= 0, arrow_feature(k, part), feature)
    return feature


def radiance(directions: np.ndarray) -> np.ndarray:
    """Linear RGB of the test map at directions (..., 3): its canonical colours."""
    return feature_colours()[feature_at(directions)]


def generate(face_size: int = FACE_SIZE, samples: int = 4) -> np.ndarray:
    """The test map's faces (6, N, N, 3) float32, texels averaged over solid angle."""
    return average_over_texels(radiance, face_size, face_size, samples)
