"""instruments/map_probe.py on in-process fakes (tests/helpers/fake_lookups.py):
a run on a public map held, on a sample of its directions, to what
fetchColor asks for on random faces of the same size, and the lookups that
judge a check on the latter."""
from __future__ import annotations

import numpy as np
import pytest

from fake_lookups import FakeLookups
from grader import PROJECT_ROOT
from grader.checks.context import CheckContext, look_up_public_map
from grader.checks.instruments import map_probe
from grader.envmap import library

POS_Z = library.FACE_NAMES.index("+Z")
GRID_ROOM = PROJECT_ROOT / "Cubemap" / "grid_room_cross.hdr"


class RightOnlyOnLargeFaces(FakeLookups):
    """v flipped on +Z except on faces 128 wide or more (every public map):
    redteam4/right_on_the_public_maps.cpp's behaviour, written from what it does."""

    def _requests(self, dirs):
        faces, uv = super()._requests(dirs)
        if self.faces.shape[2] < 128:
            uv = uv.copy()
            uv[faces == POS_Z, 1] = 1 - uv[faces == POS_Z, 1]
        return faces, uv


class RightOnlyOnThePublicTexels(FakeLookups):
    """v flipped on +Z except on grid_room_cross.hdr, told by its first
    texel (redteam5's lookups tell the public maps by what readTexture
    answers; this one by the texels themselves)."""

    def _requests(self, dirs):
        faces, uv = super()._requests(dirs)
        if not np.array_equal(self.faces[0, 0, 0], map_probe.load_map(GRID_ROOM)[0, 0, 0]):
            uv = uv.copy()
            uv[faces == POS_Z, 1] = 1 - uv[faces == POS_Z, 1]
        return faces, uv


def run(lookups, tmp_path, n: int = 4000):
    """One observed run on grid_room_cross.hdr: (ctx, the run's outcome)."""
    ctx = CheckContext(lookups=lookups, seed=5, artifacts=tmp_path)
    dirs = np.random.default_rng(3).normal(size=(n, 3))
    faces = map_probe.load_map(GRID_ROOM)
    samples = map_probe.sample_runs(ctx, "renders", [("renders", "the render", dirs, faces.shape[1:3])])
    outcome = look_up_public_map(ctx, faces, dirs, sample=samples["renders"])
    return ctx, outcome


@pytest.mark.parametrize("lookups", [FakeLookups(), FakeLookups(fetch={"+Z": "v-flipped"}),
                                     FakeLookups(texture="nearest"), FakeLookups(fetch="clamped-inward",
                                                                                 texture="half-texel"),
                                     FakeLookups(fetch="half-texel-u"), FakeLookups(fetch="clamped-to-texel-centres"),
                                     FakeLookups(fetch="inset"), RightOnlyOnLargeFaces()],
                         ids=["correct", "v-flipped", "nearest-readtexture", "two-mistakes", "half-texel-u",
                              "clamped-to-texel-centres", "inset", "right-only-on-large-faces"])
def test_code_whose_answers_depend_on_the_direction_and_the_size_alone_is_seen_alike(tmp_path, lookups):
    """Right or wrong, and whatever it makes of the face size, the same code
    on random faces of the map's size and on the map: no difference. A
    lookup right only on faces 128 wide or more is right on the public maps
    at their size, as a snapping one is as wrong there as its snapping
    makes it: each judged at each size by what it does there."""
    ctx, _ = run(lookups, tmp_path)
    (seen,) = ctx.map_probe().seen
    assert seen.compared > 0.8 * map_probe.SAMPLE and seen.differ == 0 and not ctx.map_probe().depends
    # The run itself looked up the public map.
    assert lookups.faces.shape[1:3] == map_probe.load_map(GRID_ROOM).shape[1:3]


