"""Each check against a fake submission with one injected mistake (no compiler,
no worker: tests/helpers/fake_lookups.py), and the check runner's contract.

The zoo (test_grading_zoo.py) proves the same verdicts on real C++ in a
sandbox; these tests say which check is responsible for which verdict, in
milliseconds.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fake_lookups import FakeLookups
from grader.envmap import library
from grader.checks import CheckDefinitionError, Needs, all_checks, check, run_checks
from grader.checks.context import CheckContext
from grader.grading.results import ERROR, FAILED, PASSED, SKIPPED, CheckResult, Diagnosis
from project_paths import SUBMISSIONS
from cases import cases

CHECKS = all_checks()


def run(lookups, tmp_path, *names: str) -> dict[str, CheckResult]:
    """The named checks (and what they require, reported too) on `lookups`."""
    order = [c for c in CHECKS.values() if c.name in _with_prerequisites(names)]
    ctx = CheckContext(lookups=lookups, seed=1234, artifacts=tmp_path / "images", quick=True)
    return {r.name: r for r in run_checks(order, ctx, [c.name for c in order]).results}


def _with_prerequisites(names) -> set[str]:
    out, todo = set(), list(names)
    while todo:
        n = todo.pop()
        if n not in out:
            out.add(n)
            todo += CHECKS[n].prerequisites
    return out


def ids(result: CheckResult) -> set[tuple[str, str | None]]:
    return {(d.id, d.face) for d in result.diagnoses}


# ---- readTexture ------------------------------------------------------------

def test_a_correct_read_texture_passes(tmp_path):
    r = run(FakeLookups(), tmp_path, "read_texture")["read_texture"]
    assert (r.status, r.fraction, ids(r)) == (PASSED, 1.0, set())


@pytest.mark.parametrize("mistake, diagnosis", cases([
    ("nearest", "nearest-neighbor"),
    ("half-texel", "half-texel-offset"),
    ("size-minus-one", "scaled-by-size-minus-one"),
    ("u-flipped", "texture-u-flipped"),
    ("v-flipped", "texture-v-flipped"),
    ("uv-swapped", "texture-uv-swapped"),
], slow={"v-flipped-texture-v-flipped", "uv-swapped-texture-uv-swapped", "u-flipped-texture-u-flipped",
         "size-minus-one-scaled-by-size-minus-one"}))   # slow: a long fit each (6-28 s); the cheaper cases stay fast
def test_read_texture_names_its_mistake_and_fetch_color_keeps_its_points(tmp_path, mistake, diagnosis):
    results = run(FakeLookups(texture=mistake), tmp_path, "fetch_sweep", "diagnosis")
    texture = results["read_texture"]
    assert texture.status == FAILED and texture.fraction < 1.0
    assert ids(texture) == {(diagnosis, None)}
    # fetchColor is right: judged with readTexture's mistake allowed for.
    if mistake in ("nearest", "half-texel"):
        assert results["fetch_sweep"].fraction == 1.0, results["fetch_sweep"].output[:500]
        assert results["diagnosis"].status == PASSED, results["diagnosis"].output


# slow: checks on fake lookups whose readTexture no model fits, or fits only after a long search (6-28 s each); the cheaper cases of each family stay fast
@pytest.mark.slow
def test_an_out_of_bounds_read_is_attributed_to_read_texture(tmp_path):
    r = run(FakeLookups(texture="out-of-bounds"), tmp_path, "read_texture")["read_texture"]
    assert r.status == FAILED
    assert ("out-of-bounds-read", None) in ids(r)


# ---- fetchColor -------------------------------------------------------------

def test_a_correct_fetch_color_passes_every_mapping_check(tmp_path):
    results = run(FakeLookups(), tmp_path, "fetch_sweep", "diagnosis", "stability")
    for name in ("read_texture", "fetch_sweep", "diagnosis", "stability"):
        r = results[name]
        assert (r.status, r.fraction, ids(r)) == (PASSED, 1.0, set()), (name, r.output[:800])


@pytest.mark.parametrize("mistakes, expected", [
    ({"+X": "u-flipped"}, {("u-flipped", "+X")}),
    ({"+Z": "v-flipped"}, {("v-flipped", "+Z")}),
    ({"-Y": "uv-swapped"}, {("uv-swapped", "-Y")}),
    ({"+X": "wrong-face:-X", "-X": "wrong-face:+X"}, {("wrong-face", "+X"), ("wrong-face", "-X")}),
    ("not-normalized", {("not-divided-by-m", None)}),
    ("black", {("not-implemented", None)}),
])
def test_fetch_color_mistakes_are_named_per_face(tmp_path, mistakes, expected):
    results = run(FakeLookups(fetch=mistakes), tmp_path, "fetch_sweep", "diagnosis")
    assert results["read_texture"].status == PASSED        # readTexture is not blamed
    assert ids(results["diagnosis"]) == expected, results["diagnosis"].output
    assert results["fetch_sweep"].status == FAILED and results["fetch_sweep"].fraction < 1.0


def test_a_seam_is_found_where_one_face_is_flipped(tmp_path):
    r = run(FakeLookups(fetch={"+X": "u-flipped"}), tmp_path, "stability")["stability"]
    assert r.status == FAILED and ("discontinuous-seam", None) in ids(r)


def test_arrows_point_the_right_way_only_when_fetch_color_is_right(tmp_path):
    right = run(FakeLookups(), tmp_path / "a", "arrows")["arrows"]
    assert (right.status, right.fraction, ids(right)) == (PASSED, 1.0, set())
    swapped = run(FakeLookups(fetch={"+X": "wrong-face:-X", "-X": "wrong-face:+X"}), tmp_path / "b", "arrows")["arrows"]
    assert swapped.status == FAILED and {i for i, _ in ids(swapped)} <= {"arrow-wrong", "arrow-missing"} and ids(swapped)


# ---- one strict judge, whatever readTexture does (issue 18) -------------------

# slow: checks on fake lookups whose readTexture no model fits, or fits only after a long search (6-28 s each); the cheaper cases of each family stay fast
@pytest.mark.slow
def test_being_hard_to_model_buys_no_fetch_color_points(tmp_path):
    """readTexture wrong at one point only (no model fits it) and fetchColor
    half a texel off: fetchColor scores what it scores over the handout's
    readTexture (the old one-texel slack gave it the whole sweep)."""
    attack = run(FakeLookups(fetch="half-texel-u", texture="one-point"), tmp_path / "a", "fetch_sweep", "stability")
    control = run(FakeLookups(fetch="half-texel-u"), tmp_path / "b", "fetch_sweep", "stability")
    # Nothing proves a named mistake: one call in numbers instead.
    assert attack["read_texture"].diagnoses == [] and "yours reads no texel" in attack["read_texture"].output
    assert attack["fetch_sweep"].fraction < 0.1
    for name in ("fetch_sweep", "stability"):
        assert attack[name].fraction <= control[name].fraction, name


# slow: checks on fake lookups whose readTexture no model fits, or fits only after a long search (6-28 s each); the cheaper cases of each family stay fast
@pytest.mark.slow
def test_a_fetch_color_that_reads_its_texels_itself_is_said_to_and_judged_end_to_end(tmp_path):
    """fetchColor reads its texels itself (correctly) while readTexture,
    called alone, always crashes: the record shows no readTexture call, the
    colours are judged end to end, right, and the report says so (issue 29)."""
    results = run(FakeLookups(texture="crash-alone"), tmp_path, "fetch_sweep")
    assert results["fetch_sweep"].fraction == 1.0
    assert "made no readTexture call" in results["fetch_sweep"].output
    assert results["fetch_sweep"].metrics["reads_itself"] == results["fetch_sweep"].metrics["cases"]


class _SwapsOnYWhenCalledAlone(FakeLookups):
    """issue 18's red team (believed_on_two_faces.cpp): readTexture called on
    its own swaps u and v on +Y and -Y, as fetchColor wrongly reads them
    (fetchColor's own reads go through the handout's readTexture)."""

    def read_texture(self, face, uv, placement="end"):
        uv = np.asarray(uv, np.float64).reshape(-1, 2)
        return super().read_texture(face, uv[:, ::-1] if face in (2, 3) else uv, placement)


class _PaysToBeBelieved(FakeLookups):
    """issue 18's red team (pays_to_be_believed.cpp): readTexture called on
    its own is black for 0.35 <= u < 0.5 on the readTexture check's faces
    (some 13% of its calls) and at 1 - v on the sweep's 32 x 32 faces, as
    fetchColor wrongly reads them."""

    def read_texture(self, face, uv, placement="end"):
        uv = np.asarray(uv, np.float64).reshape(-1, 2)
        if self.faces.shape[1:3] == (32, 32):
            return super().read_texture(face, np.stack([uv[:, 0], 1 - uv[:, 1]], 1), placement)
        out = super().read_texture(face, uv, placement)
        out.values[(uv[:, 0] >= 0.35) & (uv[:, 0] < 0.5)] = 0.0
        return out


@pytest.mark.parametrize("attack, control", [
    (_SwapsOnYWhenCalledAlone(fetch={"+Y": "uv-swapped", "-Y": "uv-swapped"}),
     FakeLookups(fetch={"+Y": "uv-swapped", "-Y": "uv-swapped"})),
    (_PaysToBeBelieved(fetch={f: "v-flipped" for f in library.FACE_NAMES}),
     FakeLookups(fetch={f: "v-flipped" for f in library.FACE_NAMES})),
], ids=["acts-on-faces-the-check-never-read", "pays-a-little-readtexture"])
# slow: checks on fake lookups whose readTexture no model fits, or fits only after a long search (6-28 s each); the cheaper cases of each family stay fast
@pytest.mark.slow
def test_a_read_texture_answering_the_judge_otherwise_buys_no_fetch_color_points(tmp_path, attack, control):
    """What readTexture answers when called alone (a face the check never
    read, a few black answers paid in the check) plays no part in judging
    fetchColor: it is judged on the record of its own calls
    (instruments.fetch_record), so the attack scores exactly the control."""
    a = run(attack, tmp_path / "a", "fetch_sweep")
    c = run(control, tmp_path / "c", "fetch_sweep")
    assert a["read_texture"].status == FAILED or a["read_texture"].fraction < 1.0
    assert a["fetch_sweep"].fraction == c["fetch_sweep"].fraction < 1.0


def test_robustness_needs_a_working_lookup(tmp_path):
    """Black never crashes, but earns no robustness points (as for speed):
    what it finds is said, and it can earn none of it."""
    r = run(FakeLookups(fetch="black"), tmp_path, "stability")["stability"]
    assert r.status == FAILED and r.fraction > 0.0 and r.credit == 0.0
    assert "nothing up to 30%" in r.output and "Your sweep: 0.00% right" in r.output


# ---- fetchColor described from its record, whatever readTexture does (issue 29) -----------

def test_fetch_color_is_analysed_when_read_texture_is_almost_right(tmp_path):
    """readTexture wrong at one point only: fetchColor's flip is named from
    the record, which never asks readTexture."""
    r = run(FakeLookups(fetch={"+X": "u-flipped"}, texture="one-point"), tmp_path, "diagnosis")["diagnosis"]
    assert ids(r) == {("u-flipped", "+X")}, r.output


def test_an_inset_is_named_once_and_orientation_is_told_under_it(tmp_path):
    from grader.checks.instruments.face_map import analyse
    fake = FakeLookups(fetch="inset")
    r = run(fake, tmp_path, "diagnosis")["diagnosis"]
    assert ids(r) == {("uv-inset", None)}, r.output
    analysis = analyse(fake, quick=True)
    for v in analysis.faces:
        assert v.affine is not None and v.affine.orientation_ids == []
        assert abs(v.affine.scale[0] - 29 / 32) < 0.01 and abs(v.affine.offset[0] * 32 - 1.5) < 0.1


def test_fetch_color_is_described_over_a_scrambled_read_texture(tmp_path):
    """A scrambled readTexture still leaves what fetchColor asked on the
    record: the inset is found, and nothing is said to be unclamped."""
    results = run(FakeLookups(fetch="inset", texture="scrambled"), tmp_path, "diagnosis")
    assert ("uv-inset", None) in ids(results["diagnosis"]), results["diagnosis"].output
    texture = results["read_texture"]
    # Its footprint proves one thing only: every probe reads one texel.
    assert "At u = " in texture.output and "not clamped" not in texture.output
    assert ("nearest-neighbor", None) in ids(texture)
    assert {d for d in ids(texture) if d[0] not in ("nearest-neighbor",)} == set(), ids(texture)


def test_a_constant_read_texture_leaves_fetch_color_analysed(tmp_path):
    """readTexture black everywhere: fetchColor's recorded requests are
    answered by the handout's readTexture, so its flip is still named
    (issue 29; before, nothing could be said)."""
    r = run(FakeLookups(fetch={"+X": "u-flipped"}, texture="black"), tmp_path, "diagnosis")["diagnosis"]
    assert ids(r) == {("u-flipped", "+X")}, r.output


def test_speed_is_not_timed_for_a_lookup_that_returns_black(tmp_path):
    results = run(FakeLookups(fetch="black"), tmp_path, "speed")
    assert results["speed"].status == SKIPPED and results["speed"].fraction == 0.0
    assert "more than 30%" in results["speed"].output


# ---- the runner's contract --------------------------------------------------

def _registry():
    registry: dict = {}

    @check(registry=registry)
    def producer(ctx, result):
        """Produces a number."""
        result.status, result.fraction = FAILED, 0.5
        return 7

    @check(requires=(producer,), registry=registry)
    def consumer(ctx, result, number):
        """Uses it."""
        result.output = f"got {number}"
        return number * 2

    @check(requires=(Needs(producer, passing=lambda n: n > 10, why="the number must exceed 10."),), registry=registry)
    def picky(ctx, result, number):
        """Needs a large number."""

    @check(registry=registry)
    def broken(ctx, result):
        """Fails inside the harness."""
        result.diagnoses.append(Diagnosis("crash", "half-written"))
        raise KeyError("a bug in the grader")

    @check(requires=(broken,), registry=registry)
    def after_broken(ctx, result, value):
        """Depends on the broken one."""

    return registry


def test_findings_are_passed_typed_and_a_failed_prerequisite_still_hands_its_finding_over(tmp_path):
    registry = _registry()
    results = {r.name: r for r in run_checks(list(registry.values()), None).results}
    assert results["producer"].status == FAILED
    assert results["consumer"].status == PASSED and results["consumer"].output == "got 7"
    assert results["consumer"].title == "Uses it."


def test_a_dependent_is_skipped_with_a_reason_when_its_condition_fails(tmp_path):
    results = {r.name: r for r in run_checks(list(_registry().values()), None).results}
    assert results["picky"].status == SKIPPED and results["picky"].output == "Not run: the number must exceed 10."


def test_a_harness_error_shows_no_traceback_to_the_student_and_skips_dependents():
    results = {r.name: r for r in run_checks(list(_registry().values()), None).results}
    broken = results["broken"]
    assert broken.status == ERROR and broken.diagnoses == []
    assert "Traceback" not in broken.output and "KeyError" not in broken.output
    assert "KeyError: 'a bug in the grader'" in broken.error_log
    after = results["after_broken"]
    assert after.status == SKIPPED and "Fails inside the harness." in after.output


def test_unselected_prerequisites_run_but_are_not_reported():
    registry = _registry()
    run = run_checks(list(registry.values()), None, ["consumer"])
    assert [r.name for r in run.results] == ["consumer"] and run.hidden_runs == ["producer"]
    assert run.results[0].output == "got 7"


def test_a_requirement_that_is_not_a_check_is_refused_at_definition():
    with pytest.raises(CheckDefinitionError, match="not a @check function"):
        @check(requires=(len,), registry={})
        def odd(ctx, result, x):
            """Odd."""


# ---- end-to-end checks in both process states --------------------------------

class TwoStates:
    """A context whose fetchColor answers otherwise (or not) in a process whose
    first faces they are: what instruments.process_state observed, given."""

    def __init__(self, tmp_path, depends: bool):
        from grader.checks.instruments.process_state import StateProbe
        dirs = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
        first, after = np.array([[0.2, 0.2, 0.2], [0.5, 0.5, 0.5]]), np.array([[0.8, 0.2, 0.2], [0.5, 0.5, 0.5]])
        self.probe = StateProbe(dirs, first, after, np.array([True, True]), np.array([depends, False]))
        self.lookups, self.seed, self.artifacts, self.first_faces = object(), 1, tmp_path, False
        self.probed = 0

    def states(self):
        self.probed += 1
        return self.probe


def _state_registry(seen: list):
    registry: dict = {}

    @check(registry=registry, end_to_end=True)
    def whole_map(ctx, result):
        """Looks at a whole map."""
        seen.append((ctx.first_faces, ctx.artifacts.name))
        result.status = FAILED if ctx.first_faces else PASSED
        result.fraction = 0.25 if ctx.first_faces else 1.0
        return "first" if ctx.first_faces else "after"

    @check(registry=registry)
    def not_whole(ctx, result):
        """Looks at directions alone."""
        result.fraction = 1.0

    return registry


@pytest.mark.parametrize("depends", [True, False])
def test_an_end_to_end_check_counts_the_lower_of_both_states_where_answers_differ(tmp_path, depends):
    seen: list = []
    ctx = TwoStates(tmp_path, depends)
    results = {r.name: r for r in run_checks(list(_state_registry(seen).values()), ctx).results}
    if depends:
        # Run again with each lookup in a fresh worker, its pictures apart; the lower kept, the observation said.
        assert seen == [(False, tmp_path.name), (True, "first-faces")]
        assert results["whole_map"].fraction == 0.25 and results["whole_map"].status == FAILED
        (said,) = results["whole_map"].diagnoses
        assert said.id == "fetch-depends-on-earlier-faces" and "1 of 2 directions" in said.detail
        assert "(0.2, 0.2, 0.2) first and (0.8, 0.2, 0.2) after" in said.detail
    else:
        assert seen == [(False, tmp_path.name)] and results["whole_map"].fraction == 1.0
    assert results["not_whole"].diagnoses == [] and ctx.first_faces is False


def test_the_state_an_end_to_end_check_scores_better_in_is_not_kept(tmp_path):
    """A size kept from the first call (pattern 12) is wrong after the prelude
    and right first: the prelude's lower score stays, with its own diagnoses."""
    registry: dict = {}

    @check(registry=registry, end_to_end=True)
    def whole_map(ctx, result):
        """Looks at a whole map."""
        result.fraction = 1.0 if ctx.first_faces else 0.5
        if not ctx.first_faces:
            result.diagnoses.append(Diagnosis("address-not-face-start", "a size kept"))

    (result,) = run_checks(list(registry.values()), TwoStates(tmp_path, True)).results
    assert result.fraction == 0.5 and [d.id for d in result.diagnoses] == ["address-not-face-start"]


