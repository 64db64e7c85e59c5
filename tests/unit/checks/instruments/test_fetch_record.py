"""instruments/fetch_record.py on fakes of the worker's RECORD_FETCH rows:
each case of a record is told apart, and judged as the table says."""
from __future__ import annotations

import numpy as np

from fake_lookups import FakeLookups
from grader.envmap import library
from grader.checks.instruments import fetch_record
from grader.checks.instruments.compare import tolerance
from grader.checks.instruments.textures import coordinate_faces
from grader.worker.protocol import RECORD_ROW

W = H = 8
DIRS = np.array([[1, 0.2, 0.3], [-0.1, -1, 0.5], [0.3, 0.3, -1], [1, 1, 0.2]], np.float64)


def judged(lookups):
    faces = coordinate_faces(W, H)
    lookups.set_faces(faces)
    return fetch_record.observe(lookups, DIRS, faces, tolerance(W, H, W + 1.0))


class Rows(FakeLookups):
    """The correct fake's rows, then `edit(rows, tagged)` applied."""

    def __init__(self, edit, **kwargs):
        super().__init__(**kwargs)
        self.edit = edit

    def record_fetch(self, dirs, tags):
        out = super().record_fetch(dirs, tags)
        self.edit(out.values, tags is not None)
        return out


def test_a_correct_fetch_color_is_read_right_everywhere():
    rec, verdict = judged(FakeLookups())
    assert (verdict.case == fetch_record.READ).all() and verdict.ok.all()
    # The printed places are the table's and the recorded (u, v), not colours read back.
    table, asked = fetch_record.hits(verdict, 0, (W, H))
    faces, uv = library.direction_to_face(DIRS[:1])
    assert table.face == asked.face == library.FACE_NAMES[faces[0]] and table.uv == tuple(uv[0])


def test_a_wrong_u_is_seen_on_its_face_only():
    _, verdict = judged(FakeLookups(fetch={"+X": "u-flipped"}))
    # The tie [1, 1, 0.2] goes to +X here (its u flipped: right on neither face it touches).
    assert list(verdict.ok) == [False, True, True, False]


def test_a_u_off_by_more_than_float_rounding_is_wrong_even_where_the_colour_is_clamped_flat():
    # (u, v) = (0.65 - 1e-4, ...) moves less than the border's flat half texel
    # would hide in a colour; the record is compared as numbers.
    def nudge(rows, tagged):
        rows[0, 7] -= 1e-4
    _, verdict = judged(Rows(nudge))
    assert not verdict.ok[0] and verdict.ok[1:].all()
    _, verdict = judged(Rows(lambda rows, tagged: rows.__setitem__((0, 7), rows[0, 7] + 2 ** -24)))
    assert verdict.ok.all()


def test_an_answer_not_returned_is_its_own_case():
    def scale(rows, tagged):
        rows[1, :3] *= 0.5
        rows[1, 4] = -1
    _, verdict = judged(Rows(scale))
    assert verdict.case[1] == fetch_record.NOT_RETURNED and not verdict.ok[1]


def test_an_address_inside_a_face_is_no_face_start():
    def inside(rows, tagged):
        rows[2, 5] = -1
        rows[2, 6] += 3 * (W + 1)
    rec, verdict = judged(Rows(inside))
    assert verdict.case[2] == fetch_record.NO_FACE_START and not verdict.ok[2]
    # Its worst case prints the address and (u, v) it asked there, not a colour read at no face.
    table, asked = fetch_record.hits(verdict, 2, (W, H))
    assert table.face == "-Z" and asked.face == "" and asked.address == rec.offsets[2, 0]
    assert asked.uv == tuple(rec.uv[2, 0]) and np.isfinite(asked.uv).all()
    from grader.reports.view import hit_text
    assert hit_text(asked).startswith(f"an address {rec.offsets[2, 0]:.0f} floats after the first face's first texel")


def test_asking_otherwise_when_the_student_answers_is_seen():
    def other(rows, tagged):
        if not tagged:
            rows[3, 8] = 1 - rows[3, 8]
    _, verdict = judged(Rows(other))
    assert verdict.case[3] == fetch_record.ASKS_OTHERWISE and not verdict.ok[3]


