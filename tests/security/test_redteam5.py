"""Attacks on the public-map observation of 2026-12-07
(tests/submissions/redteam5/, each file's first line says what it does and
the verdict a secure grader gives; each attack has its control, the same
code with `kTrick = false`). A red-team helper wrote them against the first
form of checks.instruments.map_probe, which recorded fetchColor on 2,048
random directions on each public map and on 32 x 32 faces, in a worker of
its own, and compared the records: every attack below scored more than its
control there (88.17 -> 94.07, 92.85 or 90.74), as each is right on the
public maps only where that probe did not look:

- right_when_real_texels_answer, knows_the_tags: right only when readTexture
  answers with texels (not the recording's tags);
- right_after_the_prelude: right only in a process whose first faces were
  uniform (the end-to-end checks' prelude);
- right_on_dense_or_swept_rays: right only for camera rays that bunch up, the
  arrows' Fibonacci sweep, or after 100,000 lookups on a map;
- right_after_many_lookups: right after 4,096 lookups on a map.

Held since each run on a public map is observed on a sample of its own
directions (map_probe.sample, observe): recorded on 32 x 32 faces in the same
worker just before the map is set, then read again by the student's
readTexture on the map at what fetchColor asked there; where an answer in
the run differs, the arrows and renders are judged again through
SweepFaceRequests and the lower score counts.

- reads_itself_on_every_map: fetchColor reads through its readTexture
  called qualified (`EnvironmentMap::readTexture`), which no recording logs:
  there is no request to read again, and it is judged end to end on the
  public maps. WORKS (88.17 -> 94.07), a strict xfail.

Both isolation modes (tests/helpers/isolation.py)."""
from __future__ import annotations

import pytest

from isolation import isolation_mode
from red_team import REDTEAM5, by_name, graded

HELD = ("right_when_real_texels_answer", "knows_the_tags", "right_after_the_prelude", "right_on_dense_or_swept_rays",
        "right_after_many_lookups")
OPEN = ("reads_itself_on_every_map",)
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
    # Said where it was observed (the arrows meet fewer lookups than the renders,
    # so a lookup right only after many is seen in the renders alone).
    said = {check for check in ("arrows", "renders") if "fetch-depends-on-the-map" in {d.id for d in a[check].diagnoses}}
    assert "renders" in said, said


@pytest.mark.xfail(strict=True, reason=(
    "fetchColor reads through EnvironmentMap::readTexture called qualified: no readTexture call is recorded, so "
    "nothing it asks can be read again on the public map, and the arrows and renders are end to end there "
    "(94.07 against 88.17 graded whole)"))
def test_reading_itself_right_only_on_the_public_maps_buys_nothing(tmp_path, mode):
    a, c = attack_and_control("reads_itself_on_every_map", tmp_path, mode)
    for check in ("arrows", "renders"):
        assert a[check].score <= c[check].score + 1e-9, (check, a[check].score, c[check].score)