class MapDependent:
    """A context whose fetchColor asks otherwise on the public maps (or not):
    what instruments.map_probe observed, given."""

    def __init__(self, tmp_path, depends: bool):
        self.depends = depends
        self.lookups, self.seed, self.artifacts, self.first_faces = "the worker", 1, tmp_path, False
        self.probed = 0

    def map_probe(self):
        self.probed += 1
        return self

    def diagnosis(self):
        return Diagnosis("fetch-depends-on-the-map", "asked otherwise on a public map")

    def random_face_requests(self):
        from grader.checks.instruments.map_probe import RandomFaceRequests
        return RandomFaceRequests(self.lookups, self.seed)


@pytest.mark.parametrize("depends", [True, False])
def test_a_check_on_the_public_maps_counts_the_lower_with_random_face_requests_where_they_differ(tmp_path, depends):
    from grader.checks.instruments.map_probe import RandomFaceRequests
    registry: dict = {}
    seen: list = []

    @check(registry=registry, end_to_end=True, public_maps=True)
    def on_maps(ctx, result):
        """Looks up the public maps."""
        requests = isinstance(ctx.lookups, RandomFaceRequests)
        seen.append((requests, ctx.artifacts.name))
        result.fraction = 0.5 if requests else 0.75

    @check(registry=registry, end_to_end=True)
    def on_own_faces(ctx, result):
        """Looks up faces of its own."""
        seen.append((isinstance(ctx.lookups, RandomFaceRequests), ctx.artifacts.name))
        result.fraction = 1.0

    ctx = MapDependent(tmp_path, depends)
    results = {r.name: r for r in run_checks(list(registry.values()), ctx).results}
    assert ctx.probed == 1      # asked for the check on the public maps only
    if depends:
        assert seen == [(False, tmp_path.name), (True, "random-face-requests"), (False, tmp_path.name)]
        assert results["on_maps"].fraction == 0.5
        assert [d.id for d in results["on_maps"].diagnoses] == ["fetch-depends-on-the-map"]
        # The run kept says first what it is: its numbers and pictures are not the lookup on the maps.
        assert results["on_maps"].output.startswith("What follows (numbers and pictures) is this check's run on what")
    else:
        assert seen == [(False, tmp_path.name), (False, tmp_path.name)] and results["on_maps"].fraction == 0.75
    assert results["on_own_faces"].diagnoses == [] and ctx.lookups == "the worker"


