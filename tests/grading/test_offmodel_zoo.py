"""The off-model zoo (tests/submissions/offmodel/): submissions written in
styles and with mistakes unlike the other zoos (face tables, if-chains,
float (u, v), a signed major component, OpenGL's table, readTextures no
model of the family reproduces, an inset, ties behind crashes). Each one's
truth was written in its sidecar X.json from the code, before grading:
- causes: the (id, face) the report must name;
- per_face: true per-face ids a named pattern may also show;
- symptoms: ids that may appear as consequences;
- loses / keeps: checks that must lose or keep their points.
Nothing else may be named. Where readTexture is wrong (its body sits between
`// readTexture:begin` and `// readTexture:end`), fetchColor's own checks
score within a point of the same fetchColor over the handout's readTexture.

attack18/ holds issue 18's attacks, graded against their controls.

Measure (any version of the grader):
    .venv/bin/python -m grader grade --quick tests/submissions/offmodel/*.cpp --out OUT
    PYTHONPATH=. .venv/bin/python tests/grading/test_offmodel_zoo.py OUT
"""
import json
from pathlib import Path

import pytest

from grader.grading.grade import GradeOptions
from grading_cache import grade_once   # each (file, options) graded once a session
from zoo_truth import Zoo
from grader.grading.results import GRADED
from project_paths import SUBMISSIONS

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]   # grades whole submissions

ZOO = SUBMISSIONS / "offmodel"
NAMES = sorted(p.stem for p in ZOO.glob("*.cpp"))
FETCH_CHECKS = ("fetch_sweep", "stability", "speed")   # what judges fetchColor alone

ZOO_TRUTH = Zoo(ZOO)
truth, verdict, with_handout_read = ZOO_TRUTH.truth, ZOO_TRUTH.verdict, ZOO_TRUTH.with_handout_read


def test_every_offmodel_submission_has_its_truth():
    assert len(NAMES) >= 10 and {p.stem for p in ZOO.glob("*.json")} == set(NAMES)
    for name in NAMES:
        assert set(truth(name)) >= {"causes", "per_face", "symptoms", "loses", "keeps"}, name


# False ids the per-face analysis (instruments/face_map.py) still names, each
# checked false in the file's header. (int-abs-axis_c-style was one: uv-mismatch,
# "reads the right face", on the faces its directions leave.)
KNOWN_FALSE: dict[str, str] = {}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.xfail(reason=KNOWN_FALSE[n], strict=True))
                                  if n in KNOWN_FALSE else n for n in NAMES])
def test_offmodel_submission_is_diagnosed_exactly(name, tmp_path):
    result = grade_once(ZOO / f"{name}.cpp", tmp_path, GradeOptions(quick=True))
    assert result.status == GRADED
    missing, false = verdict(name, {(d.id, d.face) for d in result.diagnoses})
    assert not missing and not false, f"missing {missing}, false {false}"
    t, by_name = truth(name), {c.name: c for c in result.checks}
    assert all(by_name[c].score < by_name[c].max_score for c in t["loses"]), {c: by_name[c].score for c in t["loses"]}
    assert all(by_name[c].score == by_name[c].max_score for c in t["keeps"]), {c: by_name[c].score for c in t["keeps"]}


def fetch_points(result) -> float:
    return sum(c.score for c in result.checks if c.name in FETCH_CHECKS)


# A readTexture that crashes on its whole top row (v = 1): the worker now goes
# on past each crash, so only the crashing inputs are lost, but those are
# many of the stability check's edge directions (not earned where readTexture
# crashes: crashing must not pay) and every timed pass (speed needs a lookup
# that does not crash): 6.44 / 10 and 0 / 5 against the handout's 10 and 5.
# Known and kept visible (strict); strict-ties_unclamped-x1, which the
# failed-run budget used to sink, now passes.
CRASH_CLIFF = {"unclamped-top-row_correct-fetch"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.xfail(
                                      reason="crashing inputs are not earned: stability's edges and every timed pass",
                                      strict=True))
                                  if n in CRASH_CLIFF else n for n in NAMES if with_handout_read(n) is not None])
