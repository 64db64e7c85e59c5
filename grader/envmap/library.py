"""The reference library (reference/, C) seen from Python through cffi.

Numpy arrays in and out; C errors become EnvmapError with the C message.
Cube maps are numpy arrays of shape (6, H, W, 3), float32, indexed
[face, y, x, channel] with y = 0 the bottom row (docs/assignment.md, "Buffer"):
exactly the memory layout the C library and students' code use.
"""
from __future__ import annotations

import os
import re
import subprocess
import threading
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from cffi import FFI, CDefError

from .. import PROJECT_ROOT

HEADER = PROJECT_ROOT / "reference" / "include" / "envmap.h"
LIBRARY = Path(os.environ.get("ENVMAP_LIBRARY", PROJECT_ROOT / "build" / "libenvmap.so"))



class EnvmapError(Exception):
    """An error reported by the reference library; .code is its em_status."""

    def __init__(self, code: int, message: str):
        super().__init__(message)
        self.code = code


def _cdef_source(header: Path) -> str:
    """The header as cffi's cdef accepts it: no preprocessor lines, no C++ guards."""
    text = header.read_text()
    text = re.sub(r"#ifdef __cplusplus.*?#endif", "", text, flags=re.S)
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    return "\n".join(line for line in text.splitlines() if not line.lstrip().startswith("#"))


def _declarations() -> FFI:
    """envmap.h parsed by cffi (no library needed): the enums below come from it."""
    ffi = FFI()
    ffi.cdef(_cdef_source(HEADER))
    return ffi


def _enum(ffi: FFI, ctype: str, prefix: str) -> dict[str, int]:
    """An enum's non-negative members by their C name without `prefix`, in value order."""
    members = ffi.typeof(ctype).relements
    return {name[len(prefix):]: value for name, value in sorted(members.items(), key=lambda kv: kv[1])
            if name.startswith(prefix) and value >= 0}


def _declares(ffi: FFI, ctype: str) -> bool:
    try:
        ffi.typeof(ctype)
        return True
    except CDefError:
        return False


_ffi_decl = _declarations()
# "nearest" -> EM_FILTER_NEAREST, ...: the header's enum, not a copy of it.
# The student kit's envmap.h declares no lookup (grader/kit/build.py cuts it
# out), so there the filters are none and only the renderer's side is here.
FILTERS = ({name.lower(): value for name, value in _enum(_ffi_decl, "em_filter", "EM_FILTER_").items()}
           if _declares(_ffi_decl, "em_filter") else {})
# +X -X +Y -Y +Z -Z, in em_face order (EM_FACE_POS_X = 0, ...).
FACE_NAMES = tuple(("+" if name.startswith("POS") else "-") + name[-1]
                   for name in _enum(_ffi_decl, "em_face", "EM_FACE_"))

_lock = threading.Lock()
# One make at a time in a process: a PrairieLearn job builds ahead in a thread
# (platforms/prairielearn: _build_ahead) while the grading may ask too.
_build_lock = threading.Lock()
_ffi: FFI | None = None
_lib = None


def ensure_built() -> Path:
    """Build the library with make when it is missing or older than its sources."""
    sources = list((PROJECT_ROOT / "reference").glob("src/*.[ch]")) + [HEADER]
    if "ENVMAP_LIBRARY" in os.environ:
        return LIBRARY
    with _build_lock:
        if not LIBRARY.exists() or max(p.stat().st_mtime for p in sources) > LIBRARY.stat().st_mtime:
            # Its two libraries built side by side: a cold PrairieLearn job builds them on every grading.
            subprocess.run(["make", "-s", f"-j{os.cpu_count() or 1}", "-C", str(PROJECT_ROOT), "reference"],
                           check=True)
    return LIBRARY


def library():
    """(ffi, lib), loaded once per process."""
    global _ffi, _lib
    with _lock:
        if _lib is None:
            _lib = _ffi_decl.dlopen(str(ensure_built()))
            _ffi = _ffi_decl
    return _ffi, _lib


def _check(status: int, err) -> None:
    if status != 0:
        ffi, _ = library()
        raise EnvmapError(status, ffi.string(err.message).decode("utf-8", "replace"))


def _new_error():
    ffi, _ = library()
    return ffi.new("em_error *")


def _ptr(ffi, ctype: str, array: np.ndarray):
    return ffi.cast(ctype, ffi.from_buffer(array))


# ---- images ---------------------------------------------------------------

def _take_image(img) -> np.ndarray:
    """Copy an em_image into numpy (H, W, 3) float32 and free it."""
    ffi, lib = library()
    try:
        n = img.width * img.height * 3
        out = np.frombuffer(ffi.buffer(img.rgb, n * 4), dtype=np.float32).copy()
        return out.reshape(img.height, img.width, 3)
    finally:
        lib.em_image_free(img)


