"""score_render's shortcut for identical images (a correct lookup's render
equals the reference's bit for bit) gives what the full computation gives:
SSIM exactly 1, FLIP exactly 0, full marks; and the check still pictures a
FLIP map for the render it shows."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fake_lookups import FakeLookups
from grader.checks import renders
from grader.checks.context import CheckContext
from grader.checks.instruments.image_metrics import display, flip, ssim
from grader.grading import fixtures
from grader.grading.results import CheckResult


def images() -> list[np.ndarray]:
    rng = np.random.default_rng(5)
    expected = renders._expected(renders.stamp(fixtures.render_fixtures()[0].path)).copy()
    return [expected, rng.random((48, 64, 3)).astype(np.float32),
            np.zeros((40, 40, 3), np.float32), np.ones((40, 40, 3), np.float32)]


@pytest.mark.parametrize("k", range(4))
def test_identical_images_score_as_the_full_computation_scores_them(k):
    image = images()[k]
    scored = renders.score_render(image, image.copy())
    full_mean, _ = flip(image, image.copy())
    assert (scored.ssim, scored.flip_mean) == (ssim(image, image.copy()), full_mean) == (1.0, 0.0)
    assert scored.passed and scored.matched == 1.0 and scored.score == 1.0


def test_an_image_one_value_off_takes_the_full_computation():
    image = images()[1]
    other = image.copy()
    other[3, 4, 1] = np.nextafter(other[3, 4, 1], np.float32(2))
    scored = renders.score_render(image, other)
    assert scored.flip_map is not None
    assert scored.ssim == ssim(image, other) and scored.flip_mean == flip(image, other)[0]


def test_a_correct_lookup_s_renders_are_pictured_with_their_flip_map(tmp_path: Path):
    result = CheckResult("renders", "renders")
    ctx = CheckContext(lookups=FakeLookups(), seed=1, artifacts=tmp_path, quick=True)
    renders.renders(ctx, result)
    assert result.fraction == 1.0
    assert result.artifacts["render_flip"].is_file()
    assert result.metrics["ssim"] == 1.0 and result.metrics["flip_mean"] == 0.0