def test_a_wrong_read_texture_costs_fetch_color_at_most_a_point(name, tmp_path):
    control = tmp_path / "control" / "EnvironmentMap.cpp"
    control.parent.mkdir()
    control.write_text(with_handout_read(name))
    theirs = grade_once(ZOO / f"{name}.cpp", tmp_path / "a", GradeOptions(quick=True))
    handout = grade_once(control.parent, tmp_path / "b", GradeOptions(quick=True))
    assert abs(fetch_points(theirs) - fetch_points(handout)) <= 1.0, \
        ({c.name: c.score for c in theirs.checks}, {c.name: c.score for c in handout.checks})


# ---- issue 18: being hard to model buys nothing ------------------------------

ATTACKS = ZOO / "attack18"


def test_an_unfittable_read_texture_buys_fetch_color_no_points(tmp_path):
    """readTexture exact except at one point, fetchColor half a texel off:
    no more than the same fetchColor over the handout's readTexture (before:
    85.94 against 44.82 in quick mode)."""
    attack = grade_once(ATTACKS / "half-texel-fetch_one-point-read.cpp", tmp_path / "a", GradeOptions(quick=True))
    control = grade_once(ATTACKS / "half-texel-fetch_handout-read.cpp", tmp_path / "b", GradeOptions(quick=True))
    texture = {c.name: c for c in attack.checks}["read_texture"]
    assert texture.diagnoses == [] and "At u = " in texture.output   # nothing proved: one call in numbers
    assert attack.score <= control.score, (attack.score, control.score)
    assert fetch_points(attack) <= fetch_points(control) + 0.1


def test_a_read_texture_that_answers_the_judge_differently_buys_nothing(tmp_path):
    """readTexture, called on its own on the judges' face sizes (not from
    fetchColor), shifts u as fetchColor does: the live judge would see a
    fetchColor "right over its own readTexture" (71.56 before the guard).
    The readTexture check found it honest on other sizes, so the live answers
    are not believed there."""
    attack = grade_once(ATTACKS / "direct-call-cheat.cpp", tmp_path / "a", GradeOptions(quick=True))
    control = grade_once(ATTACKS / "half-texel-fetch_handout-read.cpp", tmp_path / "b", GradeOptions(quick=True))
    assert "texture-context-dependent" in {d.id for d in attack.diagnoses}
    assert attack.score <= control.score, (attack.score, control.score)


def test_a_cheap_path_on_the_timing_faces_fails_speed_behind_an_unfittable_read_texture(tmp_path):
    result = grade_once(ATTACKS / "cheap-timing-faces_one-point-read.cpp", tmp_path, GradeOptions(quick=True))
    speed = {c.name: c for c in result.checks}["speed"]
    assert speed.score == 0 and [d.id for d in speed.diagnoses] == ["timing-faces-wrong"], speed.output


def exact_share(out: Path) -> tuple[int, int, list[str]]:
    """(exact, total, lines) for a folder of reports written by
    `python -m grader grade --quick tests/submissions/offmodel/*.cpp --out OUT`."""
    exact, lines = 0, []
    for name in NAMES:
        data = json.loads((out / name / "results.json").read_text())
        found = {(d["id"], d.get("face")) for d in data["extra_data"]["diagnoses"]}
        missing, false = verdict(name, found)
        exact += not missing and not false
        lines.append(f"{'exact' if not missing and not false else 'WRONG'}  {name}"
                     + (f"  missing {sorted(missing, key=str)}" if missing else "")
                     + (f"  false {sorted(false, key=str)}" if false else ""))
    return exact, len(NAMES), lines


if __name__ == "__main__":
    import sys
    exact, total, lines = exact_share(Path(sys.argv[1]))
    print("\n".join(lines) + f"\nexactly diagnosed: {exact} of {total}")
