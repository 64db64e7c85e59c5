"""How alike two renders look: SSIM (Wang et al. 2004) and NVIDIA FLIP.

Both compare display images: linear renders are tone-mapped first with
grader.imaging.tone_map, so the metrics see what a person would.
"""
from __future__ import annotations

import numpy as np


def display(linear: np.ndarray) -> np.ndarray:
    from ...imaging import tone_map
    return np.clip(tone_map(np.nan_to_num(linear, nan=0.0, posinf=0.0, neginf=0.0)), 0.0, 1.0).astype(np.float32)


# Wang et al. 2004's settings, as the render check uses SSIM (docs/thresholds.md measured them).
SSIM_SIGMA = 1.5          # Gaussian window's standard deviation, pixels
SSIM_TRUNCATE = 3.5       # window radius in sigmas: int(3.5 * 1.5 + 0.5) = 5, an 11 x 11 window
SSIM_K1, SSIM_K2 = 0.01, 0.03
SSIM_DATA_RANGE = 1.0     # display values


def ssim(reference_display: np.ndarray, test_display: np.ndarray) -> float:
    """Mean SSIM with Wang et al.'s settings: 11x11 Gaussian window, sigma 1.5,
    population covariance, K1 = 0.01, K2 = 0.03, data range 1 (display values);
    each channel on its own, then their mean.

    Written here in numpy, where scikit-image's structural_similarity exists,
    so that the student kit (whose whole environment must stay under 100 MB)
    needs neither scikit-image nor scipy, and kit and grader judge with one
    function. It follows that function step for step (windows reflected at
    the border, a band of the window's radius left out of the mean, float32
    images filtered in float32 as scipy.ndimage does); tests/test_image_metrics.py
    holds it to scikit-image within 1e-6."""
    a, b = np.asarray(reference_display), np.asarray(test_display)
    if a.shape != b.shape or a.ndim != 3:
        raise ValueError(f"ssim: expected two (H, W, C) images of one shape, got {a.shape} and {b.shape}")
    dtype = np.float32 if a.dtype in (np.float16, np.float32) else np.float64
    a, b = a.astype(dtype, copy=False), b.astype(dtype, copy=False)
    per_channel = np.array([_ssim_channel(a[..., c], b[..., c]) for c in range(a.shape[2])], dtype)
    return float(per_channel.mean())


def _gaussian_window() -> np.ndarray:
    """The 1-D Gaussian taps (centre first, then distance 1, 2, ...), summing to 1."""
    radius = int(SSIM_TRUNCATE * SSIM_SIGMA + 0.5)
    x = np.arange(-radius, radius + 1)
    taps = np.exp(-0.5 / (SSIM_SIGMA * SSIM_SIGMA) * x ** 2)
    return (taps / taps.sum())[radius:]


def _blur(image: np.ndarray) -> np.ndarray:
    """The Gaussian window over a 2-D image, one axis then the other, borders
    mirrored (a b c | c b a); sums in float64, each pass stored in the image's type."""
    taps = _gaussian_window()
    radius = len(taps) - 1
    for axis in (0, 1):
        line = np.moveaxis(np.pad(image.astype(np.float64), [(radius, radius) if k == axis else (0, 0) for k in (0, 1)],
                                  mode="symmetric"), axis, 0)
        n = line.shape[0] - 2 * radius
        total = line[radius:radius + n] * taps[0]
        for j in range(radius, 0, -1):          # farthest first, pairs of mirror taps
            total += (line[radius - j:radius - j + n] + line[radius + j:radius + j + n]) * taps[j]
        image = np.moveaxis(total, 0, axis).astype(image.dtype)
    return image


def _ssim_channel(x: np.ndarray, y: np.ndarray) -> float:
    if min(x.shape) < 2 * int(SSIM_TRUNCATE * SSIM_SIGMA + 0.5) + 1:
        raise ValueError(f"ssim: an image of {x.shape[1]} x {x.shape[0]} is smaller than the 11 x 11 window")
    ux, uy = _blur(x), _blur(y)
    vx = _blur(x * x) - ux * ux
    vy = _blur(y * y) - uy * uy
    vxy = _blur(x * y) - ux * uy
    c1, c2 = (SSIM_K1 * SSIM_DATA_RANGE) ** 2, (SSIM_K2 * SSIM_DATA_RANGE) ** 2
    s = ((2 * ux * uy + c1) * (2 * vxy + c2)) / ((ux * ux + uy * uy + c1) * (vx + vy + c2))
    pad = int(SSIM_TRUNCATE * SSIM_SIGMA + 0.5)
    return float(s[pad:-pad, pad:-pad].mean(dtype=np.float64))


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