def test_reading_texels_itself_is_judged_end_to_end():
    rec, verdict = judged(FakeLookups(texture="crash-alone"))
    assert (verdict.case == fetch_record.READS_ITSELF).all() and verdict.ok.all()
    assert (rec.calls == 0).all()


def test_rows_have_the_protocol_width():
    assert FakeLookups().record_fetch(DIRS, fetch_record.TAGS).values.shape == (len(DIRS), RECORD_ROW)


class Memoising(FakeLookups):
    """fetchColor with a cache of answers by direction that lives as long as
    the worker: a direction seen before makes no readTexture call and returns
    what it returned then (a tag, after a tagged recording); restart() is a
    fresh worker, the cache empty."""

    def __init__(self):
        super().__init__()
        self.cache, self.restarts = {}, 0

    def restart(self):
        self.cache, self.restarts = {}, self.restarts + 1

    def record_fetch(self, dirs, tags):
        out = super().record_fetch(dirs, tags)
        for i, d in enumerate(map(tuple, np.asarray(dirs).reshape(-1, 3))):
            if d in self.cache:
                out.values[i] = np.nan
                out.values[i, :3], out.values[i, 3], out.values[i, 4] = self.cache[d], 0, -1
            else:
                self.cache[d] = out.values[i, :3].copy()
        return out


def test_a_fetch_color_that_memoises_is_judged_on_what_it_asked_in_a_fresh_worker():
    lookups = Memoising()
    rec, verdict = judged(lookups)
    # Without the fresh worker, the plain run finds every answer remembered
    # (no call) and the tagged run's tags: asks-otherwise everywhere.
    assert lookups.restarts >= 1
    assert (verdict.case == fetch_record.READ).all() and verdict.ok.all(), verdict.case
    # A second observation in the same worker (its cache full) is judged the same.
    _, again = judged(lookups)
    assert (again.case == fetch_record.READ).all() and again.ok.all()


def test_without_a_fresh_worker_the_memoised_answers_would_have_been_judged_otherwise():
    # The test above can fail: the same fake with restart() doing nothing.
    lookups = Memoising()
    lookups.restart = lambda: None
    _, verdict = judged(lookups)
    assert not verdict.ok.all()


# ---- the handout's bilinear, and the plain recording on a sample -------------------

def test_the_handout_read_agrees_with_the_c_reference_bilinear():
    from grader.checks.instruments.textures import random_faces
    faces = random_faces(13, 7, 3)
    cube = library.CubeMap(faces)
    rng = np.random.default_rng(1)
    uv = np.concatenate([rng.random((4000, 2)), np.stack(np.meshgrid(np.arange(14) / 13, np.arange(8) / 7), -1).reshape(-1, 2),
                         [[0, 0], [1, 1], [0, 1], [1, 0], [1 - 1e-12, 0.5]]])
    for face in (0, 3, 5):
        got = fetch_record.handout_read(faces, np.full(len(uv), face), uv)
        np.testing.assert_allclose(got, cube.read_texture(face, uv, "bilinear"), rtol=0, atol=1e-12)
    # Outside [0, 1] (a student's u): clamped to [0, 1] as the reference's readTexture takes it.
    outside = np.array([[-0.3, 0.5], [1.4, -0.2], [-0.01, 1.01]])
    np.testing.assert_allclose(fetch_record.handout_read(faces, np.full(3, 2), outside),
                               cube.read_texture(2, outside, "bilinear"), rtol=0, atol=1e-12)
    assert np.isnan(fetch_record.handout_read(faces, np.array([-1, 2]), np.array([[0.5, 0.5], [np.nan, 0.5]]))).all()


MANY = np.random.default_rng(5).normal(size=(3 * fetch_record.PLAIN_SAMPLE, 3))


class Counting(FakeLookups):
    """The fake, counting the directions recorded plainly; `other` (n,) of
    MANY's rows ask for another v when answered by the student's readTexture."""

    def __init__(self, other=None):
        super().__init__()
        self.plain, self.other = 0, other

    def record_fetch(self, dirs, tags):
        out = super().record_fetch(dirs, tags)
        if tags is None:
            self.plain += len(dirs)
            if self.other is not None:
                rows = np.flatnonzero((np.asarray(dirs)[:, None, :] == MANY[self.other][None]).all(axis=2).any(axis=1))
                out.values[rows, 8] = 1 - out.values[rows, 8]
        return out


