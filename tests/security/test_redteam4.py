"""Attacks on three changes of 2026-12-07 (tests/submissions/redteam4/, each
file's first line says what it does and the verdict a secure grader gives;
each attack has a control, the same code without its trick):

1. The renders share one worker (grader/checks/renders.py: a first lookup
   on faces larger than the largest map, then the seven maps in turn,
   same_process) and identical images score SSIM 1 / FLIP 0 unmeasured.
   - wrong_until_the_faces_change: v flipped on +Z until the process has
     looked up on faces of a second size. A program that loads one map
     always shows the flip; every end-to-end check (arrows, stability,
     renders) starts with faces of another size
     (checks.instruments.process_state.set_faces_after_another_size), so it is right there.
     WORKED (88.17 -> 94.83, both modes); not new with the shared worker: the
     renders had the same prelude, one per render, before it. Held since
     fetchColor is asked the same directions in both states
     (checks.instruments.process_state): where answers differ, the
     end-to-end checks and the sweep's second-size set are judged in both
     and the lower score counts (88.17 graded whole, as the control).
   - right_on_the_public_maps: v flipped on +Z except on faces 128 wide or
     more (every map in Cubemap/): the seven renders are bit for bit the
     reference's (the shortcut scores them) and the arrows point right.
     It scores 94.07 against the control's 88.17: the arrows and renders
     see it right at their maps' size. Not an attack after all, but the rule
     (checks.instruments.map_probe): each size is judged by what the lookup
     does there, as a lookup that snaps (u, v) to texel centres is; judged
     at the sweep's 32 x 32 instead, such honest mistakes lost 11 to 12
     points more in the arrows and renders than they cost on the maps
     (a blind reviewer, 2026-12-07). A lookup right only on the public
     texels, or only when nothing records it, is held
     (tests/security/test_redteam5.py).
   - remembers_the_first_map: a cache of answers keyed by the direction
     alone. The shared worker now shows it: the renders after the first on
     envmap_test.cfg get grid_room's colours (3 of 7 fail; 1 of 7 when each
     render had its own worker). Held.
2. The speed check settles after 3 rounds (SETTLED_ROUNDS, SETTLED_FACTOR).
   - fast_for_the_first_round, fast_for_three_rounds: a correct 20x lookup
     without its busy loop for the first 50,000 (330,000) calls of a
     process; the speed worker is fresh, and a side's figure is its fastest
     pass, so one honest fast pass is full points. WORKED (95 -> 100); not
     the early stop: with no early stop (15 rounds) both still scored 5 / 5.
     Held since the timed rounds follow an untimed run of a drawn length
     (400,000 to 1.2 million calls, speed.WARM_UP_PASSES) in every fresh
     worker.
3. readTexture in context is measured on public faces (IN_CONTEXT_SEED)
   and held to the grading's draw (compare.below_by_more_than_chance).
   - honest_on_the_public_in_context_faces: honest to fetchColor on the
     public faces only. Held: the draw finds every call answered otherwise.
   - hides_from_the_drawn_in_context: the same, and on the draw's faces
     (16 x 16 random texels that are not the public ones) fetchColor returns
     readTexture's answer 2^-40 off: in_context observes only answers
     returned unchanged, so the draw observes nothing, its share is 1, and
     the public share (all alike) is kept. WORKED (65.07 -> 90.07); held
     since the draw's unreturned answers count as answered otherwise where
     the public ones were returned (fetch_record.InContext.hiding).
   - honest_on_small_faces: honest to fetchColor on faces 16 wide or less;
     both in-context sets were 16 x 16, the renders' maps 128 or 256. WORKED
     (65.07 -> 90.07); held since readTexture is observed in context on the
     maps' face sizes too (fetch_record.IN_CONTEXT_SIZES).

Each working attack is a strict xfail saying what should happen. Both
isolation modes (tests/helpers/isolation.py)."""
from __future__ import annotations

from pathlib import Path

import pytest

from grader.checks.renders import SSIM_MIN
from grader.grading.grade import GradeOptions
from grader.grading.results import FAILED, GRADED
from grading_cache import grade_once
from isolation import ISOLATION, isolation_mode
from red_team import REDTEAM4, by_name, graded
CONTROLS = ("v_flipped_pos_z_control", "correct_control", "slow_control", "nearest_control")
ATTACKS = ("wrong_until_the_faces_change", "right_on_the_public_maps", "remembers_the_first_map",
           "fast_for_the_first_round", "fast_for_three_rounds", "honest_on_the_public_in_context_faces",
           "hides_from_the_drawn_in_context", "honest_on_small_faces")
RED_TEAM = {"redteam4": set(CONTROLS + ATTACKS)}

# Both production modes (tests/helpers/isolation.py), under the name these tests use.
mode = isolation_mode

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]


def whole(name: str, out: Path, mode: str, only: tuple[str, ...] = ()):
    """A grading with the full direction sets and all seven renders (quick
    runs one render: state kept across the renders' maps needs them all)."""
    result = grade_once(REDTEAM4 / f"{name}.cpp", out, GradeOptions(allow_stale=True, only=only), write_reports=False)
    assert result.status == GRADED, result.status
    assert result.isolation == ISOLATION[mode]
    return result


