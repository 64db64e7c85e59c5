"""The readTexture model family, without a compiler: the handout's member
agrees with the C reference, and a fake lookup built from each member (one
injected mistake, and some combinations) is fitted back to a member that
names the same mistakes. Behaviour the probes cannot see (truncation where
p is never negative) is not asked for."""
from dataclasses import replace

import numpy as np
import pytest

from grader import reference
from grader.checks import texture_model as tm
from grader.checks.textures import coordinate_faces, random_faces

A = tm.Axis


def both(**parts) -> tm.TextureModel:
    return tm.TextureModel(A(**parts), A(**parts))


def test_the_handout_member_agrees_with_the_reference_bilinear_and_nearest():
    faces = random_faces(13, 7, 3)
    cube = reference.CubeMap(faces)
    rng = np.random.default_rng(1)
    uv = np.concatenate([rng.random((4000, 2)), np.stack(np.meshgrid(np.arange(14) / 13, np.arange(8) / 7), -1).reshape(-1, 2),
                         [[0, 0], [1, 1], [0, 1], [1, 0], [1 - 1e-12, 0.5]]])
    for face in (0, 5):
        got, past = tm.evaluate(tm.HANDOUT, faces[face], uv)
        assert not past.any()
        np.testing.assert_allclose(got, cube.read_texture(face, uv, "bilinear"), rtol=0, atol=1e-12)
        got, _ = tm.evaluate(both(weights="nearest"), faces[face], uv)
        np.testing.assert_array_equal(got, cube.read_texture(face, uv, "nearest"))


def test_an_unclamped_index_reads_the_next_row_then_faults_past_the_face():
    faces = coordinate_faces(4, 3)
    model = both(weights="nearest", edge="none", offset=1.0)
    got, past = tm.evaluate(model, faces[0], np.array([[3.2 / 4, 0.1 / 3], [3.2 / 4, 2.1 / 3], [0.0, 0.0]]))
    np.testing.assert_array_equal(got[0], [1, 3, 1])       # x = 4 on row 1 is (0, 2)
    assert past.tolist() == [False, True, False]
    got, past = tm.evaluate(both(weights="nearest", edge="none", offset=-1.0), faces[0], np.array([[0.0, 0.0]]))
    np.testing.assert_array_equal(got[0], [0, 0, 0])       # before the face: the zero-filled page


# (member, the ids its fit must name)
MEMBERS = {
    "handout": (tm.HANDOUT, []),
    "nearest": (both(weights="nearest"), ["nearest-neighbor"]),
    "weights-swapped": (both(weights="swapped"), ["weights-swapped"]),
    "constant-weights": (both(weights="half"), ["constant-weights"]),
    "half-texel": (both(offset=-0.5), ["half-texel-offset"]),
    "half-texel-plus": (both(offset=0.5), ["half-texel-offset"]),
    "texel-offset-clamped": (both(offset=-1.0), ["texel-offset"]),
    "texel-offset-unclamped": (both(offset=-1.0, edge="none"), ["texel-offset", "unclamped-edge"]),
    "texel-offset-plus": (both(offset=1.0), ["texel-offset"]),
    "half-texel-truncated": (both(offset=-0.5, rounding="trunc"), ["half-texel-offset", "truncation-of-negatives"]),
    "nearest-rounded": (both(weights="nearest", rounding="round"), ["nearest-neighbor", "half-texel-offset"]),
    "unclamped-nearest": (both(weights="nearest", edge="none"), ["nearest-neighbor", "unclamped-edge"]),
    "unclamped-bilinear": (both(edge="none"), ["unclamped-edge"]),
    "wrapped": (both(edge="wrap"), ["wrapped-edge"]),
    "scale-w-minus-1": (both(scale="N-1"), ["scaled-by-size-minus-one"]),
    "scale-w-plus-1": (both(scale="N+1"), ["scaled-by-size-plus-one"]),
    "nearest-w-minus-1": (both(weights="nearest", scale="N-1"), ["nearest-neighbor", "scaled-by-size-minus-one"]),
    "unclamped-w-minus-1-offset": (both(scale="N-1", offset=-1.0, edge="none"),
                                   ["texel-offset", "unclamped-edge", "scaled-by-size-minus-one"]),
    "rows-flipped": (tm.TextureModel(A(), A(flip="index")), ["rows-flipped"]),
    "rows-flipped-coordinate": (tm.TextureModel(A(), A(flip="coordinate")), ["rows-flipped"]),
    "columns-flipped": (tm.TextureModel(A(flip="index"), A()), ["columns-flipped"]),
    "wh-swapped": (both(size="other"), ["width-height-swapped"]),
    "uv-swapped": (both(source="other"), ["uv-swapped"]),
    "rows-flipped-w-minus-1-half-truncated": (
        tm.TextureModel(A(scale="N-1", offset=-0.5, rounding="trunc"), A(scale="N-1", offset=-0.5, rounding="trunc", flip="index")),
        ["half-texel-offset", "truncation-of-negatives", "scaled-by-size-minus-one", "rows-flipped"]),
}


@pytest.mark.parametrize("name", sorted(MEMBERS))
def test_a_fake_lookup_is_fitted_back_to_its_member(name):
    model, ids = MEMBERS[name]
    found = tm.fit(tm.fake_read_texture(model))
    assert found.fits, (found.closest, found.share)
    assert sorted(tm.mistake_ids(found.model)) == sorted(ids)
    # The fitted member answers exactly as the fake on fresh points.
    faces = random_faces(9, 5, 7)[1]
    uv = np.random.default_rng(2).random((500, 2))
    a, b = tm.evaluate(model, faces, uv)[0], tm.evaluate(found.model, faces, uv)[0]
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-9)


def test_a_lookup_outside_the_family_is_not_forced_into_it():
    def squared(face, uv, faces):        # p = (u^2 W, v H): no member does this
        return tm.evaluate(tm.HANDOUT, faces[face], np.stack([uv[:, 0] ** 2, uv[:, 1]], 1))[0]
    found = tm.fit(squared)
    assert not found.fits and 0 < found.share < 1


def test_a_constant_lookup_is_reported_as_such():
    found = tm.fit(lambda face, uv, faces: np.ones((len(uv), 3)))
    assert found.constant and not found.fits


def test_the_words_name_the_offset():
    text = tm.describe_model(both(weights="nearest", offset=-1.0))
    assert "one to the left and below" in text and "p = (uW - 1, vH - 1)" in text