def observe_many(lookups):
    faces = coordinate_faces(W, H)
    lookups.set_faces(faces)
    return fetch_record.observe(lookups, MANY, faces, tolerance(W, H, W + 1.0))[1]


def test_honest_code_is_recorded_plainly_on_a_sample_only():
    lookups = Counting()
    verdict = observe_many(lookups)
    assert lookups.plain == fetch_record.PLAIN_SAMPLE and verdict.ok.all()


def test_asking_otherwise_on_one_direction_in_a_hundred_is_caught_and_then_judged_everywhere():
    # 1% of the directions: the sample misses all of them with probability 0.99 ** 1024 = 3e-5.
    other = np.random.default_rng(6).choice(len(MANY), len(MANY) // 100, replace=False)
    lookups = Counting(other)
    verdict = observe_many(lookups)
    assert lookups.plain == fetch_record.PLAIN_SAMPLE + len(MANY)
    assert set(np.flatnonzero(verdict.case == fetch_record.ASKS_OTHERWISE)) == set(other)
    assert verdict.ok.sum() == len(MANY) - len(other)


def test_the_sample_is_the_same_for_the_same_directions():
    # Determinism: the same submission graded twice draws the same sample (and so the same report).
    a, b = Counting(np.array([0])), Counting(np.array([0]))
    observe_many(a), observe_many(b)
    assert a.plain == b.plain


# ---- readTexture as fetchColor calls it (redteam4) ----------------------------------

def test_readtexture_is_observed_in_context_on_every_face_size_the_renders_use():
    """A readTexture that answers fetchColor otherwise only on large faces
    (redteam4/honest_on_small_faces) shows on the maps' own sizes."""
    from grader.grading import fixtures
    sizes = set()
    for fixture in fixtures.render_fixtures():
        cross = library.read_hdr(fixture.map)
        sizes.add((cross.shape[1] // 3, cross.shape[0] // 4))
    assert sizes <= set(fetch_record.IN_CONTEXT_SIZES), sizes
    assert min(fetch_record.IN_CONTEXT_SIZES) < min(sizes)


def test_a_draw_whose_answers_are_not_returned_where_the_public_ones_are_counts_them_as_differing():
    public = fetch_record.InContext(differ=0, observed=2900, called=2900, example=None)
    hiding = fetch_record.InContext(differ=0, observed=0, called=2850, example=None).hiding(public)
    assert (hiding.differ, hiding.observed, hiding.hidden) == (2850, 2850, 2850)
    # Honest code returns every answer in both: nothing changes.
    honest = fetch_record.InContext(differ=0, observed=2870, called=2870, example=None)
    assert honest.hiding(public) == honest
    # A fetchColor that returns no answer anywhere (its own mistake, judged by the sweep) hides nothing here.
    nowhere = fetch_record.InContext(differ=0, observed=0, called=2800, example=None)
    assert nowhere.hiding(fetch_record.InContext(0, 0, 2900, None)) == nowhere


def test_an_answer_returned_through_float_is_the_answer_returned():
    """As the shim counts it (ObservedMap::returned): each channel bit for bit,
    or the answer rounded to float; anything else is not the answer."""
    answer = np.array([[0.1, 1 / 3, 2.0 ** -30], [np.nan, 0.5, 7.0]])
    through_float = answer.astype(np.float32).astype(np.float64)
    assert fetch_record.returned_as(answer, answer).all() and fetch_record.returned_as(answer, through_float).all()
    nudged = answer.copy()
    nudged[0, 1] = np.nextafter(nudged[0, 1], 1.0)
    assert list(fetch_record.returned_as(answer, nudged)) == [False, True]
    assert not fetch_record.returned_as(answer[:1], answer[:1] * (1 + 1e-6)).any()
    # Beyond float's range nothing rounds to float: infinity is not 1e300 returned.
    assert not fetch_record.returned_as(np.array([[1e300, 1.0, 1.0]]), np.array([[np.inf, 1.0, 1.0]])).any()
