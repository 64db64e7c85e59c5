"""instruments/map_probe.py on in-process fakes (tests/helpers/fake_lookups.py):
fetchColor's requests on the public maps compared with those on the
sweep's faces, and the lookups that judge a check on the latter."""
from __future__ import annotations

import numpy as np

from fake_lookups import FakeLookups
from grader.checks.instruments import map_probe
from grader.checks.instruments.textures import SWEEP_FACE_SIZE
from grader.envmap import library

POS_Z = library.FACE_NAMES.index("+Z")


class RightOnlyOnLargeFaces(FakeLookups):
    """v flipped on +Z except on faces 128 wide or more (every public map):
    redteam4/right_on_the_public_maps.cpp's behaviour, written from what it does."""

    def _requests(self, dirs):
        faces, uv = super()._requests(dirs)
        if self.faces.shape[2] < 128:
            uv = uv.copy()
            uv[faces == POS_Z, 1] = 1 - uv[faces == POS_Z, 1]
        return faces, uv


def test_the_probe_looks_at_every_public_map_once():
    maps = map_probe.public_maps()
    names = {p.name for p in maps}
    assert len(maps) == len(names) and "test_environment_map.hdr" in names and "grid_room_cross.hdr" in names


def test_a_correct_fetch_color_asks_the_same_everywhere():
    probe = map_probe.probe(FakeLookups(), seed=5)
    assert not probe.depends
    assert len(probe.on_maps) == len(map_probe.public_maps())
    assert all((rec.calls == 1).all() for _p, _s, rec in probe.on_maps)


def test_a_mistake_the_same_on_every_map_is_no_dependence():
    assert not map_probe.probe(FakeLookups(fetch={"+Z": "v-flipped"}), seed=5).depends


def test_right_only_on_large_faces_is_observed_call_for_call():
    probe = map_probe.probe(RightOnlyOnLargeFaces(), seed=5)
    assert probe.depends
    said = probe.diagnosis()
    assert said.id == "fetch-depends-on-the-map"
    # The +Z directions of the probe, on the map the diagnosis names, and both calls in numbers.
    faces, uv = library.direction_to_face(probe.directions)
    on_z = int((faces == POS_Z).sum())
    assert f"for {on_z} of {len(probe.directions)} directions" in said.detail
    i = int(np.flatnonzero(faces == POS_Z)[0])
    u, v = (float(x) for x in uv[i])
    assert f"+Z at (u, v) = ({u!r}, {v!r}) there and +Z at (u, v) = ({u!r}, {1 - v!r})" in said.detail


def test_a_request_that_uses_the_face_size_is_observed_too():
    """Honest code can depend on the size (half a texel in u): what it asks
    differs from map to map, and the diagnosis says so (true, if not a trick)."""
    assert map_probe.probe(FakeLookups(fetch="half-texel-u"), seed=5).depends


def test_differences_below_float_rounding_are_not_a_dependence():
    probe = map_probe.probe(FakeLookups(), seed=5)
    path, size, rec = probe.on_maps[0]
    import dataclasses
    nudged = dataclasses.replace(rec, uv=rec.uv + 2.0 ** -24)
    assert not map_probe.differ(probe.on_sweep_faces, nudged).any()
    moved = dataclasses.replace(rec, uv=rec.uv + 1e-6)
    assert map_probe.differ(probe.on_sweep_faces, moved).all()


def test_judged_on_sweep_face_requests_the_trick_renders_as_the_mistake_everywhere():
    """Through SweepFaceRequests, the lookup right only on large faces gives,
    on a public map, the colours the same mistake on every face gives there."""
    faces = map_probe.load_map(map_probe.public_maps()[0])
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
    seen.set_faces(map_probe.load_map(map_probe.public_maps()[0]))
    got = seen.fetch(np.array([[0.3, 0.2, 1.0], [1.0, 0.1, 0.1]]))
    assert (got.values == 0).all() and got.evaluated.all()