# ---- worker failures and the whole pipeline on the fake ---------------------

@pytest.mark.parametrize("kind", ["crash", "exited", "protocol", "load-error", "out-of-bounds-read", "timeout"])
def test_a_worker_failure_reaches_the_student_under_its_own_id(kind):
    from grader.checks.context import failure_diagnoses
    from grader.grading.catalogue import CATALOGUE
    from grader.worker.runner import Failure
    failure = Failure(kind, "fetchColor", 3, "fetchColor(Vector3(1, 0, 0))", "it happened", "do this")
    [d] = failure_diagnoses([failure])
    assert d.id == kind and d.id in CATALOGUE and d.hint == "do this"


def test_grade_reports_the_runner_isolation_and_warnings(tmp_path, monkeypatch, correct_build):
    """grade() copies what the runner says about isolation; the checks see only the lookups."""
    import contextlib

    from grader.grading import grade as grade_module
    fake = FakeLookups(fetch={"+X": "u-flipped"})
    fake.isolation, fake.warnings = "privilege-drop", ["no bubblewrap here: ran as an unprivileged user"]
    monkeypatch.setattr(grade_module, "_open_lookups", lambda library, options: contextlib.nullcontext(fake))
    source = sorted((SUBMISSIONS / "correct").glob("*.cpp"))[0]
    result = grade_module.grade(source, tmp_path, grade_module.GradeOptions(
        quick=True, only=("read_texture", "fetch_sweep", "diagnosis")), write_reports=False)
    assert result.isolation == "privilege-drop"
    assert "no bubblewrap here: ran as an unprivileged user" in result.warnings
    assert [c.name for c in result.checks] == ["read_texture", "fetch_sweep", "diagnosis"]
    assert {(d.id, d.face) for d in result.diagnoses} == {("u-flipped", "+X")}


