"""The grader's verdicts on a zoo of submissions: every correct one gets full
marks and no diagnosis; every wrong one loses points where its mistake is,
keeps them where it is not, and gets exactly the diagnoses that name it.

The expectations are written from what each mistake is (see the comment at
the top of each file in tests/submissions/wrong/), not from grader output.
"""
import json
import re
from pathlib import Path

import numpy as np
import pytest

from grader.grading import fixtures
from grader.envmap import library
from grader.grading.grade import GradeOptions, grade
from grader.grading.results import BUILD_ERROR, GRADED, TIMEOUT
from grading_cache import grade_once
from project_paths import PROJECT_ROOT, SUBMISSIONS
from cases import cases

HERE = SUBMISSIONS
CORRECT = sorted((HERE / "correct").glob("*.cpp")) + sorted((HERE / "correct_lead").glob("*.cpp"))
MAPPING, FILTER = "fetch_sweep", "read_texture"

# name: (exact diagnoses as (id, face or None), checks that must lose points,
#        checks that must keep full points, overall status)
ZOO = {
    "u-flipped-pos-x": ({("u-flipped", "+X")}, {MAPPING}, {FILTER, "speed"}, GRADED),
    "v-flipped-pos-z": ({("v-flipped", "+Z")}, {MAPPING}, {FILTER, "speed"}, GRADED),
    "uv-swapped-neg-y": ({("uv-swapped", "-Y")}, {MAPPING}, {FILTER, "speed"}, GRADED),
    "wrong-face-x-swapped": ({("wrong-face", "+X"), ("wrong-face", "-X")}, {MAPPING, "arrows"}, {FILTER}, GRADED),
    "combo-swapped-and-flipped": ({("wrong-face", "+Y"), ("wrong-face", "-Y"), ("v-flipped", "+X")},
                                  {MAPPING, "arrows"}, {FILTER}, GRADED),
    # Dividing by the length (or by nothing) also breaks tiny/huge directions; the same direction
    # asked at lengths a power of two apart shows it in two calls (length-dependent, issue 29).
    "not-normalized-length": ({("not-divided-by-m", None), ("nan-output", None), ("length-dependent", None)},
                              {MAPPING, "stability"}, {FILTER}, GRADED),
    # Its NaN came from its readTexture given u = 5e307 (floor of inf): fetchColor asks a finite (u, v) and
    # returns what it is given (issue 29: judged as if readTexture were the handout's); the cause stays named.
    "not-normalized-unit": ({("not-divided-by-m", None), ("length-dependent", None)}, {MAPPING}, {FILTER}, GRADED),
    # readTexture mistakes: fetchColor is judged on its own and keeps its points.
    "nearest-neighbor": ({("nearest-neighbor", None)}, {FILTER, "renders"}, {MAPPING, "arrows", "stability"}, GRADED),
    "half-texel-offset": ({("half-texel-offset", None)}, {FILTER, "renders"}, {MAPPING, "arrows", "stability"}, GRADED),
    "weights-swapped": ({("weights-swapped", None)}, {FILTER, "renders"}, {MAPPING, "arrows", "stability"}, GRADED),
    "scaled-by-size-minus-one": ({("scaled-by-size-minus-one", None)}, {FILTER, "renders"}, {MAPPING, "arrows"}, GRADED),
    # Runtime failures are attributed, and cost only what they touch.
    # x1 = x0 + 1 unclamped: the cause (unclamped-edge) is named beside what it does.
    # fetchColor is right and is judged on what it asks readTexture (issue 29): readTexture's read
    # past the face is its own check's (out-of-bounds-read), no longer a crash of fetchColor's checks.
    "out-of-bounds-x1": ({("out-of-bounds-read", None), ("unclamped-edge", None)}, {FILTER}, set(), GRADED),
    # Every direction toward -Z crashes: that face is listed as not analysed, never dropped.
    "crash-null": ({("crash", None), ("face-not-analysed", "-Z")}, {MAPPING}, {FILTER}, GRADED),
    "timeout-loop": ({("timeout", None)}, {"stability"}, {FILTER, "renders"}, TIMEOUT),
    "nan-huge": ({("nan-output", None), ("length-overflow", None), ("length-dependent", None)}, {"stability"},
                 {FILTER, MAPPING, "renders", "arrows"}, GRADED),
    "slow": ({("slow", None)}, {"speed"}, {FILTER, MAPPING, "renders", "arrows", "stability"}, GRADED),
    "syntax-error": ({("build-error", None)}, {FILTER, MAPPING}, set(), BUILD_ERROR),
}


