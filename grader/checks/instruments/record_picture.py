"""A picture of the record: the unfolded cross drawn twice, each face
lettered with an F that shows its orientation: as the handout's table reads
it (the reference), and through the (face, u, v) the student's fetchColor
asked readTexture for at each texel (instruments.fetch_record),
so a face upside down or read from the wrong face shows before any word."""
from __future__ import annotations

import numpy as np

from ...envmap.geometry import FACE_NAMES, cross_cells, face_uv_to_direction
from ...i18n import _
from . import fetch_record
from .textures import coordinate_faces

SIZE = 24                      # texels per face side
HUES = np.array([[0.93, 0.45, 0.40], [0.55, 0.20, 0.18], [0.45, 0.80, 0.40],
                 [0.18, 0.45, 0.16], [0.40, 0.55, 0.95], [0.16, 0.22, 0.55]], np.float32)   # +X -X +Y -Y +Z -Z
UNSEEN = np.array([0.5, 0.5, 0.5], np.float32)    # no face asked (a crash, no call, no face start)


def lettered_faces(size: int = SIZE) -> np.ndarray:
    """(6, size, size, 3): each face its hue with a white F, upright in the
    face's own (u, v) (u to the right, v up): a flip or a turn moves it."""
    c = (np.arange(size) + 0.5) / size
    u, v = np.meshgrid(c, c)                 # [y, x]: v runs with the row (row 0 is v near 0)
    f = (((u >= 0.25) & (u < 0.37) & (v >= 0.15) & (v < 0.85))
         | ((u >= 0.25) & (u < 0.75) & (v >= 0.73) & (v < 0.85))
         | ((u >= 0.25) & (u < 0.62) & (v >= 0.47) & (v < 0.58)))
    faces = np.broadcast_to(HUES[:, None, None, :], (6, size, size, 3)).copy()
    faces[:, f] = 1.0
    return faces


def asked_faces(lookups, size: int = SIZE) -> np.ndarray:
    """(6, size, size, 3): each texel of each face coloured by what the
    student's fetchColor asks for in the direction through its lattice point:
    the lettered faces' texel that holds the asked (face, u, v), so a correct
    fetchColor draws the reference's faces exactly and a flip or a turn
    draws them flipped or turned, texel for texel. Recorded on
    the diagnosis's coordinate faces (their size: no new worker), which only
    code that reads the texels itself sees (face_map.places)."""
    from .face_map import FACE_SIZE, places
    lookups.set_faces(coordinate_faces(FACE_SIZE, FACE_SIZE))
    # At each texel's lattice point p = (x, y) (just inside, off the edges):
    # the handout's readTexture reads that texel alone there.
    c = (np.arange(size) + 0.01) / size
    u, v = np.meshgrid(c, c)
    face = np.repeat(np.arange(6), size * size)
    dirs = face_uv_to_direction(face, np.tile(u.ravel(), 6), np.tile(v.ravel(), 6))
    asked, uv, _itself = places(fetch_record.record(lookups, dirs), (FACE_SIZE, FACE_SIZE))
    colours = np.tile(UNSEEN, (len(dirs), 1))
    seen = (asked >= 0) & np.isfinite(uv).all(axis=1)
    column, row = (np.clip(np.floor(uv[seen] * size), 0, size - 1).astype(np.int64).T)
    colours[seen] = lettered_faces(size)[asked[seen], row, column]
    return colours.reshape(6, size, size, 3).astype(np.float32)


def cross(faces: np.ndarray) -> np.ndarray:
    """The faces (6, H, W, 3) laid out as the vertical cross (docs/assignment.md), top row first."""
    h, w = faces.shape[1:3]
    out = np.ones((4 * h, 3 * w, 3), np.float32)
    for name, (col, row) in cross_cells().items():
        out[row * h:(row + 1) * h, col * w:(col + 1) * w] = faces[FACE_NAMES.index(name)][::-1]
    return out


def draw(ctx, lookups) -> "Path":
    """reference | your fetchColor, each an unfolded cross, faces named; written to record.png."""
    import OpenImageIO as oiio
    from ...envmap.imaging import write_image
    from ..arrows import _fonts
    scale, pad, top = 6, 16, 26
    pictures = [cross(lettered_faces()), cross(asked_faces(lookups))]
    h, w = pictures[0].shape[:2]
    canvas = np.ones((top + h * scale + pad, 2 * w * scale + 3 * pad, 3), np.float32)
    for k, picture in enumerate(pictures):
        left = pad + k * (w * scale + pad)
        canvas[top:top + h * scale, left:left + w * scale] = np.repeat(np.repeat(picture, scale, 0), scale, 1)
    page = oiio.ImageBuf(canvas)
    font = _fonts()[0]
    for k, title in enumerate((_("reference"), _("your fetchColor"))):
        left = pad + k * (w * scale + pad)
        oiio.ImageBufAlgo.render_text(page, left + w * scale // 2, 5, title, 15, font, (0.0, 0.0, 0.0), "center", "top")
        for name, (col, row) in cross_cells().items():
            oiio.ImageBufAlgo.render_text(page, left + col * SIZE * scale + 4, top + row * SIZE * scale + 4, name, 13,
                                          font, (0.0, 0.0, 0.0), "left", "top")
    path = ctx.artifact("record.png")
    write_image(path, page.get_pixels(oiio.FLOAT), display_referred=True)
    return path
