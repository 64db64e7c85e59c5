"""Images on disk and on screen: reading and writing (OpenImageIO), and the one
tone-mapping operator every picture the grader shows goes through.

Images are numpy arrays (H, W, 3) float32, top row first (docs/ARCHITECTURE.md).
Renders are linear radiance; PNGs are display-referred 8-bit sRGB.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import OpenImageIO as oiio

# Files whose pixels are linear floats; anything else is written as 8-bit sRGB.
LINEAR_SUFFIXES = (".exr", ".hdr")
DISPLAY_SUFFIXES = (".png",)


def srgb_oetf(linear: np.ndarray) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1) on values in [0, 1]:
    12.92 x for x <= 0.0031308, else 1.055 x^(1/2.4) - 0.055."""
    x = np.asarray(linear, dtype=np.float32)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(np.maximum(x, 0.0031308), 1 / 2.4) - 0.055)


def tone_map(linear: np.ndarray, exposure: float = 0.0) -> np.ndarray:
    """Display-referred [0, 1] float32 from linear RGB, per channel:

        x = max(linear, 0) * 2**exposure
        display = srgb_oetf(x / (1 + x))          (Reinhard 2002, eq. 3)

    Reinhard's curve rather than a clamp because the maps are real HDR (the
    probes reach 2800, the generated sky's ground is about 2): a clamp turns
    everything above 1 white, and a grader comparing display images would
    not see mistakes there. NaN becomes 0, +inf becomes 1."""
    x = np.nan_to_num(np.asarray(linear, dtype=np.float32), nan=0.0, posinf=np.inf, neginf=0.0)
    x = np.maximum(x, 0.0) * np.float32(2.0 ** exposure)
    with np.errstate(invalid="ignore"):          # inf / inf, replaced by 1
        compressed = np.where(np.isinf(x), 1.0, x / (1.0 + x))
    return srgb_oetf(compressed).astype(np.float32)


def to_8bit(display: np.ndarray) -> np.ndarray:
    """Display values in [0, 1] to uint8, rounding to the nearest level."""
    return np.round(np.clip(display, 0.0, 1.0) * 255.0).astype(np.uint8)


def _as_rgb(image: np.ndarray) -> np.ndarray:
    image = np.asarray(image, dtype=np.float32)
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"expected an (H, W, 3) image, got shape {image.shape}")
    return np.ascontiguousarray(image)


def write_image(path: str | os.PathLike, image: np.ndarray, *, exposure: float = 0.0,
                display_referred: bool = False) -> None:
    """Write (H, W, 3) pixels to .exr or .hdr (linear float, as they are) or
    .png (8-bit sRGB through tone_map). `display_referred=True` says the
    pixels are already display values in [0, 1] (a difference picture, a FLIP
    map): a PNG then stores them without tone mapping."""
    path = Path(path)
    suffix = path.suffix.lower()
    pixels = _as_rgb(image)
    if suffix in LINEAR_SUFFIXES:
        data, pixel_type = pixels, oiio.FLOAT
    elif suffix in DISPLAY_SUFFIXES:
        display = pixels if display_referred else tone_map(pixels, exposure)
        data, pixel_type = to_8bit(display), oiio.UINT8
    else:
        raise ValueError(f"{path}: unsupported image type {suffix!r} (use .exr, .hdr or .png)")
    height, width = pixels.shape[:2]
    out = oiio.ImageOutput.create(str(path))
    if out is None:
        raise OSError(f"{path}: {oiio.geterror()}")
    spec = oiio.ImageSpec(width, height, 3, pixel_type)
    if suffix in DISPLAY_SUFFIXES:
        spec.attribute("oiio:ColorSpace", "sRGB")
    try:
        if not out.open(str(path), spec) or not out.write_image(data):
            raise OSError(f"{path}: {out.geterror()}")
    finally:
        out.close()


def read_image(path: str | os.PathLike) -> np.ndarray:
    """Any image OpenImageIO reads, as (H, W, 3) float32: the first three
    channels (grey repeated), 8-bit files scaled to [0, 1] and not linearised."""
    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise OSError(f"{path}: {oiio.geterror()}")
    try:
        pixels = inp.read_image(oiio.FLOAT)
        if pixels is None:
            raise OSError(f"{path}: {inp.geterror()}")
    finally:
        inp.close()
    pixels = np.asarray(pixels, dtype=np.float32)
    if pixels.ndim == 2:
        pixels = pixels[:, :, None]
    if pixels.shape[2] < 3:
        pixels = np.repeat(pixels[:, :, :1], 3, axis=2)
    return np.ascontiguousarray(pixels[:, :, :3])
