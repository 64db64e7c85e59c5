"""Cube-map geometry, once: face names, direction <-> (face, u, v), solid angle.

Everything here stands on the reference library (reference/src/lookup.c,
through grader.envmap.library): direction -> (face, u, v) *is* the C function, and
the inverse uses each face's frame read off that same function (`face_frames`),
so the face table is written down in one place, lookup.c; its text in
docs/assignment.md, the student READMEs and the figures is face_uv_formulas().
Faces are 0..5 = FACE_NAMES = +X -X +Y -Y +Z -Z (em_face). On a face, the
plane coordinates a = 2u - 1, b = 2v - 1 lie in [-1, 1]:

    direction = normal + a * u_axis + b * v_axis      (major component +-1)

Texel (x, y) of a W x H face has its centre at u = (x + 0.5) / W,
v = (y + 0.5) / H, y = 0 the bottom row (ARCHITECTURE.md, "cube maps").
Used by the checks, grader/cubemap/ (map generators and figures) and
grader/study/ (baking, accuracy).
"""
from __future__ import annotations

from functools import cache

import numpy as np

from . import oracle, library

FACE_NAMES = library.FACE_NAMES


def direction_to_face_uv(dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(face (n,) int, u (n,), v (n,)) for directions (n, 3), by the reference:
    ties go to the first of x, y, z; zero, NaN and infinite directions get
    face -1 and u = v = 0.5."""
    face, uv = oracle.current().direction_to_face(np.asarray(dirs, np.float64).reshape(-1, 3))
    return face.astype(np.int64), uv[:, 0], uv[:, 1]


@cache
def face_frames() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(normal, u_axis, v_axis), each (6, 3): every face's frame, probed from
    the reference's direction -> (u, v) (exact: the probes are dyadic)."""
    normal = np.zeros((6, 3))
    u_axis = np.zeros((6, 3))
    v_axis = np.zeros((6, 3))
    for k in range(6):
        normal[k, k // 2] = 1.0 if k % 2 == 0 else -1.0
        for j in {0, 1, 2} - {k // 2}:
            probe = normal[k].copy()
            probe[j] = 0.5          # a or b is +-0.5 along this axis
            face, uv = oracle.current().direction_to_face(probe[None])
            if face[0] != k:
                raise AssertionError(f"the reference maps {probe} to face {face[0]}, not {k}")
            a, b = 2 * uv[0] - 1
            u_axis[k, j], v_axis[k, j] = 2 * a, 2 * b
    return normal, u_axis, v_axis


def face_uv_formulas() -> dict[str, tuple[str, str]]:
    """The handout's (u, v) table, worded from face_frames(): face name ->
    (u, v) as "(1 + z/m)/2", m = |major component|. The one source of the
    table in docs/assignment.md, the student READMEs and the figures
    (tests/unit/envmap/test_face_table.py holds each copy to it)."""
    _, u_axis, v_axis = face_frames()

    def formula(axis: np.ndarray) -> str:
        j = int(np.flatnonzero(axis)[0])
        return f"(1 {'+' if axis[j] > 0 else '-'} {'xyz'[j]}/m)/2"
    return {name: (formula(u_axis[k]), formula(v_axis[k])) for k, name in enumerate(FACE_NAMES)}


def face_table_rows() -> list[str]:
    """face_uv_formulas() as the Markdown rows the documents print, in face order."""
    return [f"| {name} | {u} | {v} |" for name, (u, v) in face_uv_formulas().items()]


@cache
def cross_cells() -> dict[str, tuple[int, int]]:
    """(column, row) of each face's cell in the vertical cross, row 0 at the
    top of the image: where the reference's em_cubemap_to_cross puts it."""
    faces = np.zeros((6, 1, 1, 3), np.float32)
    faces[:, 0, 0, :] = np.arange(1, 7)[:, None]
    cross = library.faces_to_cross(faces)[..., 0]
    return {FACE_NAMES[int(cross[row, col]) - 1]: (int(col), int(row))
            for row, col in zip(*np.nonzero(cross))}


def face_plane_to_direction(face, a, b) -> np.ndarray:
    """Unnormalised directions (..., 3) through plane point (a, b) of `face`
    (an int or an array broadcast against a and b)."""
    normal, u_axis, v_axis = face_frames()
    face = np.asarray(face)
    a = np.asarray(a, np.float64)[..., None]
    b = np.asarray(b, np.float64)[..., None]
    return normal[face] + a * u_axis[face] + b * v_axis[face]


def face_uv_to_direction(face, u, v, normalized: bool = True) -> np.ndarray:
    """Directions (..., 3) float64 of points (u, v) on `face` (int or array);
    unit length unless normalized=False (then the major component is +-1)."""
    d = face_plane_to_direction(face, 2.0 * np.asarray(u, np.float64) - 1.0, 2.0 * np.asarray(v, np.float64) - 1.0)
    return normalize(d) if normalized else d


def uv_on_face(dirs: np.ndarray, face) -> np.ndarray:
    """(u, v) (n, 2) of directions (n, 3) on the given faces (n,), which each
    must touch (its major magnitude m is that face's): the inverse of
    face_uv_to_direction, exact at ties, where a nudge towards one face
    would move (u, v)."""
    normal, u_axis, v_axis = face_frames()
    dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
    face = np.asarray(face, np.int64)
    m = np.abs(dirs).max(axis=1)
    a = np.einsum("ij,ij->i", dirs, u_axis[face]) / m
    b = np.einsum("ij,ij->i", dirs, v_axis[face]) / m
    return np.stack([(1 + a) / 2, (1 + b) / 2], axis=1)


def normalize(dirs: np.ndarray) -> np.ndarray:
    return dirs / np.linalg.norm(dirs, axis=-1, keepdims=True)


def texel_centre_uv(width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """(u, v) of every texel centre, each (H, W), row 0 the bottom row."""
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    return np.meshgrid(u, v)


def texel_directions(width: int, height: int | None = None) -> np.ndarray:
    """Unit direction through every texel centre: (6, H, W, 3) float32."""
    height = width if height is None else height
    u, v = texel_centre_uv(width, height)
    return np.stack([face_uv_to_direction(f, u, v) for f in range(6)]).astype(np.float32)


def solid_angle_density(u, v) -> np.ndarray:
    """d(omega) / (du dv) on a face: 4 / (1 + a^2 + b^2)^(3/2), a = 2u-1, b = 2v-1.

    The face is the square [-1, 1]^2 at distance 1 from the centre; dOmega /
    (da db) = (1 + a^2 + b^2)^(-3/2), and (a, b) = (2u - 1, 2v - 1) scales
    areas by 4.
    """
    a = 2.0 * np.asarray(u, np.float64) - 1.0
    b = 2.0 * np.asarray(v, np.float64) - 1.0
    return 4.0 / (1.0 + a * a + b * b) ** 1.5


def texel_solid_angles(width: int, height: int | None = None) -> np.ndarray:
    """Exact solid angle of every texel of one face, (H, W) float64 (the same on all faces).

    The solid angle of the face rectangle from (0, 0) to (a, b) is
    atan(a b / sqrt(1 + a^2 + b^2)); texels are differences of corners.
    """
    height = width if height is None else height
    a = np.linspace(-1.0, 1.0, width + 1)[None, :]
    b = np.linspace(-1.0, 1.0, height + 1)[:, None]
    corner = np.arctan2(a * b, np.sqrt(1.0 + a * a + b * b))
    return corner[1:, 1:] - corner[1:, :-1] - corner[:-1, 1:] + corner[:-1, :-1]
