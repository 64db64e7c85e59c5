"""instruments/map_probe.py on in-process fakes (tests/helpers/fake_lookups.py):
a run on a public map held, on a sample of its directions, to what
fetchColor asks for on the sweep's faces, and the lookups that judge a check
on the latter."""
from __future__ import annotations

import numpy as np
import pytest

from fake_lookups import FakeLookups
from grader import PROJECT_ROOT
from grader.checks.context import CheckContext, look_up_public_map
from grader.checks.instruments import map_probe
from grader.checks.instruments.textures import SWEEP_FACE_SIZE
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


def run(lookups, tmp_path, n: int = 4000):
    """One observed run on grid_room_cross.hdr: (ctx, the run's outcome)."""
    ctx = CheckContext(lookups=lookups, seed=5, artifacts=tmp_path)
    dirs = np.random.default_rng(3).normal(size=(n, 3))
    samples = map_probe.sample_runs(ctx, [("renders", "the render", dirs)])
    outcome = look_up_public_map(ctx, map_probe.load_map(GRID_ROOM), dirs, sample=samples["renders"])
    return ctx, outcome


@pytest.mark.parametrize("lookups", [FakeLookups(), FakeLookups(fetch={"+Z": "v-flipped"}),
                                     FakeLookups(texture="nearest"), FakeLookups(fetch="clamped-inward",
                                                                                 texture="half-texel")],
                         ids=["correct", "v-flipped", "nearest-readtexture", "two-mistakes"])
def test_code_that_behaves_alike_everywhere_is_seen_alike(tmp_path, lookups):
    """Right or wrong, the same code on the sweep's faces and on the map: no difference."""
    ctx, _ = run(lookups, tmp_path)
    (seen,) = ctx.map_probe().seen
    assert seen.compared > 0.8 * map_probe.SAMPLE and seen.differ == 0 and not ctx.map_probe().depends
    # The run itself looked up the public map.
    assert lookups.faces.shape[1:3] == map_probe.load_map(GRID_ROOM).shape[1:3]


def test_right_only_on_large_faces_is_observed_in_the_run_with_its_numbers(tmp_path):
    ctx, outcome = run(RightOnlyOnLargeFaces(), tmp_path)
    observations = ctx.map_probe()
    (seen,) = observations.seen
    assert observations.depends and 0 < seen.differ < seen.compared      # the +Z directions only
    said = observations.diagnosis()
    assert said.id == "fetch-depends-on-the-map" and said.detail.startswith("In the render, fetchColor(Vector3(")
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
    ctx = CheckContext(lookups=map_probe.SweepFaceRequests(FakeLookups(), 5), seed=5, artifacts=tmp_path)
    assert not map_probe.observing(ctx)


def test_the_sample_is_drawn_from_the_seed_and_the_runs_key_on_the_sweeps_faces():
    lookups = FakeLookups()
    ctx = CheckContext(lookups=lookups, seed=5, artifacts=PROJECT_ROOT)
    dirs = np.random.default_rng(3).normal(size=(4000, 3))
    got = map_probe.sample_runs(ctx, [("renders", "x", dirs), ("renders again", "y", dirs[:100]), ("arrows", "x", dirs)])
    a, short, c = got["renders"], got["renders again"], got["arrows"]
    assert len(a.rows) == map_probe.SAMPLE and len(short.rows) == 100 and not (a.rows == c.rows).all()
    assert (map_probe.sample_runs(ctx, [("renders", "y", dirs)])["renders"].rows == a.rows).all()
    assert lookups.faces.shape[1:3] == SWEEP_FACE_SIZE[::-1]
    # Each run's part of the one recording: its own directions' calls.
    faces, uv = library.direction_to_face(c.directions)
    assert (c.record.faces[:, 0] == faces).all() and (c.record.uv[:, 0] == uv).all()


def test_judged_on_sweep_face_requests_the_trick_renders_as_the_mistake_everywhere():
    """Through SweepFaceRequests, the lookup right only on large faces gives,
    on a public map, the colours the same mistake on every face gives there."""
    faces = map_probe.load_map(GRID_ROOM)
    dirs = np.random.default_rng(3).normal(size=(3000, 3))
    seen = map_probe.SweepFaceRequests(RightOnlyOnLargeFaces(), seed=5)
    seen.set_faces(faces)
    control = FakeLookups(fetch={"+Z": "v-flipped"})
    control.set_faces(faces)
    assert seen.inner.faces.shape[1:3] == SWEEP_FACE_SIZE[::-1]     # fetchColor never saw the public map
    got, want = seen.fetch(dirs), control.fetch(dirs)
    assert got.evaluated.all()
    np.testing.assert_allclose(got.values, want.values, rtol=0, atol=1e-5)
    # As it is on the map itself: right.
    trick = RightOnlyOnLargeFaces()
    trick.set_faces(faces)
    assert np.abs(trick.fetch(dirs).values - want.values).max() > 0.01


def test_a_direction_with_no_readtexture_call_is_black_there():
    seen = map_probe.SweepFaceRequests(FakeLookups(fetch="black"), seed=5)
    seen.set_faces(map_probe.load_map(GRID_ROOM))
    got = seen.fetch(np.array([[0.3, 0.2, 1.0], [1.0, 0.1, 0.1]]))
    assert (got.values == 0).all() and got.evaluated.all()
