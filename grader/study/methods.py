"""The lookup methods the study compares.

A method binds to a cube map and gives back a batch lookup: a function from
directions (n, 3) float64 to colours (n, 3) float64. That is the whole
interface; a submission enters the study the same way (submission_method),
with an optional timer of its own when its calls cross a process boundary
(the isolated worker) and the time should be measured on the far side.

    nearest, bilinear, seamless   the reference C (grader.envmap.library), batch API
    numpy-bilinear                the handout's bilinear, vectorised numpy (peer)
    oiio-latlong                  OpenImageIO TextureSystem.environment on a
                                  lat-long conversion of the same map (peer)
    bicubic                       Catmull-Rom over texel centres across face
                                  edges, numpy: the expensive end of the curve
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ..envmap.geometry import direction_to_face_uv, face_plane_to_direction
from ..i18n import N_

Lookup = Callable[[np.ndarray], np.ndarray]
# Optional timer: (lookup, dirs, repeats) -> list of seconds per call of lookup(dirs).
Timer = Callable[[Lookup, np.ndarray, int], list]


@dataclass
class Method:
    name: str                           # the CSV's method column
    label: str                          # the chart legend
    bind: Callable[[np.ndarray], Lookup]  # faces (6, N, N, 3) -> lookup
    kind: str = "reference"             # reference | peer | extra | submission
    timer: Timer | None = None
    # Timing is per call of the batch lookup; slow methods time a subset.
    max_timing_batch: int | None = None


# ---- the reference C ---------------------------------------------------------

def reference_method(filter_name: str) -> Method:
    def bind(faces):
        from ..envmap.library import CubeMap
        cube = CubeMap(faces)
        return lambda dirs: cube.fetch(dirs, filter_name)
    # Marked: the chart shows a method's label in the student's language (grader/study/chart.py).
    labels = {"nearest": N_("nearest (handout start, C)"),
              "bilinear": N_("bilinear (handout, C)"),
              "seamless": N_("seamless bilinear (C)")}
    return Method(filter_name, labels[filter_name], bind)


# ---- numpy peers ---------------------------------------------------------------

def numpy_bilinear(faces: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """The handout's bilinear (p = (uW, vH), lattice clamped per face), vectorised."""
    size_y, size_x = faces.shape[1:3]
    face, u, v = direction_to_face_uv(dirs)
    bad = face < 0
    face = np.where(bad, 0, face)
    u = np.clip(u, 0, 1)
    v = np.clip(v, 0, 1)
    px, py = u * size_x, v * size_y
    fx, fy = np.floor(px), np.floor(py)
    alpha, beta = (px - fx)[:, None], (py - fy)[:, None]
    x0 = np.clip(fx.astype(np.intp), 0, size_x - 1)
    x1 = np.clip(fx.astype(np.intp) + 1, 0, size_x - 1)
    y0 = np.clip(fy.astype(np.intp), 0, size_y - 1)
    y1 = np.clip(fy.astype(np.intp) + 1, 0, size_y - 1)
    c0 = (1 - alpha) * faces[face, y0, x0] + alpha * faces[face, y0, x1]
    c1 = (1 - alpha) * faces[face, y1, x0] + alpha * faces[face, y1, x1]
    out = (1 - beta) * c0 + beta * c1
    out[bad] = 0
    return out