def read_hdr(path: str | os.PathLike) -> np.ndarray:
    """Decode a Radiance .hdr file into (H, W, 3) float32, top row first."""
    ffi, lib = library()
    img, err = ffi.new("em_image *"), _new_error()
    _check(lib.em_rgbe_read(os.fsencode(path), img, err), err)
    return _take_image(img)


def read_hdr_bytes(data: bytes, name: str = "<memory>") -> np.ndarray:
    ffi, lib = library()
    img, err = ffi.new("em_image *"), _new_error()
    _check(lib.em_rgbe_read_memory(data, len(data), name.encode(), img, err), err)
    return _take_image(img)


def _as_em_image(image: np.ndarray):
    ffi, _ = library()
    image = np.ascontiguousarray(image, dtype=np.float32)
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"expected an (H, W, 3) image, got shape {image.shape}")
    img = ffi.new("em_image *")
    img.height, img.width = image.shape[:2]
    img.rgb = _ptr(ffi, "float *", image)
    return img, image


def write_hdr(path: str | os.PathLike, image: np.ndarray) -> None:
    """Write (H, W, 3) linear RGB as new-style RLE RGBE."""
    _, lib = library()
    img, keep = _as_em_image(image)
    err = _new_error()
    _check(lib.em_rgbe_write(os.fsencode(path), img, err), err)
    del keep


# ---- cube maps --------------------------------------------------------------

def cross_to_faces(cross: np.ndarray) -> np.ndarray:
    """Cut a vertical cross (H, W, 3) into faces (6, H/4, W/3, 3)."""
    ffi, lib = library()
    img, keep = _as_em_image(cross)
    cube, err = ffi.new("em_cubemap *"), _new_error()
    _check(lib.em_cubemap_from_cross(img, cube, err), err)
    try:
        return _faces_copy(cube)
    finally:
        lib.em_cubemap_free(cube)


def faces_to_cross(faces: np.ndarray) -> np.ndarray:
    """The inverse of cross_to_faces; unused cells are 0."""
    ffi, lib = library()
    cube = CubeMap(faces)
    img, err = ffi.new("em_image *"), _new_error()
    _check(lib.em_cubemap_to_cross(cube.c, img, err), err)
    return _take_image(img)


def _faces_copy(cube) -> np.ndarray:
    ffi, _ = library()
    w, h = cube.face_width, cube.face_height
    data = np.frombuffer(ffi.buffer(cube.texels, 6 * w * h * 3 * 4), dtype=np.float32)
    return data.copy().reshape(6, h, w, 3)


class CubeMap:
    """Six faces (6, H, W, 3) float32 and the reference lookups over them."""

    def __init__(self, faces: np.ndarray):
        ffi, _ = library()
        faces = np.ascontiguousarray(faces, dtype=np.float32)
        if faces.ndim != 4 or faces.shape[0] != 6 or faces.shape[3] != 3:
            raise ValueError(f"expected faces of shape (6, H, W, 3), got {faces.shape}")
        self.faces = faces
        self.c = ffi.new("em_cubemap *")
        self.c.face_height, self.c.face_width = faces.shape[1:3]
        self.c.texels = _ptr(ffi, "float *", faces)

    @classmethod
    def load_cross(cls, path: str | os.PathLike) -> "CubeMap":
        return cls(cross_to_faces(read_hdr(path)))

    @property
    def face_width(self) -> int:
        return self.faces.shape[2]

    @property
    def face_height(self) -> int:
        return self.faces.shape[1]

    def fetch(self, dirs: np.ndarray, filter: str = "bilinear") -> np.ndarray:
        """Colours (n, 3) float64 for directions (n, 3)."""
        return self.fetch_with_faces(dirs, filter)[0]

    def fetch_with_faces(self, dirs: np.ndarray, filter: str = "bilinear"):
        ffi, lib = library()
        dirs = np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1, 3)
        n = len(dirs)
        rgb = np.empty((n, 3), np.float64)
        faces = np.empty(n, np.int32)
        lib.em_fetch_batch(self.c, FILTERS[filter], _ptr(ffi, "double *", dirs), n,
                           _ptr(ffi, "double *", rgb), _ptr(ffi, "int *", faces))
        return rgb, faces

    def read_texture(self, faces: np.ndarray, uv: np.ndarray, filter: str = "bilinear") -> np.ndarray:
        """Colours (n, 3) float64 at (u, v) (n, 2) on faces (n,)."""
        ffi, lib = library()
        uv = np.ascontiguousarray(uv, dtype=np.float64).reshape(-1, 2)
        faces = np.ascontiguousarray(np.broadcast_to(faces, (len(uv),)), dtype=np.int32)
        rgb = np.empty((len(uv), 3), np.float64)
        lib.em_read_texture_batch(self.c, FILTERS[filter], _ptr(ffi, "int *", faces),
                                  _ptr(ffi, "double *", uv), len(uv), _ptr(ffi, "double *", rgb))
        return rgb


