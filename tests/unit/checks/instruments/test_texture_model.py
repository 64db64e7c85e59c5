"""The readTexture model family, without a compiler: the handout's member
agrees with the C reference, and a fake lookup built from each member (one
injected mistake, and some combinations) is fitted back to a member that
names the same mistakes. Behaviour the probes cannot see (truncation where
p is never negative) is not asked for."""
from dataclasses import replace

import numpy as np
import pytest

from grader.envmap import library
from grader.checks.instruments import texture_model as tm
from grader.checks.instruments.textures import coordinate_faces, random_faces

A = tm.Axis


def both(**parts) -> tm.TextureModel:
    return tm.TextureModel(A(**parts), A(**parts))


def test_the_handout_member_agrees_with_the_reference_bilinear_and_nearest():
    faces = random_faces(13, 7, 3)
    cube = library.CubeMap(faces)
    rng = np.random.default_rng(1)
    uv = np.concatenate([rng.random((4000, 2)), np.stack(np.meshgrid(np.arange(14) / 13, np.arange(8) / 7), -1).reshape(-1, 2),
                         [[0, 0], [1, 1], [0, 1], [1, 0], [1 - 1e-12, 0.5]]])
    for face in (0, 5):
        got, past = tm.evaluate(tm.HANDOUT, faces[face], uv)
        assert not past.any()
        np.testing.assert_allclose(got, cube.read_texture(face, uv, "bilinear"), rtol=0, atol=1e-12)
        got, _ = tm.evaluate(both(weights="nearest"), faces[face], uv)
        np.testing.assert_array_equal(got, cube.read_texture(face, uv, "nearest"))


def test_an_unclamped_index_reads_the_next_row_then_faults_past_the_face():
    faces = coordinate_faces(4, 3)
    model = both(weights="nearest", edge="none", offset=1.0)
    got, past = tm.evaluate(model, faces[0], np.array([[3.2 / 4, 0.1 / 3], [3.2 / 4, 2.1 / 3], [0.0, 0.0]]))
    np.testing.assert_array_equal(got[0], [1, 3, 1])       # x = 4 on row 1 is (0, 2)
    assert past.tolist() == [False, True, False]
    got, past = tm.evaluate(both(weights="nearest", edge="none", offset=-1.0), faces[0], np.array([[0.0, 0.0]]))
    np.testing.assert_array_equal(got[0], [0, 0, 0])       # before the face: the zero-filled page


# (member, the ids its fit must name)
MEMBERS = {
    "handout": (tm.HANDOUT, []),
    "nearest": (both(weights="nearest"), ["nearest-neighbor"]),
    "weights-swapped": (both(weights="swapped"), ["weights-swapped"]),
    "constant-weights": (both(weights="half"), ["constant-weights"]),
    "half-texel": (both(offset=-0.5), ["half-texel-offset"]),
    "half-texel-plus": (both(offset=0.5), ["half-texel-offset"]),
    "texel-offset-clamped": (both(offset=-1.0), ["texel-offset"]),
    "texel-offset-unclamped": (both(offset=-1.0, edge="none"), ["texel-offset", "unclamped-edge"]),
    "texel-offset-plus": (both(offset=1.0), ["texel-offset"]),
    "half-texel-truncated": (both(offset=-0.5, rounding="trunc"), ["half-texel-offset", "truncation-of-negatives"]),
    "nearest-rounded": (both(weights="nearest", rounding="round"), ["nearest-neighbor", "half-texel-offset"]),
    "unclamped-nearest": (both(weights="nearest", edge="none"), ["nearest-neighbor", "unclamped-edge"]),
    "unclamped-bilinear": (both(edge="none"), ["unclamped-edge"]),
    "wrapped": (both(edge="wrap"), ["wrapped-edge"]),
    "scale-w-minus-1": (both(scale="N-1"), ["scaled-by-size-minus-one"]),
    "scale-w-plus-1": (both(scale="N+1"), ["scaled-by-size-plus-one"]),
    "nearest-w-minus-1": (both(weights="nearest", scale="N-1"), ["nearest-neighbor", "scaled-by-size-minus-one"]),
    "unclamped-w-minus-1-offset": (both(scale="N-1", offset=-1.0, edge="none"),
                                   ["texel-offset", "unclamped-edge", "scaled-by-size-minus-one"]),
    "rows-flipped": (tm.TextureModel(A(), A(flip="index")), ["rows-flipped"]),
    "v-flipped": (tm.TextureModel(A(), A(flip="coordinate")), ["texture-v-flipped"]),
    "u-flipped": (tm.TextureModel(A(flip="coordinate"), A()), ["texture-u-flipped"]),
    "columns-flipped": (tm.TextureModel(A(flip="index"), A()), ["columns-flipped"]),
    "wh-swapped": (both(size="other"), ["width-height-swapped"]),
    "uv-swapped": (both(source="other"), ["texture-uv-swapped"]),
    "rows-flipped-w-minus-1-half-truncated": (
        tm.TextureModel(A(scale="N-1", offset=-0.5, rounding="trunc"), A(scale="N-1", offset=-0.5, rounding="trunc", flip="index")),
        ["half-texel-offset", "truncation-of-negatives", "scaled-by-size-minus-one", "rows-flipped"]),
}