def test_grade_refuses_a_check_name_the_rubric_does_not_have(tmp_path):
    from grader.grading.grade import GradeOptions, grade
    from grader.grading.score import RubricError
    with pytest.raises(RubricError, match="no such check: fetch_swep"):
        grade(Path("nowhere.cpp"), tmp_path, GradeOptions(only=("fetch_swep",), allow_stale=True))


@pytest.mark.sandbox
def test_the_fake_answers_like_a_real_correct_submission_in_its_worker(correct_build, rng):
    """The fake is a faithful stand-in: same colours as compiled C++ in the worker."""
    from grader.checks.instruments.textures import random_faces
    from grader.worker.lookups import open_lookups
    faces = random_faces(9, 7, 5)
    dirs = rng.normal(size=(2000, 3))
    uv = rng.random((500, 2))
    fake = FakeLookups()
    fake.set_faces(faces)
    with open_lookups(correct_build.library) as real:
        real.set_faces(faces)
        np.testing.assert_allclose(real.fetch(dirs).values, fake.fetch(dirs).values, atol=1e-5)
        np.testing.assert_allclose(real.read_texture(5, uv).values, fake.read_texture(5, uv).values, atol=1e-5)


def test_worst_cases_say_where_the_lookup_landed(tmp_path):
    """fetch_sweep hands reports its worst cases as data: face, texel and (u, v)."""
    sweep = run(FakeLookups(fetch={"+X": "u-flipped"}), tmp_path, "fetch_sweep")["fetch_sweep"]
    from grader.checks.instruments.directions import RANDOM_SET
    scored = {group: n for group, n in sweep.mismatch_counts.items() if group != RANDOM_SET}
    assert sweep.mismatches and sum(scored.values()) == sweep.metrics["cases"] - sweep.metrics["matched"] > 0
    for m in sweep.mismatches:
        assert m.call.startswith("fetchColor(Vector3(") and m.group in sweep.mismatch_counts
        assert m.expected_at.face == m.got_at.face == "+X"
        # u flipped: the two samples mirror each other across the face's middle; v agrees.
        assert m.expected_at.uv[0] + m.got_at.uv[0] == pytest.approx(1.0, abs=2 / 32)
        assert m.expected_at.uv[1] == pytest.approx(m.got_at.uv[1], abs=1e-6)


