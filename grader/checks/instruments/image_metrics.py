"""How alike two renders look: SSIM (Wang et al. 2004) and NVIDIA FLIP.

Both compare display images: linear renders are tone-mapped first with
grader.envmap.imaging.tone_map, so the metrics see what a person would.
"""
from __future__ import annotations

import numpy as np


def display(linear: np.ndarray) -> np.ndarray:
    from ...envmap.imaging import tone_map
    return np.clip(tone_map(np.nan_to_num(linear, nan=0.0, posinf=0.0, neginf=0.0)), 0.0, 1.0).astype(np.float32)


# Wang et al. 2004's settings, as the render check uses SSIM (docs/thresholds.md measured them).
SSIM_SIGMA = 1.5          # Gaussian window's standard deviation, pixels
SSIM_TRUNCATE = 3.5       # window radius in sigmas: int(3.5 * 1.5 + 0.5) = 5, an 11 x 11 window
SSIM_K1, SSIM_K2 = 0.01, 0.03
SSIM_DATA_RANGE = 1.0     # display values
WINDOW_RADIUS = int(SSIM_TRUNCATE * SSIM_SIGMA + 0.5)


def ssim(reference_display: np.ndarray, test_display: np.ndarray) -> float:
    """Mean SSIM with Wang et al.'s settings: 11x11 Gaussian window, sigma 1.5,
    population covariance, K1 = 0.01, K2 = 0.03, data range 1 (display values);
    each channel on its own, then their mean.

    Written here in numpy, where scikit-image's structural_similarity exists,
    so that the student kit (whose whole environment must stay under 100 MB)
    needs neither scikit-image nor scipy, and kit and grader judge with one
    function. It follows that function step for step (windows reflected at
    the border, a band of the window's radius left out of the mean, float32
    images filtered in float32 as scipy.ndimage does); tests/unit/checks/instruments/test_image_metrics.py
    holds it to scikit-image within 1e-6."""
    a, b = np.asarray(reference_display), np.asarray(test_display)
    if a.shape != b.shape or a.ndim != 3:
        raise ValueError(f"ssim: expected two (H, W, C) images of one shape, got {a.shape} and {b.shape}")
    dtype = np.float32 if a.dtype in (np.float16, np.float32) else np.float64
    a, b = a.astype(dtype, copy=False), b.astype(dtype, copy=False)
    if min(a.shape[:2]) < 2 * WINDOW_RADIUS + 1:
        raise ValueError(f"ssim: an image of {a.shape[1]} x {a.shape[0]} is smaller than the 11 x 11 window")
    x, y = np.moveaxis(a, 2, 0), np.moveaxis(b, 2, 0)          # (C, H, W): each channel on its own
    ux, uy, uxx, uyy, uxy = _blur(np.stack([x, y, x * x, y * y, x * y]))
    vx, vy, vxy = uxx - ux * ux, uyy - uy * uy, uxy - ux * uy
    c1, c2 = (SSIM_K1 * SSIM_DATA_RANGE) ** 2, (SSIM_K2 * SSIM_DATA_RANGE) ** 2
    s = ((2 * ux * uy + c1) * (2 * vxy + c2)) / ((ux * ux + uy * uy + c1) * (vx + vy + c2))
    r = WINDOW_RADIUS      # the band the window overhangs is left out of the mean
    per_channel = np.array([s[c, r:-r, r:-r].mean(dtype=np.float64) for c in range(len(s))], dtype)
    return float(per_channel.mean())


def _gaussian_window() -> np.ndarray:
    """The 1-D Gaussian taps (centre first, then distance 1, 2, ...), summing to 1."""
    x = np.arange(-WINDOW_RADIUS, WINDOW_RADIUS + 1)
    taps = np.exp(-0.5 / (SSIM_SIGMA * SSIM_SIGMA) * x ** 2)
    return (taps / taps.sum())[WINDOW_RADIUS:]


def _blur(images: np.ndarray) -> np.ndarray:
    """The Gaussian window over images (..., H, W), down then across, borders
    mirrored (a b c | c b a); sums in float64, each pass stored in the images' type."""
    taps = _gaussian_window()
    r = WINDOW_RADIUS
    for axis in (-2, -1):
        widths = [(0, 0)] * images.ndim
        widths[axis] = (r, r)
        line = np.moveaxis(np.pad(images.astype(np.float64), widths, mode="symmetric"), axis, 0)
        n = line.shape[0] - 2 * r
        total = line[r:r + n] * taps[0]
        pair = np.empty_like(total)
        for j in range(r, 0, -1):          # farthest first, pairs of mirror taps, as scipy.ndimage sums
            np.add(line[r - j:r - j + n], line[r + j:r + j + n], out=pair)
            pair *= taps[j]
            total += pair
        images = np.moveaxis(total, 0, axis).astype(images.dtype)
    return images


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