# The members fitted back in `make test-fast`: one for each part of the
# family (weights, offset with rounding, edge, index flip, coordinate source);
# each fit is a search of seconds. `make test-all` fits every member.
FAST_MEMBERS = {"handout", "nearest", "half-texel-truncated", "unclamped-bilinear", "rows-flipped", "uv-swapped"}


def cases(names, fast):
    return [n if n in fast else pytest.param(n, marks=pytest.mark.slow) for n in names]


@pytest.mark.parametrize("name", cases(sorted(MEMBERS), FAST_MEMBERS))
def test_a_fake_lookup_is_fitted_back_to_its_member(name):
    model, ids = MEMBERS[name]
    found = tm.fit(tm.fake_read_texture(model))
    assert found.fits, (found.closest, found.share)
    assert sorted(tm.mistake_ids(found.model)) == sorted(ids)
    # The fitted member answers exactly as the fake on fresh points.
    faces = random_faces(9, 5, 7)[1]
    uv = np.random.default_rng(2).random((500, 2))
    a, b = tm.evaluate(model, faces, uv)[0], tm.evaluate(found.model, faces, uv)[0]
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-9)


def test_a_lookup_outside_the_family_is_not_forced_into_it():
    def squared(face, uv, faces):        # p = (u^2 W, v H): no member does this
        return tm.evaluate(tm.HANDOUT, faces[face], np.stack([uv[:, 0] ** 2, uv[:, 1]], 1))[0]
    found = tm.fit(squared)
    assert not found.fits and 0 < found.share < 1


def test_a_constant_lookup_is_reported_as_such():
    found = tm.fit(lambda face, uv, faces: np.ones((len(uv), 3)))
    assert found.constant and not found.fits


@pytest.mark.parametrize("model", [
    tm.TextureModel(A(offset=-0.5), A(flip="index")),
    # slow: 2 s each; the first model stays fast
    pytest.param(tm.TextureModel(A(edge="none", scale="N-1"), A(rounding="trunc", offset=-1.0)), marks=pytest.mark.slow),
    pytest.param(tm.TextureModel(A(weights="nearest", source="other"), A(edge="wrap", flip="coordinate")),
                 marks=pytest.mark.slow),
    pytest.param(tm.TextureModel(A(weights="half", size="other"), A(weights="swapped", scale="N+1", rounding="round")),
                 marks=pytest.mark.slow),
], ids=["half-texel_rows", "unclamped-w-1_trunc-1", "nearest-swapped_wrap-1-v", "half-wh_swapped-round"])
def test_the_fits_batched_axis_judge_equals_judging_each_axis(model):
    """The fit ranks all 6,480 axis models with all_mismatches; it must count
    what mismatches counts for each, on every model of the family."""
    probes = tm.probe(tm.fake_read_texture(model), 3)
    axes = list(tm.all_axes())
    for which in (0, 1):
        data = tm._AxisData(probes, which)
        assert data.all_mismatches(axes).tolist() == [data.mismatches(a) for a in axes]


def test_the_words_name_the_offset():
    text = tm.describe_model(both(weights="nearest", offset=-1.0))
    assert "one to the left and below" in text and "p = (uW - 1, vH - 1)" in text


# ---- fetchColor through the fitted readTexture --------------------------------

from hypothesis import HealthCheck, given, settings, strategies as st  # noqa: E402

from grader.checks.instruments import face_recovery  # noqa: E402
from model_lookups import ModelLookups  # noqa: E402

FACE_NAMES = library.FACE_NAMES

# One fetchColor mistake: (what the fake does, the diagnoses it must get).
def fetch_mistakes():
    face = st.sampled_from(FACE_NAMES)
    per_face = st.tuples(st.sampled_from(["u-flipped", "v-flipped", "uv-swapped"]), face).map(
        lambda t: ({t[1]: t[0]}, {(t[0], t[1])}))
    wrong_face = st.sampled_from([("+X", "-X"), ("+Y", "-Y"), ("+Z", "-Z")]).map(
        lambda p: ({p[0]: f"wrong-face:{p[1]}", p[1]: f"wrong-face:{p[0]}"}, {("wrong-face", p[0]), ("wrong-face", p[1])}))
    whole = st.sampled_from([("strict-ties", {("tie-untouched-face", None)}),
                             ("float", {("float-precision", None)}),
                             ("normalise-first", {("length-overflow", None)}),
                             (None, set())])
    return st.one_of(per_face, wrong_face, whole)