def test_a_harness_error_leaves_its_traceback_for_the_instructor_only(tmp_path, monkeypatch, correct_build):
    import contextlib

    from grader.grading import grade as grade_module

    def broken(*args, **kwargs):
        raise ZeroDivisionError("the grader's own bug")   # the real runner reports student faults as Outcomes
    fake = FakeLookups()
    fake.read_texture = broken
    monkeypatch.setattr(grade_module, "_open_lookups", lambda library, options: contextlib.nullcontext(fake))
    source = sorted((SUBMISSIONS / "correct").glob("*.cpp"))[0]
    result = grade_module.grade(source, tmp_path, grade_module.GradeOptions(quick=True, only=("read_texture",)))
    assert result.status == "ungradable" and result.checks[0].status == ERROR
    log = (tmp_path / grade_module.HARNESS_LOG).read_text()
    assert "ZeroDivisionError: the grader's own bug" in log and "Traceback" in log
    for name in ("report.md", "report.html", "results.json", "junit.xml"):
        text = (tmp_path / name).read_text()
        assert "ZeroDivisionError" not in text and "Traceback" not in text, name


# ---- speed: a failure on rare inputs is not a draw's luck (issue 30) ----------

class FailsSomeRounds(FakeLookups):
    """A correct lookup whose first `failing` timed rounds fail at one lookup
    with a broken reply (as runtime_attacks/forged_reply.cpp does near +x)."""

    def __init__(self, failing: int):
        super().__init__()
        self.failing = failing

    def time_fetch(self, passes, repeats: int = 1):
        from grader.worker.runner import Failure, TimedPasses
        if self.failing > 0:
            self.failing -= 1
            return TimedPasses(failure=Failure("protocol", "fetchColor", 7, "fetchColor(Vector3(1, 0, 0))",
                                               "the reply broke the protocol", ""))
        return super().time_fetch(passes, repeats)


def test_speed_draws_again_rounds_that_failed_at_a_rare_input(tmp_path):
    from grader.checks.speed import REDRAWS
    speed = run(FailsSomeRounds(failing=4), tmp_path, "speed")["speed"]
    assert speed.status == PASSED and speed.score == speed.max_score, speed.output
    assert "4 timed rounds failed at some lookup" in speed.output and REDRAWS >= 4


def test_speed_fails_a_lookup_that_fails_every_round_after_its_redraws(tmp_path):
    from grader.checks.speed import REDRAWS
    lookups = FailsSomeRounds(failing=10 ** 6)
    speed = run(lookups, tmp_path, "speed")["speed"]
    assert speed.status == FAILED and speed.fraction == 0.0 and ids(speed) == {("protocol", None)}, speed.output
    assert lookups.failing == 10 ** 6 - REDRAWS - 1
