"""grader/envmap/geometry.py against the handout's face table (tests/helpers/assignment_model.py,
written from ASSIGNMENT.md independently of the C code it stands on)."""
import numpy as np
import pytest

import assignment_model as model
from grader.envmap import geometry, library


def test_face_names_and_filters_come_from_the_header():
    assert geometry.FACE_NAMES == model.FACE_NAMES == library.FACE_NAMES
    assert set(model.FILTERS) <= set(library.FILTERS)
    assert library.FILTERS["bilinear"] == 1 and library.FILTERS["nearest"] == 0


@pytest.mark.parametrize("face", range(6))
def test_face_uv_to_direction_inverts_the_handout_table(face, rng):
    u, v = rng.random(200), rng.random(200)
    d = geometry.face_uv_to_direction(face, u, v)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-15)
    assert model.touching_faces(d)[:, face].all()
    mu, mv = model.face_uv(d, face)
    np.testing.assert_allclose(mu, u, atol=1e-14)
    np.testing.assert_allclose(mv, v, atol=1e-14)


def test_direction_to_face_uv_round_trips(rng):
    face = rng.integers(0, 6, 1000)
    u, v = rng.uniform(0.01, 0.99, (2, 1000))
    got_face, got_u, got_v = geometry.direction_to_face_uv(geometry.face_uv_to_direction(face, u, v, normalized=False))
    assert (got_face == face).all()
    np.testing.assert_allclose(got_u, u, atol=1e-15)
    np.testing.assert_allclose(got_v, v, atol=1e-15)


def test_degenerate_directions_have_no_face():
    face, u, v = geometry.direction_to_face_uv(np.array([[0.0, 0, 0], [np.nan, 1, 0], [np.inf, 0, 0]]))
    assert (face == -1).all() and (u == 0.5).all() and (v == 0.5).all()


def test_solid_angles_cover_the_sphere_and_match_the_density():
    omega = geometry.texel_solid_angles(16, 8)
    assert 6 * omega.sum() == pytest.approx(4 * np.pi, rel=1e-12)
    u, v = geometry.texel_centre_uv(16, 8)
    # A texel's solid angle is its density at the centre times its area, to O(h^2).
    np.testing.assert_allclose(omega, geometry.solid_angle_density(u, v) / (16 * 8), rtol=0.02)


def test_cross_cells_are_where_the_reference_puts_each_face():
    # ASSIGNMENT.md's vertical cross, row 0 at the top.
    assert geometry.cross_cells() == {"+Y": (1, 0), "-X": (0, 1), "-Z": (1, 1), "+X": (2, 1),
                                      "-Y": (1, 2), "+Z": (1, 3)}
