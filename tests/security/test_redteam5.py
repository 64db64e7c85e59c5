"""Attacks on the public-map observation of 2026-12-07
(tests/submissions/redteam5/, each file's first line says what it does and
the verdict a secure grader gives; each attack has its control, the same
code with `kTrick = false`). A red-team helper wrote the first six against
the first form of checks.instruments.map_probe, which recorded fetchColor on
2,048 random directions on each public map and on 32 x 32 faces, in a
worker of its own, and compared the records: each scored more than its
control there (88.17 -> 94.07, 92.85 or 90.74), right on the public maps
only where that probe did not look:

- right_when_real_texels_answer, knows_the_tags: right only when readTexture
  answers with texels (not the recording's tags);
- right_after_the_prelude: right only in a process whose first faces were
  uniform (the end-to-end checks' prelude);
- right_on_dense_or_swept_rays: right only for camera rays that bunch up, the
  arrows' Fibonacci sweep, or after 100,000 lookups on a map;
- right_after_many_lookups: right after 4,096 lookups on a map;
- reads_itself_on_every_map: right on faces 128 wide or more, reading
  through its readTexture called qualified (`EnvironmentMap::readTexture`),
  which no recording logs.

right_on_the_public_texels (ours) is right only on the texels of Cubemap/.

Now each run on a public map is observed on 256 of its own directions
(map_probe.sample_runs, observe): recorded before the check's runs on random
faces of the map's size in a fresh worker, then read again by the student's
readTexture on the map at what fetchColor asked there; where an answer in
the run differs, the arrows and renders are judged again through
RandomFaceRequests (every direction recorded on random faces of each map's
size) and the lower score counts. HELD: the texels, tags and prelude tricks
score their controls' 88.17. OPEN, strict xfails: the two that are right
only in a stream of lookups (many on one map, or bunched) are observed, but
the judging again records the whole stream on random faces, where they are
right again; and reading itself records no call to read again.

Both isolation modes (tests/helpers/isolation.py)."""
from __future__ import annotations

import pytest

from isolation import isolation_mode
from red_team import REDTEAM5, by_name, graded

HELD = ("right_when_real_texels_answer", "knows_the_tags", "right_after_the_prelude", "right_on_the_public_texels")
STREAM = ("right_on_dense_or_swept_rays", "right_after_many_lookups")
OPEN = STREAM + ("reads_itself_on_every_map",)
RED_TEAM = {"redteam5": {name + suffix for name in HELD + OPEN for suffix in ("", "_control")}}

mode = isolation_mode

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]


def attack_and_control(name: str, tmp_path, mode: str):
    only = ("fetch_sweep", "arrows", "renders")
    return (by_name(graded(REDTEAM5 / f"{name}.cpp", tmp_path / "attack", mode, only=only)),
            by_name(graded(REDTEAM5 / f"{name}_control.cpp", tmp_path / "control", mode, only=only)))


@pytest.mark.parametrize("name", HELD)
def test_right_only_where_nothing_records_buys_nothing(tmp_path, mode, name):
    a, c = attack_and_control(name, tmp_path, mode)
    assert a["fetch_sweep"].score == c["fetch_sweep"].score < c["fetch_sweep"].max_score
    for check in ("arrows", "renders"):
        assert a[check].score <= c[check].score + 1e-9, (check, a[check].score, c[check].score)
    for check in ("arrows", "renders"):
        assert "fetch-depends-on-the-map" in {d.id for d in a[check].diagnoses}, check


@pytest.mark.parametrize("name", STREAM)
@pytest.mark.xfail(strict=True, reason=(
    "right only in a stream of lookups (4,096 on one map, or rays that bunch up): the sample of 256 directions "
    "recorded on random faces in a fresh worker sees the flip, but judging again records every ray on random faces "
    "of the map's size, where the stream makes it right again (90.74 and 92.85 against 88.17 graded whole)"))
def test_right_only_in_a_stream_of_lookups_buys_nothing(tmp_path, mode, name):
    a, c = attack_and_control(name, tmp_path, mode)
    for check in ("arrows", "renders"):
        assert a[check].score <= c[check].score + 1e-9, (check, a[check].score, c[check].score)


@pytest.mark.xfail(strict=True, reason=(
    "fetchColor reads through EnvironmentMap::readTexture called qualified: no readTexture call is recorded, so "
    "nothing it asks can be read again on the public map, and the arrows and renders are end to end there "
    "(94.07 against 88.17 graded whole)"))
def test_reading_itself_right_only_on_the_public_maps_buys_nothing(tmp_path, mode):
    a, c = attack_and_control("reads_itself_on_every_map", tmp_path, mode)
    for check in ("arrows", "renders"):
        assert a[check].score <= c[check].score + 1e-9, (check, a[check].score, c[check].score)
