"""How alike two renders look: SSIM (Wang et al. 2004) and NVIDIA FLIP.

Both compare display images: linear renders are tone-mapped first with
grader.imaging.tone_map, so the metrics see what a person would.
"""
from __future__ import annotations

import numpy as np


def display(linear: np.ndarray) -> np.ndarray:
    from ...imaging import tone_map
    return np.clip(tone_map(np.nan_to_num(linear, nan=0.0, posinf=0.0, neginf=0.0)), 0.0, 1.0).astype(np.float32)


def ssim(reference_display: np.ndarray, test_display: np.ndarray) -> float:
    """Mean SSIM with Wang et al.'s settings: 11x11 Gaussian window, sigma 1.5,
    population covariance, K1 = 0.01, K2 = 0.03, data range 1 (display values)."""
    from skimage.metrics import structural_similarity
    return float(structural_similarity(
        reference_display, test_display, data_range=1.0, channel_axis=2,
        gaussian_weights=True, sigma=1.5, use_sample_covariance=False, K1=0.01, K2=0.03))


def flip(reference_display: np.ndarray, test_display: np.ndarray):
    """(mean FLIP error, error map (H, W, 3) magma-coloured) on sRGB display images."""
    import flip_evaluator
    error_map, mean, _ = flip_evaluator.evaluate(
        np.ascontiguousarray(reference_display), np.ascontiguousarray(test_display), "LDR", applyMagma=True)
    return float(mean), np.asarray(error_map, np.float32)


def flip_pixels(reference_display: np.ndarray, test_display: np.ndarray) -> np.ndarray:
    """Per-pixel FLIP error (H, W), 0 = indistinguishable, 1 = the largest
    difference FLIP knows; on sRGB display images, LDR mode."""
    import flip_evaluator
    error_map, _, _ = flip_evaluator.evaluate(
        np.ascontiguousarray(reference_display), np.ascontiguousarray(test_display), "LDR", applyMagma=False)
    return np.asarray(error_map, np.float32).reshape(reference_display.shape[:2])


def difference_picture(reference_display: np.ndarray, test_display: np.ndarray) -> np.ndarray:
    """|reference - test| per pixel, amplified 4x so small errors show."""
    return np.clip(4.0 * np.abs(reference_display - test_display), 0.0, 1.0)
