"""SSIM in numpy (grader/checks/instruments/image_metrics.py, so the student
kit needs no scikit-image) agrees with scikit-image's structural_similarity
called as the render check called it before, on the fixture renders and on
random images. scikit-image stays in the grader's development environment
for this test."""
from __future__ import annotations

import numpy as np
import pytest
from skimage.metrics import structural_similarity

from grader.grading import fixtures
from grader.checks.instruments.image_metrics import display, ssim

AGREE = 1e-6


def scikit_ssim(a, b) -> float:
    return float(structural_similarity(a, b, data_range=1.0, channel_axis=2, gaussian_weights=True, sigma=1.5,
                                       use_sample_covariance=False, K1=0.01, K2=0.03))


def renders() -> list[np.ndarray]:
    paths = sorted((fixtures.FIXTURES / "renders").glob("*.npy"))
    assert len(paths) >= 2
    return [display(np.load(p)) for p in paths]


def test_ssim_agrees_with_scikit_image_on_the_renders():
    rng = np.random.default_rng(20261202)
    images = renders()
    compared = []
    for i, image in enumerate(images):
        others = [np.clip(image + rng.normal(0, 0.002, image.shape), 0, 1).astype(np.float32),   # near the threshold
                  np.roll(image, 1, axis=1), images[(i + 1) % len(images)], np.zeros_like(image), image]
        for other in others:
            if other.shape == image.shape:
                ours, theirs = ssim(image, other), scikit_ssim(image, other)
                assert abs(ours - theirs) <= AGREE, (i, ours, theirs)
                compared.append(ours)
    assert min(compared) < 0.9 and max(compared) == 1.0 and any(0.999 < c < 1.0 for c in compared)


@pytest.mark.parametrize("shape", [(11, 11, 3), (37, 64, 3), (200, 13, 1)])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_ssim_agrees_with_scikit_image_on_random_images(shape, dtype):
    rng = np.random.default_rng(sum(shape))
    a = rng.random(shape).astype(dtype)
    for b in (np.clip(a + rng.normal(0, 0.05, shape), 0, 1), rng.random(shape), a[::-1].copy()):
        b = b.astype(dtype)
        assert abs(ssim(a, b) - scikit_ssim(a, b)) <= AGREE


def test_ssim_refuses_what_it_cannot_compare():
    with pytest.raises(ValueError):
        ssim(np.zeros((10, 40, 3), np.float32), np.zeros((10, 40, 3), np.float32))    # under the 11 x 11 window
    with pytest.raises(ValueError):
        ssim(np.zeros((20, 20, 3)), np.zeros((20, 21, 3)))