def quick(name: str, out: Path, mode: str, only: tuple[str, ...] = ()):
    return graded(REDTEAM4 / f"{name}.cpp", out, mode, only=only)


# ---- 1. the renders' shared worker -----------------------------------------------

def test_wrong_until_the_faces_change_buys_nothing(tmp_path, mode):
    a = quick("wrong_until_the_faces_change", tmp_path / "attack", mode)
    c = quick("v_flipped_pos_z_control", tmp_path / "control", mode)
    assert by_name(c)["fetch_sweep"].status == FAILED
    for name in ("arrows", "stability", "renders"):
        assert by_name(a)[name].score <= by_name(c)[name].score + 1e-9, (name, by_name(a)[name].score,
                                                                         by_name(c)[name].score)
    assert a.score <= c.score
    assert "fetch-depends-on-earlier-faces" in {d.id for d in by_name(a)["arrows"].diagnoses}


def test_right_on_every_map_as_wide_as_the_public_ones_is_judged_at_that_size(tmp_path, mode):
    """Right on faces 128 wide or more, whatever their texels: the sweep
    charges the flip on its 32 x 32 faces as the control's; the arrows and
    renders, on maps that wide, see it right, with nothing said about the
    maps (each size judged by what the lookup does there: a lookup that
    snaps (u, v) to texel centres is not charged at the maps' size for what
    its snapping costs at 32)."""
    a = by_name(quick("right_on_the_public_maps", tmp_path / "attack", mode))
    c = by_name(quick("v_flipped_pos_z_control", tmp_path / "control", mode))
    right = by_name(quick("correct_control", tmp_path / "right", mode))
    assert a["fetch_sweep"].status == FAILED and a["fetch_sweep"].score == c["fetch_sweep"].score
    for name in ("arrows", "renders"):
        assert a[name].score == right[name].score == right[name].max_score, name
        assert "fetch-depends-on-the-map" not in {d.id for d in a[name].diagnoses}, name


def test_answers_kept_across_maps_cost_the_renders_after_the_first(tmp_path, mode):
    """A cache keyed by the direction alone: the first map's colours for
    the maps after it on the same scene. Charged in the renders (3 of 7)
    and nowhere else: every recorded check re-records remembered answers in
    a fresh worker."""
    a = by_name(whole("remembers_the_first_map", tmp_path / "attack", mode))
    c = by_name(whole("correct_control", tmp_path / "control", mode))
    assert a["renders"].score < c["renders"].score == c["renders"].max_score
    assert a["renders"].metrics["ssim_envmap_test--grid_room_cross"] == 1.0
    for later in ("interior_cross", "sky_cross", "test_environment_map"):
        assert a["renders"].metrics[f"ssim_envmap_test--{later}"] < SSIM_MIN, later
    for name in ("read_texture", "fetch_sweep", "arrows", "stability"):
        assert a[name].score == c[name].score == c[name].max_score, name


# ---- 2. the speed check's early stop ----------------------------------------------

@pytest.mark.parametrize("attack", ["fast_for_the_first_round", "fast_for_three_rounds"])
def test_fast_only_for_the_first_calls_of_a_process_buys_nothing(tmp_path, mode, attack):
    c = by_name(quick("slow_control", tmp_path / "control", mode, only=("speed",)))["speed"]
    assert c.status == FAILED and {d.id for d in c.diagnoses} == {"slow"}
    a = by_name(quick(attack, tmp_path / "attack", mode, only=("speed",)))["speed"]
    assert a.score <= c.score, a.output


# ---- 3. readTexture in context, on public faces held to the draw -----------------

def test_honest_only_on_the_public_in_context_faces_buys_nothing(tmp_path, mode):
    a = by_name(quick("honest_on_the_public_in_context_faces", tmp_path / "attack", mode,
                      only=("read_texture", "fetch_sweep", "renders")))
    c = by_name(quick("nearest_control", tmp_path / "control", mode, only=("read_texture", "fetch_sweep", "renders")))
    assert "texture-context-dependent" in {d.id for d in a["read_texture"].diagnoses}
    assert a["read_texture"].score <= c["read_texture"].score
    assert sum(x.score for x in a.values()) <= sum(x.score for x in c.values())


@pytest.mark.parametrize("attack", ["hides_from_the_drawn_in_context", "honest_on_small_faces"])
def test_readtexture_honest_only_where_in_context_looks_buys_nothing(tmp_path, mode, attack):
    a = by_name(quick(attack, tmp_path / "attack", mode, only=("read_texture", "fetch_sweep", "renders")))
    c = by_name(quick("nearest_control", tmp_path / "control", mode, only=("read_texture", "fetch_sweep", "renders")))
    assert a["renders"].status == FAILED        # what every render shows: the starting code's nearest texel
    assert a["read_texture"].score <= c["read_texture"].score
