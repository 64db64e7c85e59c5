"""The picture of the record (issue 29 point 5): each face of "your
fetchColor" is the reference's lettered face seen through the (face, u, v)
fetchColor asked for, so a flip, a swap or another face shows as that same
transformation of the lettered face, and a face never asked for is grey.
Fakes in-process (tests/helpers/fake_lookups.py)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fake_lookups import FACES, FakeLookups
from grader.checks.context import CheckContext
from grader.checks.instruments import record_picture as rp


def test_a_correct_fetch_color_draws_the_reference_s_faces():
    np.testing.assert_array_equal(rp.asked_faces(FakeLookups()), rp.lettered_faces())


# The lettered face is (row = v, column = u): a flip of u reverses its
# columns, of v its rows, a swap transposes it.
@pytest.mark.parametrize("mistake, seen", [("u-flipped", lambda f: f[:, ::-1]), ("v-flipped", lambda f: f[::-1]),
                                           ("uv-swapped", lambda f: f.transpose(1, 0, 2))])
def test_a_face_asked_the_wrong_way_shows_the_lettered_face_turned_that_way(mistake, seen):
    reference = rp.lettered_faces()
    asked = rp.asked_faces(FakeLookups(fetch={"+Z": mistake}))
    z = FACES.index("+Z")
    np.testing.assert_array_equal(asked[z], seen(reference[z]))
    others = [k for k in range(6) if k != z]
    np.testing.assert_array_equal(asked[others], reference[others])
    assert not np.array_equal(asked[z], reference[z])   # the F is not symmetric: each turn shows


def test_a_face_read_from_another_shows_that_face_s_hue():
    asked = rp.asked_faces(FakeLookups(fetch={"+X": "wrong-face:-X"}))
    plus_x, minus_x = FACES.index("+X"), FACES.index("-X")
    hues = {tuple(c) for c in asked[plus_x].reshape(-1, 3)} - {(1.0, 1.0, 1.0)}
    assert hues == {tuple(rp.HUES[minus_x])}


def test_a_fetch_color_that_never_asks_is_grey():
    asked = rp.asked_faces(FakeLookups(fetch="black"))
    assert (asked == rp.UNSEEN).all()


def test_the_picture_is_written_with_both_crosses(tmp_path: Path):
    ctx = CheckContext(lookups=FakeLookups(fetch={"+Z": "v-flipped"}), seed=1, artifacts=tmp_path)
    path = rp.draw(ctx, ctx.lookups)
    assert path.is_file() and path.stat().st_size > 1000
    import OpenImageIO as oiio
    spec = oiio.ImageInput.open(str(path)).spec()
    assert spec.width > 2 * 3 * rp.SIZE * 6 * 0.9 and spec.height > 4 * rp.SIZE * 6 * 0.9
