"""Textures the checks hand to a submission, set from memory (no .hdr, so no
8-bit RGBE rounding).

The coordinate-encoding texture stores where each texel is: R = x + 1,
G = y + 1, B = face + 1, all exact in float32 for faces up to 2^24 texels
wide. Bilinear interpolation reproduces linear ramps exactly, so whatever a
submission returns from it says which face it sampled and where
(`decode_sample_coordinates`); 0 means it sampled nothing.
"""
from __future__ import annotations

import numpy as np


def coordinate_faces(width: int, height: int) -> np.ndarray:
    """(6, H, W, 3) float32 with R = x + 1, G = y + 1, B = face + 1."""
    faces = np.empty((6, height, width, 3), np.float32)
    faces[..., 0] = np.arange(width, dtype=np.float32)[None, None, :] + 1
    faces[..., 1] = np.arange(height, dtype=np.float32)[None, :, None] + 1
    faces[..., 2] = np.arange(6, dtype=np.float32)[:, None, None] + 1
    return faces


def random_faces(width: int, height: int, seed: int) -> np.ndarray:
    """(6, H, W, 3) float32, independent uniform [0, 1) texels."""
    return np.random.default_rng(seed).random((6, height, width, 3), dtype=np.float32)


def decode_sample_coordinates(rgb: np.ndarray):
    """From colours looked up in a coordinate-encoding texture: the face sampled
    (int, -1 where the colour is not one of ours) and the lattice position
    (px, py) in texel units (p = (u W, v H) in the handout's notation, after
    the clamp to [0, W-1])."""
    rgb = np.asarray(rgb, np.float64)
    face = np.rint(rgb[:, 2]) - 1
    valid = np.isfinite(rgb).all(axis=1) & (np.abs(rgb[:, 2] - (face + 1)) < 1e-3) & (face >= 0) & (face <= 5)
    face = np.where(valid, face, -1).astype(np.int64)
    return face, rgb[:, 0] - 1.0, rgb[:, 1] - 1.0