# fetchColor mistakes confined to some faces: the renders check keeps about
# the share of the (quick) render's pixels those faces do not reach (it used
# to give 0 for any visible mistake). Written from the faces each mistake
# touches; the share is computed below from the scene, not from the grader.
RENDER_FACES = {
    "u-flipped-pos-x": ("+X",),
    "v-flipped-pos-z": ("+Z",),
    "uv-swapped-neg-y": ("-Y",),
    "wrong-face-x-swapped": ("+X", "-X"),
    "combo-swapped-and-flipped": ("+X", "+Y", "-Y"),
}


def not_reached(faces) -> float:
    """Share of pixels of the quick render (the first fixture) that get no
    light from `faces`: black in a render with those faces white, the rest black."""
    fixture = fixtures.render_fixtures()[0]
    escapes = fixtures.prepared_scene(fixture).trace()
    only = np.zeros((6, 4, 4, 3), np.float32)
    for name in faces:
        only[library.FACE_NAMES.index(name)] = 1.0
    reach = escapes.resolve(library.CubeMap(only).fetch(escapes.dirs, "bilinear")).max(axis=2)
    return float((reach <= 0.0).mean())


def test_every_zoo_file_has_an_expectation():
    assert {p.stem for p in (HERE / "wrong").glob("*.cpp")} == set(ZOO)


@pytest.mark.parametrize("path", cases(CORRECT, ids=lambda p: p.stem, representative={"if_chain", "float_math"}))
def test_correct_submissions_get_full_marks_and_no_diagnosis(path, tmp_path):
    result = grade_once(path, tmp_path, GradeOptions(quick=True))
    assert result.status == GRADED
    assert [d.id for d in result.diagnoses] == []
    assert result.score == result.max_score == 100, [(c.name, c.score, c.output[:300]) for c in result.checks if c.score < c.max_score]


@pytest.mark.parametrize("name", cases(sorted(ZOO), representative={"v-flipped-pos-z", "half-texel-offset", "crash-null",
                                                                   "syntax-error"}))
def test_wrong_submission_is_diagnosed(name, tmp_path):
    diagnoses, loses, keeps, status = ZOO[name]
    result = grade_once(HERE / "wrong" / f"{name}.cpp", tmp_path, GradeOptions(quick=True))
    assert result.status == status
    assert {(d.id, d.face) for d in result.diagnoses} == diagnoses
    by_name = {c.name: c for c in result.checks}
    assert all(by_name[c].score < by_name[c].max_score for c in loses), {c: by_name[c].score for c in loses}
    assert all(by_name[c].score == by_name[c].max_score for c in keeps), {c: by_name[c].score for c in keeps}
    assert result.score < result.max_score
    if name in RENDER_FACES:
        share, renders = not_reached(RENDER_FACES[name]), by_name["renders"]
        # Never more than FLIP's spread of an error below the share; above
        # it, where the faces' wrong texels happen to look like the right ones.
        assert renders.max_score * (share - 0.03) <= renders.score <= renders.max_score * min(share + 0.1, 0.999), \
            (renders.score, share)
    # The report was written, and results.json lists the same diagnoses.
    data = json.loads((tmp_path / "results.json").read_text())
    assert {(d["id"], d.get("face")) for d in data["extra_data"]["diagnoses"]} == diagnoses


def _without_timings(text: str) -> str:
    text = re.sub(r'"execution_time": [0-9.e+-]+', "", text)
    text = re.sub(r'time="[0-9.]+"', "", text)
    return re.sub(r"\d+(\.\d+)? ns|\d+\.\d+x", "#", text)


def test_grading_twice_gives_the_same_score_and_reports(tmp_path):
    path = HERE / "wrong" / "u-flipped-pos-x.cpp"
    first = grade(path, tmp_path / "a", GradeOptions())
    second = grade(path, tmp_path / "b", GradeOptions())
    assert first.score == second.score
    for name in ("results.json", "report.md", "junit.xml"):
        a = _without_timings((tmp_path / "a" / name).read_text())
        b = _without_timings((tmp_path / "b" / name).read_text())
        assert a == b, name


@pytest.mark.representative
def test_the_untouched_template_scores_nothing_and_says_why(tmp_path):
    """Nothing for the starting code (issue 30): returning black earns no
    fetchColor, arrow, robustness, render or speed points (it never crashes,
    but robustness needs a lookup that works, as speed does), and the
    starting readTexture earns nothing either: 0 on every check, and why."""
    result = grade(PROJECT_ROOT / "student_template" / "EnvironmentMap.cpp", tmp_path,
                   GradeOptions(quick=True))
    assert {d.id for d in result.diagnoses} == {"not-implemented", "nearest-neighbor"}
    assert {c.name: c.score for c in result.checks} == {c.name: 0.0 for c in result.checks}
    assert result.score == 0 and result.max_score == 100