TEXTURE_MISTAKES = sorted(n for n in MEMBERS if n != "handout")


# slow: checks on fake lookups whose readTexture no model fits, or fits only after a long search (6-28 s each); the cheaper cases of each family stay fast
@pytest.mark.slow
def test_a_correct_fetch_color_over_a_correct_read_texture_gets_no_diagnosis():
    lookups = ModelLookups()
    analysis = face_recovery.analyse(lookups, tm.fit(lookups), quick=True)
    assert analysis.diagnoses() == [] and all(v.correct for v in analysis.faces)


def test_a_constant_read_texture_leaves_fetch_color_unanalysed_and_says_why():
    lookups = ModelLookups(fetch={"+X": "u-flipped"})
    lookups.read_texture = lambda face, uv, placement="end": lookups._outcome(np.ones((len(uv), 3)), str)
    found = tm.fit(lookups)
    assert found.constant
    ids = [d.id for d in face_recovery.analyse(lookups, found, quick=True).diagnoses()]
    assert ids == ["fetch-not-analysed"]


# slow: a hypothesis property test of about 76 s
@pytest.mark.slow
@settings(max_examples=14, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(fetch=fetch_mistakes(), texture=st.sampled_from(TEXTURE_MISTAKES))
def test_one_mistake_in_each_function_is_named_and_neither_is_blamed_for_the_other(fetch, texture):
    (mistake, fetch_ids), (model, texture_ids) = fetch, MEMBERS[texture]
    lookups = ModelLookups(texture=model, fetch=mistake)
    found = tm.fit(lookups)
    assert found.fits and sorted(tm.mistake_ids(found.model)) == sorted(texture_ids)
    got = {(d.id, d.face) for d in face_recovery.analyse(lookups, found, quick=True).diagnoses()}
    assert got == fetch_ids


# ---- the checks, scored through the fitted model ------------------------------

from grader.checks import all_checks, run_checks  # noqa: E402
from grader.checks.context import CheckContext  # noqa: E402
from grader.grading.results import FAILED, PASSED  # noqa: E402


def run_mapping_checks(lookups, tmp_path):
    checks = [c for c in all_checks().values() if c.name in ("read_texture", "fetch_sweep", "diagnosis", "stability")]
    ctx = CheckContext(lookups=lookups, seed=99, artifacts=tmp_path, quick=True)
    return {r.name: r for r in run_checks(checks, ctx).results}


@pytest.mark.parametrize("texture", cases(["texel-offset-clamped", "nearest-w-minus-1",
                                           "rows-flipped-w-minus-1-half-truncated", "weights-swapped", "wrapped"],
                                          {"nearest-w-minus-1"}))
def test_a_read_texture_mistake_costs_read_texture_points_only(texture, tmp_path):
    model, texture_ids = MEMBERS[texture]
    results = run_mapping_checks(ModelLookups(texture=model), tmp_path)
    assert results["read_texture"].status == FAILED
    assert {d.id for d in results["read_texture"].diagnoses} == set(texture_ids)
    for name in ("fetch_sweep", "diagnosis", "stability"):
        r = results[name]
        assert (r.status, r.fraction, r.diagnoses) == (PASSED, 1.0, []), (name, r.output[:600])


# slow: checks on fake lookups whose readTexture no model fits, or fits only after a long search (6-28 s each); the cheaper cases of each family stay fast
@pytest.mark.slow
def test_a_fetch_color_mistake_over_a_wrong_read_texture_costs_fetch_color_points(tmp_path):
    model, _ = MEMBERS["texel-offset-clamped"]
    results = run_mapping_checks(ModelLookups(texture=model, fetch={"+X": "u-flipped"}), tmp_path)
    assert {(d.id, d.face) for d in results["diagnosis"].diagnoses} == {("u-flipped", "+X")}
    assert results["fetch_sweep"].status == FAILED and 0.7 < results["fetch_sweep"].fraction < 0.95


def test_an_unknown_fetch_color_mistake_is_read_back_as_the_uv_it_used():
    # u = u^2 on +X: no candidate explains it; the instrument, inverted, gives the (u, v) used.
    lookups = ModelLookups(texture=both(offset=-0.5), fetch={"+X": "u-squared"})
    analysis = face_recovery.analyse(lookups, tm.fit(lookups), quick=True)
    assert {(d.id, d.face) for d in analysis.diagnoses()} == {("uv-mismatch", "+X")}
    inst = face_recovery.Instrument(both(offset=-0.5), coordinate_faces(32, 32))
    uv = np.array([[0.3, 0.8]])
    lo, hi = face_recovery.recover_uv(inst, 0, inst.predict(np.array([0]), uv ** [2, 1])[0])
    np.testing.assert_allclose([lo, hi], [[0.09, 0.8], [0.09, 0.8]], atol=1e-6)