def _lattice_texels(faces: np.ndarray, face: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Colours of texel-centre lattice points (x, y) of `face`, where x, y may
    lie a few texels outside the face: such points are placed on the extended
    face plane, turned into directions and read from the face they fall on."""
    size = faces.shape[1]
    outside = (x < 0) | (x >= size) | (y < 0) | (y >= size)
    if outside.any():
        a = (x[outside] + 0.5) / size * 2 - 1
        b = (y[outside] + 0.5) / size * 2 - 1
        nf, nu, nv = direction_to_face_uv(face_plane_to_direction(face[outside], a, b))
        face, x, y = face.copy(), x.copy(), y.copy()
        face[outside] = nf
        x[outside] = np.clip((nu * size).astype(np.intp), 0, size - 1)
        y[outside] = np.clip((nv * size).astype(np.intp), 0, size - 1)
    return faces[face, y, x].astype(np.float64)


def _catmull_rom(t: np.ndarray) -> np.ndarray:
    """Weights (n, 4) of the lattice points at -1, 0, 1, 2 for fraction t."""
    t2, t3 = t * t, t * t * t
    return np.stack([(-t3 + 2 * t2 - t) / 2, (3 * t3 - 5 * t2 + 2) / 2,
                     (-3 * t3 + 4 * t2 + t) / 2, (t3 - t2) / 2], axis=1)


def numpy_bicubic(faces: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """Catmull-Rom over texel centres, reading across face edges."""
    size = faces.shape[1]
    face, u, v = direction_to_face_uv(dirs)
    bad = face < 0
    face = np.where(bad, 0, face)
    px, py = np.clip(u, 0, 1) * size - 0.5, np.clip(v, 0, 1) * size - 0.5
    fx, fy = np.floor(px), np.floor(py)
    wx, wy = _catmull_rom(px - fx), _catmull_rom(py - fy)
    x0, y0 = fx.astype(np.intp), fy.astype(np.intp)
    out = np.zeros((len(face), 3))
    for j in range(4):
        row = np.zeros((len(face), 3))
        for i in range(4):
            row += wx[:, i:i + 1] * _lattice_texels(faces, face, x0 + i - 1, y0 + j - 1)
        out += wy[:, j:j + 1] * row
    out[bad] = 0
    return out


def numpy_method() -> Method:
    return Method("numpy-bilinear", N_("bilinear (handout, numpy)"),
                  lambda faces: (lambda dirs: numpy_bilinear(faces, dirs)), kind="peer")


def bicubic_method() -> Method:
    return Method("bicubic", N_("bicubic Catmull-Rom, seamless (numpy)"),
                  lambda faces: (lambda dirs: numpy_bicubic(faces, dirs)), kind="extra")


# ---- OpenImageIO ---------------------------------------------------------------

def latlong_directions(height: int) -> np.ndarray:
    """Unit directions (height, 2*height, 3) at the pixels of a lat-long image
    as OpenImageIO reads it. Measured with a ramp image: s = 0.5 - atan2(x, z)
    / 2pi, t = acos(y) / pi (row 0 at +Y), and since make_texture marks
    lat-long maps "oiio:sampleborder" = 1, pixel (i, j) sits at
    s = i / (width - 1), t = j / (height - 1) (first and last columns on the
    same meridian, first and last rows on the poles), not at pixel centres."""
    width = 2 * height
    s, t = np.meshgrid(np.arange(width) / (width - 1), np.arange(height) / (height - 1))
    theta, phi = t * np.pi, (0.5 - s) * 2 * np.pi
    return np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), np.sin(theta) * np.cos(phi)], -1)


def oiio_method(work_dir: Path) -> Method:
    """OpenImageIO's environment() on a lat-long map 4N x 2N made from the cube
    map with the seamless reference lookup (so the conversion adds no seam).
    The Python binding has no batch call: the timing includes one Python call
    per lookup (run.py measures that overhead separately)."""
    def bind(faces):
        import OpenImageIO as oiio
        from ..envmap.library import CubeMap
        size = faces.shape[1]
        dirs = latlong_directions(2 * size)
        latlong = CubeMap(faces).fetch(dirs.reshape(-1, 3), "seamless")
        image = latlong.reshape(dirs.shape).astype(np.float32)
        work_dir.mkdir(parents=True, exist_ok=True)
        digest = hashlib.sha256(faces.tobytes()).hexdigest()[:16]
        path = str(work_dir / f"latlong-{size}-{digest}.exr")
        if not oiio.ImageBufAlgo.make_texture(oiio.MakeTxEnvLatl, oiio.ImageBuf(image), path):
            raise RuntimeError(f"OpenImageIO make_texture failed: {oiio.geterror()}")
        system = oiio.TextureSystem(False)
        options = oiio.TextureOpt()
        options.interpmode = oiio.InterpMode.Bilinear
        options.mipmode = oiio.MipMode.NoMIP   # the full-resolution level, as the cube lookups
        zero = (0.0, 0.0, 0.0)
        environment = system.environment

        def lookup(dirs):
            dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
            return np.array([environment(path, options, d, zero, zero, 3) for d in dirs.tolist()],
                            np.float64).reshape(-1, 3)
        return lookup
    return Method("oiio-latlong", N_("OpenImageIO environment, lat-long (Python per call)"),
                  bind, kind="peer", max_timing_batch=20000)


# ---- a submission ----------------------------------------------------------------

def submission_method(bind: Callable[[np.ndarray], Lookup], timer: Timer | None = None,
                      name: str = "submission", label: str | None = None) -> Method:
    """A student's fetchColor as a study method. `bind(faces)` returns the
    batch lookup (e.g. through grader/worker/); `timer`, when given, measures
    the time per batch call where the code runs (so IPC is not counted)."""
    return Method(name, label or name, bind, kind="submission", timer=timer)


def default_methods(work_dir: Path, include_oiio: bool = True, include_bicubic: bool = True) -> list[Method]:
    methods = [reference_method(f) for f in ("nearest", "bilinear", "seamless")]
    methods.append(numpy_method())
    if include_oiio:
        methods.append(oiio_method(work_dir))
    if include_bicubic:
        methods.append(bicubic_method())
    return methods
