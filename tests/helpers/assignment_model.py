"""An independent numpy model of ASSIGNMENT.md, for tests and benchmarks.

Written from the text of ASSIGNMENT.md (and the handout's equations (1)-(3)),
not from the reference C, so that the two can check each other. Cube maps are
numpy arrays (6, H, W, 3) indexed [face, y, x, channel], y = 0 the bottom row,
faces +X -X +Y -Y +Z -Z (ASSIGNMENT.md, "Buffer").

The tie rule of ASSIGNMENT.md is "every face a direction touches is a correct
answer", so the model can say which faces a direction touches
(`touching_faces`) and give the colour through each (`fetch_touching`);
`fetch` picks one touching face per direction, for speed comparisons.
"""
from __future__ import annotations

import numpy as np

FACE_NAMES = ("+X", "-X", "+Y", "-Y", "+Z", "-Z")
FILTERS = ("nearest", "bilinear")


def touching_faces(dirs: np.ndarray) -> np.ndarray:
    """(n, 6) bool: the faces each direction exits through. A face is touched
    when its axis has the largest |component| and the component has the
    face's sign; edges touch two faces, corners three. Zero, NaN and infinite
    directions touch none."""
    dirs = np.asarray(dirs, dtype=np.float64).reshape(-1, 3)
    size = np.abs(dirs)
    with np.errstate(invalid="ignore"):
        largest = size.max(axis=1, keepdims=True)
        valid = np.isfinite(dirs).all(axis=1) & (largest[:, 0] > 0)
        is_major = (size == largest) & valid[:, None]
    touched = np.zeros((len(dirs), 6), dtype=bool)
    for axis in range(3):
        touched[:, 2 * axis] = is_major[:, axis] & (dirs[:, axis] > 0)
        touched[:, 2 * axis + 1] = is_major[:, axis] & (dirs[:, axis] < 0)
    return touched


# ASSIGNMENT.md, "Face parameters": (u, v) from x, y, z already divided by m.
UV_TABLE = {
    0: lambda x, y, z: ((1 + z) / 2, (1 + y) / 2),  # +X
    1: lambda x, y, z: ((1 - z) / 2, (1 + y) / 2),  # -X
    2: lambda x, y, z: ((1 + x) / 2, (1 + z) / 2),  # +Y
    3: lambda x, y, z: ((1 + x) / 2, (1 - z) / 2),  # -Y
    4: lambda x, y, z: ((1 + x) / 2, (1 - y) / 2),  # +Z
    5: lambda x, y, z: ((1 + x) / 2, (1 + y) / 2),  # -Z
}


def face_uv(dirs: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(u, v) where the ray along each direction meets face faces[i]
    (UV_TABLE), with m = |component on the face's axis|. Only meaningful for
    a face the direction touches; NaN for faces outside 0..5."""
    dirs = np.asarray(dirs, dtype=np.float64).reshape(-1, 3)
    faces = np.broadcast_to(np.asarray(faces), (len(dirs),))
    u = np.full(len(dirs), np.nan)
    v = np.full(len(dirs), np.nan)
    for face, uv_of in UV_TABLE.items():
        rows = np.flatnonzero(faces == face)
        on_face = dirs[rows]
        m = np.abs(on_face[:, face // 2])
        with np.errstate(invalid="ignore", divide="ignore"):
            x, y, z = (on_face / m[:, None]).T
        u[rows], v[rows] = uv_of(x, y, z)
    return u, v


def read_nearest(cube: np.ndarray, faces: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The handout's starting code: x0 = clamp((int)(u*W), 0, W-1), likewise y0."""
    _, height, width, _ = cube.shape
    x0 = np.clip(np.trunc(u * width), 0, width - 1).astype(np.intp)
    y0 = np.clip(np.trunc(v * height), 0, height - 1).astype(np.intp)
    return cube[faces, y0, x0].astype(np.float64)


def read_bilinear(cube: np.ndarray, faces: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The handout's bilinear interpolation: p = (u W, v H); the lattice
    points around p (texel (x, y) at integer point (x, y)), clamped to
    [0, W-1] x [0, H-1]; alpha, beta the fractional parts of p; then
    c0 = (1-alpha) c00 + alpha c10, c1 = (1-alpha) c01 + alpha c11,
    c = (1-beta) c0 + beta c1."""
    _, height, width, _ = cube.shape
    px, py = u * width, v * height
    left, bottom = np.floor(px), np.floor(py)
    alpha, beta = (px - left)[:, None], (py - bottom)[:, None]
    x0 = np.clip(left, 0, width - 1).astype(np.intp)
    x1 = np.clip(left + 1, 0, width - 1).astype(np.intp)
    y0 = np.clip(bottom, 0, height - 1).astype(np.intp)
    y1 = np.clip(bottom + 1, 0, height - 1).astype(np.intp)
    c00, c10 = cube[faces, y0, x0].astype(np.float64), cube[faces, y0, x1].astype(np.float64)
    c01, c11 = cube[faces, y1, x0].astype(np.float64), cube[faces, y1, x1].astype(np.float64)
    c0 = (1 - alpha) * c00 + alpha * c10
    c1 = (1 - alpha) * c01 + alpha * c11
    return (1 - beta) * c0 + beta * c1


READERS = {"nearest": read_nearest, "bilinear": read_bilinear}


def read_texture(cube: np.ndarray, faces, u, v, filter: str = "bilinear") -> np.ndarray:
    """Colours (n, 3) at (u, v) in [0, 1] on faces (n,)."""
    u = np.asarray(u, dtype=np.float64).reshape(-1)
    v = np.asarray(v, dtype=np.float64).reshape(-1)
    faces = np.broadcast_to(np.asarray(faces, dtype=np.intp), u.shape)
    return READERS[filter](cube, faces, u, v)


def fetch_touching(cube: np.ndarray, dirs: np.ndarray, filter: str = "bilinear"):
    """(colours (n, 6, 3), touched (n, 6)): the colour through every face a
    direction touches; NaN for faces it does not touch."""
    dirs = np.asarray(dirs, dtype=np.float64).reshape(-1, 3)
    touched = touching_faces(dirs)
    colours = np.full((len(dirs), 6, 3), np.nan)
    for face in range(6):
        rows = np.flatnonzero(touched[:, face])
        u, v = face_uv(dirs[rows], np.full(len(rows), face))
        colours[rows, face] = read_texture(cube, np.full(len(rows), face), u, v, filter)
    return colours, touched


def fetch(cube: np.ndarray, dirs: np.ndarray, filter: str = "bilinear") -> np.ndarray:
    """Colours (n, 3): one touching face per direction (the first in buffer
    order), black for directions that touch none. Vectorised, one texture
    read per direction: the baseline for speed comparisons."""
    dirs = np.asarray(dirs, dtype=np.float64).reshape(-1, 3)
    touched = touching_faces(dirs)
    valid = touched.any(axis=1)
    faces = np.argmax(touched, axis=1)
    u, v = face_uv(dirs, faces)
    u = np.where(valid, u, 0.5)
    v = np.where(valid, v, 0.5)
    colours = read_texture(cube, faces, u, v, filter)
    colours[~valid] = 0.0
    return colours
