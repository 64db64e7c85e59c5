"""Patterns before symptoms (issue 19): what explains several faces at once is
one diagnosis with its cause and fix, the per-face ids in its detail.

- `face-order`: every face read from another face, one to one (a numbering
  other than faceAddress's), three faces or more moved; one swapped pair
  stays two `wrong-face`s.
- `uv-rotated`: (u, v) turned 90, 180 or 270 degrees on two faces or more.
- `signed-major`, `opengl-table`: 180 degrees on their three faces and on no
  other, named beside the other faces' mistakes.

The zoo (tests/submissions/patterns/, in the off-model zoo's format: truth in
X.json written from the code before grading) proves it on real C++; the fake
submissions below say, in milliseconds, where each pattern starts and stops.

Measure (any version of the grader):
    .venv/bin/python -m grader grade --quick tests/submissions/patterns/*.cpp --out OUT
    PYTHONPATH=. .venv/bin/python tests/grading/test_pattern_zoo.py OUT
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import fake_lookups
from fake_lookups import FakeLookups
from grader.checks.instruments import face_map
from zoo_truth import Zoo
from grader.grading.results import GRADED, PASSED
from project_paths import SUBMISSIONS

HERE = SUBMISSIONS
ZOO = HERE / "patterns"
NAMES = sorted(p.stem for p in ZOO.glob("*.cpp"))
CORRECT = sorted((HERE / "correct").glob("*.cpp")) + sorted((HERE / "correct_lead").glob("*.cpp"))
PATTERN_IDS = {"face-order", "uv-rotated", "signed-major", "opengl-table"}
FETCH_CHECKS = ("fetch_sweep", "stability", "speed")   # what judges fetchColor alone
FACES = fake_lookups.FACES

ZOO_TRUTH = Zoo(ZOO)
truth, verdict, with_handout_read = ZOO_TRUTH.truth, ZOO_TRUTH.verdict, ZOO_TRUTH.with_handout_read


# ---- where each pattern starts and stops (fake submissions) ----------------------

# Turns of the (u, v) the reference computes, written from what a turn is:
# the point read, rotated about the face's centre (0.5, 0.5).
def _turn(degrees: int):
    c, s = round(np.cos(np.radians(degrees))), round(np.sin(np.radians(degrees)))
    return lambda uv: np.stack([0.5 + c * (uv[:, 0] - 0.5) - s * (uv[:, 1] - 0.5),
                                0.5 + s * (uv[:, 0] - 0.5) + c * (uv[:, 1] - 0.5)], 1)


@pytest.fixture(autouse=True)
def turns(monkeypatch):
    for degrees in (90, 180, 270):
        monkeypatch.setitem(fake_lookups.UV_MISTAKES, f"turned-{degrees}", _turn(degrees))


def found(fetch) -> set[tuple[str, str | None]]:
    analysis = face_map.analyse(FakeLookups(fetch=fetch), quick=True)
    return {(d.id, d.face) for d in analysis.diagnoses()}


def reorder(order: list[str]) -> dict[str, str]:
    """fetchColor numbering the faces in `order` and passing the number to
    faceAddress (the handout's order): face order[k] reads face k."""
    return {name: f"wrong-face:{FACES[k]}" for k, name in enumerate(order) if FACES[k] != name}


@pytest.mark.parametrize("fetch, expected", [
    # Face orders: axis by axis (four faces move), negative first (six), a cycle of three.
    (reorder(["+X", "+Y", "+Z", "-X", "-Y", "-Z"]), {("face-order", None)}),
    (reorder(["-X", "+X", "-Y", "+Y", "-Z", "+Z"]), {("face-order", None)}),
    (reorder(["+Y", "-X", "+Z", "-Y", "+X", "-Z"]), {("face-order", None)}),
    # One swapped pair is a sign, not an order: two wrong faces, as before.
    (reorder(["+X", "-X", "+Y", "-Y", "-Z", "+Z"]), {("wrong-face", "+Z"), ("wrong-face", "-Z")}),
    # Two faces reading the same face is no order either.
    ({"+Y": "wrong-face:+X", "-Y": "wrong-face:+X", "+Z": "wrong-face:+X"},
     {("wrong-face", "+Y"), ("wrong-face", "-Y"), ("wrong-face", "+Z")}),
    # Turns: every face, a consistent set, two turns at once (one diagnosis).
    ({f: "turned-90" for f in FACES}, {("uv-rotated", None)}),
    ({"+Y": "turned-270", "-Y": "turned-270", "+Z": "turned-270", "+X": "u-flipped"},
     {("uv-rotated", None), ("u-flipped", "+X")}),
    ({"+X": "turned-90", "-X": "turned-90", "+Y": "turned-180", "-Z": "turned-180"}, {("uv-rotated", None)}),
    # One face turned stays per face; mirror images are no turn.
    ({"+Z": "turned-180"}, {("u-flipped", "+Z"), ("v-flipped", "+Z")}),
    ({"+Z": "turned-90"}, {("uv-swapped", "+Z"), ("u-flipped", "+Z")}),
    ({f: "u-flipped" for f in FACES}, {("u-flipped", f) for f in FACES}),
    ({"+X": "uv-swapped", "-X": "uv-swapped"}, {("uv-swapped", "+X"), ("uv-swapped", "-X")}),
    # The named sets: beside another face's mistake, and not when a fourth face is turned too.
    ({f: "turned-180" for f in ("-X", "-Y", "-Z")} | {"+Y": "u-flipped"}, {("signed-major", None), ("u-flipped", "+Y")}),
    # OpenGL's words say the other faces are right: with a swap on +Y, the turn is told as a turn.
    ({f: "turned-180" for f in ("+X", "-X", "-Z")}, {("opengl-table", None)}),
    ({f: "turned-180" for f in ("+X", "-X", "-Z")} | {"+Y": "uv-swapped"}, {("uv-rotated", None), ("uv-swapped", "+Y")}),
    ({f: "turned-180" for f in ("-X", "-Y", "-Z", "+Z")}, {("uv-rotated", None)}),
    (None, set()),
], ids=["order-axis-major", "order-negative-first", "order-three-cycle", "one-swapped-pair", "three-read-one",
        "turned-every-face", "turned-three-and-a-flip", "two-turns", "one-face-180",
        "one-face-90", "mirrored-every-face", "swapped-two-faces", "signed-major-and-a-flip", "opengl",
        "opengl-and-a-swap",
        "four-faces-180", "correct"])
def test_a_pattern_is_named_once_and_only_where_it_is(fetch, expected):
    assert found(fetch) == expected


class MirroredOnNegX(FakeLookups):
    """fetchColor with z negated for directions toward -X before the rest:
    u runs the wrong way there ((1 - z/m)/2 on -X), whatever else it does."""

    def fetch(self, dirs, placement="end"):
        dirs = np.array(dirs, np.float64).reshape(-1, 3)
        a = np.abs(dirs)
        toward = (dirs[:, 0] < 0) & (a[:, 0] > a[:, 1]) & (a[:, 0] > a[:, 2])
        dirs[toward, 2] *= -1
        return super().fetch(dirs, placement)


def test_a_face_order_beside_a_flip_keeps_the_flip_on_its_face():
    fake = MirroredOnNegX(fetch=reorder(["-X", "+X", "-Y", "+Y", "-Z", "+Z"]))
    analysis = face_map.analyse(fake, quick=True)
    got = {d.id: d for d in analysis.diagnoses()}
    assert set(got) == {"face-order", "u-flipped"} and got["u-flipped"].face == "-X"
    assert "-X, +X, -Y, +Y, -Z, +Z" in got["face-order"].detail
    assert "+X, -X, +Y, -Y, +Z, -Z" in got["face-order"].detail


def test_the_turn_is_told_in_the_tables_terms():
    analysis = face_map.analyse(FakeLookups(fetch={"+Y": "turned-90", "-Y": "turned-90"}), quick=True)
    [d] = analysis.diagnoses()
    assert d.id == "uv-rotated" and "+Y and -Y" in d.detail and "90 degrees" in d.detail
    assert "your u is 1 - v and your v is u" in d.detail


# ---- the zoo: real C++ -----------------------------------------------------------

def fetch_points(result) -> float:
    return sum(c.score for c in result.checks if c.name in FETCH_CHECKS)


def test_every_pattern_submission_has_its_truth():
    assert len(NAMES) >= 8 and {p.stem for p in ZOO.glob("*.json")} == set(NAMES)
    for name in NAMES:
        assert set(truth(name)) >= {"causes", "per_face", "symptoms", "loses", "keeps"}, name
    # Each pattern is a case, and the swapped pair that is none.
    causes = {i for n in NAMES for i, _ in truth(n)["causes"]}
    assert {"face-order", "uv-rotated", "signed-major", "wrong-face"} <= causes


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.parametrize("name", NAMES)
def test_pattern_submission_is_diagnosed_exactly(name, tmp_path):
    from grader.grading.grade import GradeOptions
    from grading_cache import grade_once
    result = grade_once(ZOO / f"{name}.cpp", tmp_path, GradeOptions(quick=True))
    assert result.status == GRADED
    missing, false = verdict(name, {(d.id, d.face) for d in result.diagnoses})
    assert not missing and not false, f"missing {missing}, false {false}"
    t, by_name = truth(name), {c.name: c for c in result.checks}
    assert all(by_name[c].score < by_name[c].max_score for c in t["loses"]), {c: by_name[c].score for c in t["loses"]}
    assert all(by_name[c].score == by_name[c].max_score for c in t["keeps"]), {c: by_name[c].score for c in t["keeps"]}


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.parametrize("name", [n for n in NAMES if with_handout_read(n) is not None])
def test_a_wrong_read_texture_costs_the_pattern_at_most_a_point(name, tmp_path):
    from grader.grading.grade import GradeOptions
    from grading_cache import grade_once
    control = tmp_path / "control" / "EnvironmentMap.cpp"
    control.parent.mkdir()
    control.write_text(with_handout_read(name))
    theirs = grade_once(ZOO / f"{name}.cpp", tmp_path / "a", GradeOptions(quick=True))
    handout = grade_once(control.parent, tmp_path / "b", GradeOptions(quick=True))
    assert abs(fetch_points(theirs) - fetch_points(handout)) <= 1.0, \
        ({c.name: c.score for c in theirs.checks}, {c.name: c.score for c in handout.checks})
    # The same pattern is named over the handout's readTexture.
    patterns = lambda r: {d.id for d in r.diagnoses} & PATTERN_IDS
    assert patterns(theirs) == patterns(handout) != set()


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.parametrize("path", CORRECT, ids=lambda p: p.stem)
def test_no_correct_submission_gets_a_pattern(path, tmp_path):
    from grader.grading.grade import GradeOptions, grade
    result = grade(path, tmp_path, GradeOptions(quick=True, only=("diagnosis",)), write_reports=False)
    assert result.status == GRADED
    assert {d.id for d in result.diagnoses} & PATTERN_IDS == set()
    assert {c.name: c.status for c in result.checks}["diagnosis"] == PASSED


@pytest.mark.slow
@pytest.mark.parametrize("name, title", [
    ("face-order-negative-first_lambdas_nearest", "あなたの面の番号は、バッファーの面の順と違う順になっています"),
    ("rotated-270-three-faces_u-flip_if-chain", "いくつかの面で、(u, v) が 90 度・180 度・270 度回転しています"),
])
def test_a_pattern_reads_the_same_in_privilege_drop_mode_and_in_japanese(privilege_drop, tmp_path, name, title):
    from grader import i18n
    from grader.grading.grade import GradeOptions, grade
    before = i18n.language()
    try:
        result = grade(ZOO / f"{name}.cpp", tmp_path / "out", GradeOptions(quick=True, lang="ja"))
    finally:
        i18n.set_language(before)
    assert result.isolation == "privilege-drop"
    missing, false = verdict(name, {(d.id, d.face) for d in result.diagnoses})
    assert not missing and not false, f"missing {missing}, false {false}"
    report = (tmp_path / "out" / "report.md").read_text()
    assert title in report and "面ごと" in report
    from test_i18n import english_sentences
    assert english_sentences(report, name) == []


def exact_share(out: Path) -> tuple[int, int, list[str]]:
    """(exact, total, lines) for a folder of reports written by
    `python -m grader grade --quick tests/submissions/patterns/*.cpp --out OUT`."""
    exact, lines = 0, []
    for name in NAMES:
        data = json.loads((out / name / "results.json").read_text())
        got = {(d["id"], d.get("face")) for d in data["extra_data"]["diagnoses"]}
        missing, false = verdict(name, got)
        exact += not missing and not false
        lines.append(f"{'exact' if not missing and not false else 'WRONG'}  {name}"
                     + (f"  missing {sorted(missing, key=str)}" if missing else "")
                     + (f"  false {sorted(false, key=str)}" if false else ""))
    return exact, len(NAMES), lines


if __name__ == "__main__":
    import sys
    exact, total, lines = exact_share(Path(sys.argv[1]))
    print("\n".join(lines) + f"\nexactly diagnosed: {exact} of {total}")