def direction_to_face(dirs: np.ndarray):
    """(faces (n,) int32, uv (n, 2) float64) for directions (n, 3)."""
    ffi, lib = library()
    dirs = np.ascontiguousarray(dirs, dtype=np.float64).reshape(-1, 3)
    faces = np.empty(len(dirs), np.int32)
    uv = np.empty((len(dirs), 2), np.float64)
    lib.em_direction_to_face_batch(_ptr(ffi, "double *", dirs), len(dirs),
                                   _ptr(ffi, "int *", faces), _ptr(ffi, "double *", uv))
    return faces, uv


# ---- scenes and rendering -----------------------------------------------------

@dataclass
class Escapes:
    """Where the camera paths of a render leave the scene (em_escapes)."""
    dirs: np.ndarray      # (n, 3) float64
    weights: np.ndarray   # (n, 3) float64, throughput / spp
    pixels: np.ndarray    # (n,) uint32, y*width + x, y = 0 the top row
    width: int
    height: int
    hdr_gamma: float

    def resolve(self, rgb: np.ndarray) -> np.ndarray:
        """The image (H, W, 3) float32 for environment colours rgb (n, 3) (em_resolve)."""
        ffi, lib = library()
        rgb = np.ascontiguousarray(rgb, dtype=np.float64).reshape(-1, 3)
        if len(rgb) != len(self.dirs):
            raise ValueError(f"expected {len(self.dirs)} colours, got {len(rgb)}")
        esc = ffi.new("em_escapes *")
        esc.count, esc.width, esc.height, esc.hdr_gamma = len(self.dirs), self.width, self.height, self.hdr_gamma
        esc.dirs = _ptr(ffi, "double *", self.dirs)
        esc.weights = _ptr(ffi, "double *", self.weights)
        esc.pixels = _ptr(ffi, "uint32_t *", self.pixels)
        img, err = ffi.new("em_image *"), _new_error()
        _check(lib.em_resolve(esc, _ptr(ffi, "double *", rgb), img, err), err)
        return _take_image(img)


class Scene:
    """A parsed scene file (the handout's .cfg syntax)."""

    def __init__(self, c_scene):
        _, lib = library()
        self.c = c_scene
        self._free = lib.em_scene_free

    def __del__(self):
        if getattr(self, "c", None) is not None:
            self._free(self.c)
            self.c = None

    @classmethod
    def load(cls, path: str | os.PathLike) -> "Scene":
        ffi, lib = library()
        out, err = ffi.new("em_scene **"), _new_error()
        _check(lib.em_scene_load(os.fsencode(path), out, err), err)
        return cls(out[0])

    @classmethod
    def parse(cls, text: str, name: str = "<string>", base_dir: str | os.PathLike = ".") -> "Scene":
        ffi, lib = library()
        data = text.encode()
        out, err = ffi.new("em_scene **"), _new_error()
        _check(lib.em_scene_parse(data, len(data), name.encode(), os.fsencode(base_dir), out, err), err)
        return cls(out[0])

    @property
    def width(self) -> int:
        return library()[1].em_scene_width(self.c)

    @property
    def height(self) -> int:
        return library()[1].em_scene_height(self.c)

    @property
    def environment_path(self) -> Path:
        ffi, lib = library()
        return Path(os.fsdecode(ffi.string(lib.em_scene_environment_path(self.c))))

    @property
    def hdr_gamma(self) -> float:
        return library()[1].em_scene_hdr_gamma(self.c)

    def set_resolution(self, width: int, height: int) -> None:
        library()[1].em_scene_set_resolution(self.c, width, height)

    def set_samples(self, samples_per_pixel: int) -> None:
        library()[1].em_scene_set_samples(self.c, samples_per_pixel)

    def trace(self) -> Escapes:
        ffi, lib = library()
        esc, err = ffi.new("em_escapes *"), _new_error()
        _check(lib.em_trace(self.c, esc, err), err)
        try:
            n = esc.count

            def arr(ptr, count, dtype):
                if count == 0:
                    return np.empty(0, dtype)
                return np.frombuffer(ffi.buffer(ptr, count * np.dtype(dtype).itemsize), dtype=dtype).copy()

            return Escapes(arr(esc.dirs, n * 3, np.float64).reshape(-1, 3),
                           arr(esc.weights, n * 3, np.float64).reshape(-1, 3),
                           arr(esc.pixels, n, np.uint32), esc.width, esc.height, esc.hdr_gamma)
        finally:
            lib.em_escapes_free(esc)

    def render(self, cube: CubeMap, filter: str = "bilinear") -> np.ndarray:
        """Render with the reference lookup, entirely in C: (H, W, 3) float32."""
        ffi, lib = library()
        ctx = ffi.new("em_cubemap_lookup *")
        ctx.cube = cube.c
        ctx.filter = FILTERS[filter]
        img, err = ffi.new("em_image *"), _new_error()
        _check(lib.em_render(self.c, lib.em_cubemap_lookup_fn, ctx, img, err), err)
        return _take_image(img)