def test_right_only_on_the_public_texels_is_observed_in_the_run_with_its_numbers(tmp_path):
    ctx, outcome = run(RightOnlyOnThePublicTexels(), tmp_path)
    observations = ctx.map_probe()
    (seen,) = observations.seen
    assert observations.depends and 0 < seen.differ < seen.compared      # the +Z directions only
    said = observations.diagnosis()
    assert said.id == "fetch-depends-on-the-map" and said.detail.startswith("In the render, fetchColor(Vector3(")
    assert f"{seen.differ} of {seen.compared} directions sampled from this check's lookups" in said.detail
    d, answered, face, u, v, read = seen.example
    assert face == POS_Z
    # What the table asks and what the flip asks, both (u, v) numbers the fake computes.
    faces, uv = library.direction_to_face(d[None, :])
    assert (u, v) == (float(uv[0, 0]), float(1 - uv[0, 1]))
    control = FakeLookups()
    control.set_faces(map_probe.load_map(GRID_ROOM))
    np.testing.assert_array_equal(answered, control.fetch(d[None, :]).values[0])     # right in the run
    assert f"face +Z at (u, v) = ({u!r}, {v!r})" in said.detail


def test_no_sample_is_taken_in_the_other_states(tmp_path):
    ctx = CheckContext(lookups=RightOnlyOnLargeFaces(), seed=5, artifacts=tmp_path, first_faces=True)
    assert not map_probe.observing(ctx)
    ctx = CheckContext(lookups=map_probe.RandomFaceRequests(FakeLookups(), 5), seed=5, artifacts=tmp_path)
    assert not map_probe.observing(ctx)


def test_the_sample_is_drawn_from_the_seed_and_the_runs_key_on_random_faces_of_each_size():
    lookups = FakeLookups()
    ctx = CheckContext(lookups=lookups, seed=5, artifacts=PROJECT_ROOT)
    dirs = np.random.default_rng(3).normal(size=(4000, 3))
    got = map_probe.sample_runs(ctx, "renders", [("renders", "x", dirs, (128, 128)), ("renders again", "y", dirs[:100], (256, 256)),
                                                 ("arrows", "x", dirs, (128, 128))])
    a, short, c = got["renders"], got["renders again"], got["arrows"]
    assert len(a.rows) == map_probe.SAMPLE and len(short.rows) == 100 and not (a.rows == c.rows).all()
    assert (map_probe.sample_runs(ctx, "other", [("renders", "y", dirs, (128, 128))])["renders"].rows == a.rows).all()
    # The largest faces first, then the smaller: random texels, never a public map's.
    assert lookups.faces.shape[1:3] == (128, 128)
    np.testing.assert_array_equal(lookups.faces, map_probe.random_like(5, (128, 128)))
    # Each run's part of the one recording: its own directions' calls.
    faces, uv = library.direction_to_face(c.directions)
    assert (c.record.faces[:, 0] == faces).all() and (c.record.uv[:, 0] == uv).all()


def test_judged_on_random_face_requests_the_trick_renders_as_the_mistake_everywhere():
    """Through RandomFaceRequests, the lookup right only on the public texels
    gives, on that map, the colours the same mistake on every map gives there."""
    faces = map_probe.load_map(GRID_ROOM)
    dirs = np.random.default_rng(3).normal(size=(3000, 3))
    seen = map_probe.RandomFaceRequests(RightOnlyOnThePublicTexels(), seed=5)
    seen.set_faces(faces)
    control = FakeLookups(fetch={"+Z": "v-flipped"})
    control.set_faces(faces)
    # fetchColor sees random texels of the map's size, never the public ones.
    assert seen.inner.faces.shape == faces.shape and not np.array_equal(seen.inner.faces, faces)
    got, want = seen.fetch(dirs), control.fetch(dirs)
    assert got.evaluated.all()
    np.testing.assert_allclose(got.values, want.values, rtol=0, atol=1e-5)
    # As it is on the map itself: right.
    trick = RightOnlyOnThePublicTexels()
    trick.set_faces(faces)
    assert np.abs(trick.fetch(dirs).values - want.values).max() > 0.01


def test_a_direction_with_no_readtexture_call_is_black_there():
    seen = map_probe.RandomFaceRequests(FakeLookups(fetch="black"), seed=5)
    seen.set_faces(map_probe.load_map(GRID_ROOM))
    got = seen.fetch(np.array([[0.3, 0.2, 1.0], [1.0, 0.1, 0.1]]))
    assert (got.values == 0).all() and got.evaluated.all()
