"""A render that fails the whole-image rule (SSIM_MIN, FLIP_MAX) earns the
share of its pixels that match (per-pixel FLIP <= PIXEL_FLIP_MAX): a correct
render scores 1, a black one about 0, and one with a single wrong face about
the share of pixels that face does not reach.

The reached pixels are found independently of FLIP: the scene rendered with
a map whose face is white and whose other faces are black is black exactly
where no light comes from that face. The map of random texels makes a wrong
face change every pixel it reaches. Fakes in-process (tests/helpers/fake_lookups.py).
"""
from __future__ import annotations

import numpy as np
import pytest

from fake_lookups import FACES, FakeLookups
from grader.grading import fixtures
from grader.envmap import library
from grader.checks.instruments.image_metrics import display
from grader.checks.renders import PIXEL_FLIP_MAX, score_render


@pytest.fixture(scope="module")
def scene():
    """The main scene (the one quick grading renders) and a map of random texels."""
    fixture = fixtures.render_fixtures()[0]
    escapes = fixtures.prepared_scene(fixture).trace()
    texels = np.random.default_rng(3).uniform(0.0, 2.0, (6, 32, 32, 3)).astype(np.float32)
    expected = display(escapes.resolve(library.CubeMap(texels).fetch(escapes.dirs, "bilinear")))
    return escapes, texels, expected


def render(lookups, escapes, texels) -> np.ndarray:
    lookups.set_faces(texels)
    values = np.nan_to_num(lookups.fetch(escapes.dirs).values)
    return display(escapes.resolve(values))


def not_reached(escapes, face: int) -> float:
    """Share of pixels that get no light from `face`."""
    only = np.zeros((6, 4, 4, 3), np.float32)
    only[face] = 1.0
    reach = escapes.resolve(library.CubeMap(only).fetch(escapes.dirs, "bilinear")).max(axis=2)
    return float((reach <= 0.0).mean())


def test_a_correct_render_scores_one(scene):
    escapes, texels, expected = scene
    scored = score_render(expected, render(FakeLookups(), escapes, texels))
    assert scored.passed and scored.score == 1.0


def test_a_black_render_scores_about_nothing(scene):
    escapes, texels, expected = scene
    scored = score_render(expected, render(FakeLookups(fetch="black"), escapes, texels))
    assert not scored.passed and scored.score < 0.01


@pytest.mark.parametrize("face", FACES)
def test_one_wrong_face_scores_about_the_share_it_does_not_reach(scene, face):
    escapes, texels, expected = scene
    scored = score_render(expected, render(FakeLookups(fetch={face: "v-flipped"}), escapes, texels))
    share = not_reached(escapes, FACES.index(face))
    assert 0.0 < share < 1.0
    assert not scored.passed and 0.0 < scored.score < 1.0
    # FLIP's filters spread an error a pixel or so (below the share), and the
    # glass sphere's faint reflection of a face barely shows (above it).
    assert abs(scored.score - share) < 0.05, (scored.score, share, PIXEL_FLIP_MAX)


def test_one_wrong_face_costs_less_than_two(scene):
    escapes, texels, expected = scene
    one = score_render(expected, render(FakeLookups(fetch={"+X": "u-flipped"}), escapes, texels)).score
    two = score_render(expected, render(FakeLookups(fetch={"+X": "u-flipped", "-Y": "u-flipped"}), escapes, texels)).score
    assert 0.0 < two < one < 1.0
