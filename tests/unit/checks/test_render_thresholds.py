"""The renders check's thresholds hold on both sides (docs/thresholds.md).

The full measurement is bench/measure_render_thresholds.py; this keeps its
two ends in the suite: the correct solution that computes in float, built
with -O3 -ffast-math (and -O0), passes every render, and one wrong
submission of each kind (a mistake on one face, in readTexture, in the
normalisation) fails at least one.
"""
from __future__ import annotations

import types
from pathlib import Path

import pytest

from grader.grading import fixtures
from grader.build import build_submission
from grader.checks.instruments.image_metrics import display, flip, ssim
from grader.checks.renders import FLIP_MAX, SSIM_MIN, render_with_submission
from grader.worker.lookups import open_lookups
from project_paths import SUBMISSIONS



@pytest.fixture(scope="module")
def expected_displays():
    return {f.name: display(f.load()) for f in fixtures.render_fixtures()}


def render_scores(source: Path, expected_displays, extra_flags=()) -> dict[str, tuple[float, float]]:
    """{fixture: (SSIM, mean FLIP)} of every render with the submission's lookup."""
    built = build_submission(source, extra_flags=extra_flags)
    assert built.ok, built.log
    scores = {}
    with open_lookups(built.library) as lookups:
        ctx = types.SimpleNamespace(lookups=lookups, first_faces=False)
        for fixture in fixtures.render_fixtures():
            image, _ = render_with_submission(ctx, fixture)
            expected, got = expected_displays[fixture.name], display(image)
            scores[fixture.name] = (ssim(expected, got), flip(expected, got)[0])
    return scores


def passes(score: tuple[float, float]) -> bool:
    s, f = score
    return s >= SSIM_MIN and f <= FLIP_MAX


@pytest.mark.parametrize("flags", [("-O3", "-ffast-math"), ("-O0",)], ids=" ".join)
def test_float_solution_passes_every_render(flags, expected_displays):
    scores = render_scores(SUBMISSIONS / "correct" / "float_math.cpp", expected_displays, flags)
    assert len(scores) == len(fixtures.render_fixtures()) >= 7
    failing = {name: score for name, score in scores.items() if not passes(score)}
    assert not failing, f"a correct solution fails renders (SSIM, FLIP): {failing}"


@pytest.mark.parametrize("name", [
    "v-flipped-pos-z",          # one face: the least visible mistake of the zoo in the renders
    "half-texel-offset",        # readTexture
    "not-normalized-length",    # normalisation
])
def test_wrong_submission_fails_a_render(name, expected_displays):
    scores = render_scores(SUBMISSIONS / "wrong" / f"{name}.cpp", expected_displays)
    assert not all(passes(score) for score in scores.values()), f"{name} passes every render: {scores}"
