"""What fetchColor asks readTexture, recorded, and fetchColor judged on it.

readTexture is virtual in the EnvironmentMap.h the grader compiles against;
the shim's recording map (grader/shim/shim.cpp, sub_record_fetch_batch)
overrides it: each call fetchColor makes is logged (the face whose first
texel the address is, or none; u; v; how many calls) and answered with a
tag colour chosen here. Nothing is inferred from colours and the student's
readTexture is never called: fetchColor is judged as if its readTexture were
the handout's (the reference's bilinear at the recorded face and (u, v),
computed here), so a readTexture mistake never costs fetchColor anything and
a readTexture that lies buys nothing (issue 29).

Where fetchColor makes no readTexture call (it reads the texels itself, or
calls EnvironmentMap::readTexture qualified), the record says so and its
colours are judged end to end against the reference on the same faces.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ...envmap import library
from ...grading.results import TexelHit
from ...worker.protocol import RECORDED_CALLS
from .compare import Mismatches, compare, format_vector, tied_face_uv

# What the recording readTexture answers to call k of each direction: exact
# in float (a fetchColor that goes through float keeps them), distinct per
# call in every channel, and ordinary colours (no zeros, no ones, no pattern
# across channels).
TAGS = np.array([[0.359375, 0.6171875, 0.2265625],
                 [0.7265625, 0.1953125, 0.5390625],
                 [0.4453125, 0.8203125, 0.6640625],
                 [0.2890625, 0.4140625, 0.9296875]], np.float64)
assert TAGS.shape == (RECORDED_CALLS, 3) and (TAGS == TAGS.astype(np.float32)).all()

# How far a recorded (u, v) may be from the table's: a fetchColor that
# computes in float (or in another order) is a few float ulps of 1 away.
UV_TOLERANCE = 4.0 * 2.0 ** -24

# The cases of a direction's record.
READ = "read"                    # one tag returned: judged at that call's face and (u, v)
READS_ITSELF = "reads-itself"    # no readTexture call: judged end to end
NOT_RETURNED = "not-returned"    # readTexture called, its answer not returned as it came
NO_FACE_START = "no-face-start"  # the answer returned came from an address that is no face's start
ASKS_OTHERWISE = "asks-otherwise"  # other calls (or colours) when answered by the student's own readTexture
FAILED = "failed"                # fetchColor crashed, threw or timed out while recorded


@dataclass
class Record:
    """One recording's observations for n directions."""
    values: np.ndarray      # (n, 3) what fetchColor returned
    calls: np.ndarray       # (n,) readTexture calls made (-1: fetchColor did not finish)
    returned: np.ndarray    # (n,) the logged call whose answer fetchColor returned unchanged (-1: none)
    faces: np.ndarray       # (n, RECORDED_CALLS) face of each call's address (-1: no face start, or no call)
    offsets: np.ndarray     # (n, RECORDED_CALLS) the address, in floats from face 0's first texel
    uv: np.ndarray          # (n, RECORDED_CALLS, 2) (u, v) of each call
    outcome: object         # the runner's Outcome (failures), or a list of them

    def request(self) -> tuple[np.ndarray, np.ndarray]:
        """(faces (n,), uv (n, 2)) of the call whose answer was returned (-1, NaN: none)."""
        k = np.maximum(self.returned, 0)
        faces = np.where(self.returned >= 0, np.take_along_axis(self.faces, k[:, None], axis=1)[:, 0], -1)
        uv = np.where((faces >= 0)[:, None], self.uv[np.arange(len(k)), k], np.nan)
        return faces, uv


def not_finite(rec: Record) -> tuple[np.ndarray, list[str]]:
    """(rows, words): the directions for which fetchColor, having finished,
    returned NaN or infinity or asked readTexture for a u or v that is not
    finite (answered with a tag, it would return NaN to a real readTexture's
    caller), and what was seen for each, in words."""
    from ...i18n import _
    with np.errstate(invalid="ignore"):
        made = np.arange(RECORDED_CALLS)[None, :] < np.minimum(rec.calls, RECORDED_CALLS)[:, None]
        bad_uv = (made & ~np.isfinite(rec.uv).all(axis=2)).any(axis=1)
    bad_rgb = ~np.isfinite(rec.values).all(axis=1)
    rows = np.flatnonzero((rec.calls >= 0) & (bad_uv | bad_rgb))
    words = []
    for i in rows:
        if bad_uv[i]:
            k = int(np.flatnonzero(made[i] & ~np.isfinite(rec.uv[i]).all(axis=1))[0])
            words.append(_("asked readTexture for u = %(u)s, v = %(v)s") % {"u": repr(float(rec.uv[i, k, 0])),
                                                                            "v": repr(float(rec.uv[i, k, 1]))})
        else:
            words.append(_("returned %(rgb)s") % {"rgb": format_vector(rec.values[i])})
    return rows, words


def returned_as(answer: np.ndarray, got: np.ndarray) -> np.ndarray:
    """(n,) whether each colour `got` is the answer `answer` as fetchColor
    may return it: each channel bit for bit (NaN for NaN), or the answer
    rounded to float, as the shim counts an answer returned
    (grader/build/shim/shim.cpp, ObservedMap::returned): a fetchColor that
    keeps colours in float returns what it was given."""
    answer, got = np.asarray(answer, np.float64), np.asarray(got, np.float64)
    with np.errstate(invalid="ignore", over="ignore"):
        # Beyond float's range there is no float to round to (the shim's C++
        # conversion would be undefined): only the answer itself counts.
        fits = np.abs(answer) <= np.finfo(np.float32).max
        through_float = np.where(fits, answer.astype(np.float32).astype(np.float64), np.nan)
        same = (got == answer) | (got == through_float) | (np.isnan(got) & np.isnan(answer))
    return same.all(axis=-1)


def concatenate(records: list[Record]) -> Record:
    """Several records as one, in order (their outcomes as a list)."""
    return Record(**{name: np.concatenate([getattr(r, name) for r in records])
                     for name in ("values", "calls", "returned", "faces", "offsets", "uv")},
                  outcome=[r.outcome for r in records])


def record(lookups, dirs: np.ndarray, tagged: bool = True, fresh: bool = True) -> Record:
    """fetchColor for each direction (n, 3) on the faces currently set, its
    readTexture calls answered with TAGS (tagged) or by the student's own
    readTexture.

    A direction answered with no readTexture call is recorded again in a
    fresh worker: a fetchColor that memoises its answers makes no call for a
    direction it has seen (in an earlier recording, answered with tags or on
    other faces), and what it remembers is not what it does. Code that reads
    the texels itself makes no call there either, and is judged on that.
    fresh=False: no second recording; what it answered from memory is judged
    as its own colour (the speed check: its directions are new to it, and
    what a lookup remembers from the timed pass is what the pass answered)."""
    dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
    rec = _record_once(lookups, dirs, tagged)
    again = np.flatnonzero(rec.calls == 0)
    restart = getattr(lookups, "restart", None)      # stateless stand-ins (tests, the kit's recorder) have none
    if fresh and len(again) and restart is not None:
        restart()
        rec = _with_rows(rec, again, _record_once(lookups, dirs[again], tagged))
    return rec


def _with_rows(rec: Record, rows: np.ndarray, sub: Record) -> Record:
    """rec with rows replaced by sub's (recorded for dirs[rows]); the
    outcome's failures and faulted rows renumbered into rec's rows."""
    import dataclasses
    merged = {}
    for name in ("values", "calls", "returned", "faces", "offsets", "uv"):
        array = getattr(rec, name).copy()
        array[rows] = getattr(sub, name)
        merged[name] = array
    first, second = rec.outcome, sub.outcome
    failures = list(first.failures) + [dataclasses.replace(f, index=None if f.index is None else int(rows[f.index]))
                                       for f in second.failures]
    values = np.array(first.values, np.float64, copy=True)
    values[rows] = second.values
    evaluated = np.array(first.evaluated, bool, copy=True)
    evaluated[rows] = second.evaluated
    outcome = dataclasses.replace(first, values=values, evaluated=evaluated, failures=failures,
                                  gave_up=first.gave_up or second.gave_up,
                                  warnings=list(dict.fromkeys(list(first.warnings) + list(second.warnings))),
                                  recovered_rows=list(first.recovered_rows) + [int(rows[i]) for i in second.recovered_rows])
    return Record(**merged, outcome=outcome)


def _record_once(lookups, dirs: np.ndarray, tagged: bool) -> Record:
    got = lookups.record_fetch(dirs, TAGS if tagged else None)
    rows = np.asarray(got.values, np.float64).reshape(len(dirs), -1)
    evaluated = np.asarray(got.evaluated, bool) & np.isfinite(rows[:, 3])
    calls = np.where(evaluated, np.nan_to_num(rows[:, 3], nan=-1), -1).astype(np.int64)
    logged = rows[:, 5:].reshape(len(dirs), RECORDED_CALLS, 4)
    made = np.arange(RECORDED_CALLS)[None, :] < calls[:, None]
    with np.errstate(invalid="ignore"):
        faces = np.where(made & np.isin(logged[..., 0], np.arange(6)), logged[..., 0], -1).astype(np.int64)
        returned = np.where(evaluated & (rows[:, 4] >= 0) & (rows[:, 4] < np.minimum(calls, RECORDED_CALLS)),
                            rows[:, 4], -1).astype(np.int64)
    values = np.where(evaluated[:, None], rows[:, :3], np.nan)
    if tagged:
        # The worker's index is the submission's word: the tag itself must have come back.
        same = (values == TAGS[np.maximum(returned, 0) % RECORDED_CALLS]).all(axis=1)
        returned = np.where(same, returned, -1)
    return Record(values=values, calls=calls, returned=returned, faces=faces,
                  offsets=np.where(made, logged[..., 1], np.nan), uv=np.where(made[..., None], logged[..., 2:4], np.nan),
                  outcome=got)


def cases(tagged: Record, plain: Record) -> np.ndarray:
    """(n,) each direction's case: READ, READS_ITSELF, NOT_RETURNED,
    NO_FACE_START, ASKS_OTHERWISE or FAILED. `plain` is the same directions
    answered by the student's own readTexture: where it ran, its calls must
    be the tagged run's (fetchColor cannot ask otherwise when it is answered
    otherwise) and it must return an answer too; where it did not (the
    student's readTexture crashed), the tagged run alone decides."""
    face = np.where(tagged.returned >= 0,
                    np.take_along_axis(tagged.faces, np.maximum(tagged.returned, 0)[:, None], axis=1)[:, 0], -1)
    out = np.full(len(tagged.calls), NOT_RETURNED, object)
    out[tagged.calls == 0] = READS_ITSELF
    out[(tagged.returned >= 0) & (face >= 0)] = READ
    out[(tagged.returned >= 0) & (face < 0)] = NO_FACE_START
    ran = plain.calls >= 0
    same_calls = (plain.calls == tagged.calls)
    for array in ("faces", "offsets", "uv"):
        a, b = getattr(plain, array), getattr(tagged, array)
        same = (a == b) | (np.isnan(a) & np.isnan(b)) if a.dtype.kind == "f" else a == b
        same_calls &= same.reshape(len(same), -1).all(axis=1)
    itself = tagged.calls == 0
    with np.errstate(invalid="ignore"):
        same_colour = ~itself | ((plain.values == tagged.values) | (np.isnan(plain.values) & np.isnan(tagged.values))).all(axis=1)
    out[ran & (out == READ) & (plain.returned < 0)] = NOT_RETURNED
    out[ran & ~(same_calls & same_colour)] = ASKS_OTHERWISE
    out[tagged.calls < 0] = FAILED
    return out


@dataclass
class Judgement(Mismatches):
    """fetchColor judged on its record. The colours (`expected`, `actual`)
    are computed when first asked for: most judgements need only `ok`."""
    ok: np.ndarray            # (n,) what it asked for (or, reading itself, returned) is right
    error: np.ndarray         # (n,) distance to the nearest acceptable colour
    case: np.ndarray          # (n,) cases()
    unreadable: np.ndarray    # (n,) always False: the student's readTexture is never asked
    requested: tuple          # (faces (n,), uv (n, 2)) the recorded request (-1, NaN: none)
    own: np.ndarray           # (n, 3) what fetchColor returned
    own_rows: np.ndarray      # (n,) where that colour is the one credited (it read itself, or returned no answer it was given)
    texels: np.ndarray        # the faces it was recorded on
    touching: tuple           # (faces (n, 4), uv (n, 4, 2)): the table's request on each face the
                              # direction touches (compare.tied_face_uv), the first as `table`
    stray: np.ndarray | None = None   # (n, 3) address (floats from face 0's first texel), u, v of the call
                                      # returned where no face starts there (NO_FACE_START); NaN elsewhere

    @property
    def table(self) -> tuple:
        """(faces (n,), uv (n, 2)): the reference's face and (u, v) (docs/assignment.md)."""
        return self.touching[0][:, 0], self.touching[1][:, 0]

    @functools.cached_property
    def expected(self) -> np.ndarray:
        """(n, 3) the reference's colour for the direction."""
        return handout_read(self.texels, *self.table)

    @functools.cached_property
    def actual(self) -> np.ndarray:
        """(n, 3) the handout's readTexture at the recorded request (or its own colour)."""
        return _actual(self.texels, self.requested, self.own_rows, self.own)


def _actual(texels, requested, own_rows, own) -> np.ndarray:
    out = handout_read(texels, *requested)
    out[own_rows] = own[own_rows]
    return out


def handout_read(texels: np.ndarray, faces: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """The handout's readTexture (equations (1)-(3), lattice points clamped
    to the face, (u, v) to [0, 1]) on texels (6, H, W, 3) at faces[i],
    uv[i]; NaN where no face or (u, v). Written here, not asked of the
    oracle: the (u, v) are the student's, which the kit's recorded answers
    cannot hold. Held to the C reference's bilinear by
    tests/unit/checks/instruments/test_fetch_record.py."""
    texels = np.asarray(texels)
    h, w = texels.shape[1:3]
    out = np.full((len(uv), 3), np.nan)
    rows = np.flatnonzero((faces >= 0) & np.isfinite(uv).all(axis=1))
    if not len(rows):
        return out
    f = faces[rows].astype(np.int64)
    # (u, v) clamped to [0, 1] as the reference's readTexture takes them;
    # p = (uW, vH); the lattice point below-left of it and its neighbour,
    # clamped to the face.
    px, py = np.clip(uv[rows, 0], 0.0, 1.0) * w, np.clip(uv[rows, 1], 0.0, 1.0) * h
    left, bottom = np.floor(px), np.floor(py)
    alpha, beta = (px - left)[:, None], (py - bottom)[:, None]
    x0, x1 = np.clip(left, 0, w - 1).astype(np.int64), np.clip(left + 1, 0, w - 1).astype(np.int64)
    y0, y1 = np.clip(bottom, 0, h - 1).astype(np.int64), np.clip(bottom + 1, 0, h - 1).astype(np.int64)
    def c(y, x):
        return texels[f, y, x].astype(np.float64)

    c0 = (1.0 - alpha) * c(y0, x0) + alpha * c(y0, x1)
    c1 = (1.0 - alpha) * c(y1, x0) + alpha * c(y1, x1)
    out[rows] = (1.0 - beta) * c0 + beta * c1
    return out


def judge(tagged: Record, plain: Record, dirs: np.ndarray, texels: np.ndarray, tol) -> Judgement:
    """Each direction's record against the table: the recorded face is one
    the direction touches and (u, v) is the table's within UV_TOLERANCE.
    Where fetchColor reads the texels itself, its colour against the
    handout's readTexture at the table's (face, u, v), within float-level
    `tol`. The error orders the worst cases: texels off for a request
    (inf: another face), the colour's distance otherwise."""
    dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
    case = cases(tagged, plain)
    req_faces, req_uv = tagged.request()
    # Where fetchColor asks otherwise when its own readTexture answers, what
    # it asks then is what it does: that request is the one judged and shown
    # (its own colour where it returned no answer it was given).
    otherwise = case == ASKS_OTHERWISE
    plain_faces, plain_uv = plain.request()
    req_faces, req_uv = req_faces.copy(), req_uv.copy()
    req_faces[otherwise], req_uv[otherwise] = plain_faces[otherwise], plain_uv[otherwise]
    itself = case == READS_ITSELF
    own_rows = otherwise & (req_faces < 0)
    own = np.where(own_rows[:, None], plain.values, tagged.values)
    own_rows |= itself
    faces, uv = tied_face_uv(dirs)
    n, k = faces.shape
    size = np.array(texels.shape[2:0:-1], np.float64)            # (W, H)
    with np.errstate(invalid="ignore", over="ignore"):     # a u of 1e308 is inf texels off
        same_face = (faces == req_faces[:, None]) & (faces >= 0)  # (n, k)
        du, dv = np.abs(req_uv[:, None, 0] - uv[..., 0]), np.abs(req_uv[:, None, 1] - uv[..., 1])
        near = same_face & (du <= UV_TOLERANCE) & (dv <= UV_TOLERANCE)
        texels_off = np.where(same_face, np.maximum(du * size[0], dv * size[1]), np.inf)
    texels_off[np.isnan(texels_off)] = np.inf
    read = case == READ
    ok, error = near.any(axis=1) & read, texels_off.min(axis=1)
    # The colours against the handout's at every face the direction touches:
    # judged where fetchColor read itself, and the error that orders the
    # other cases' worst (few rows for most code: not computed for the rest).
    rows = np.flatnonzero(~read)
    if len(rows):
        acceptable = handout_read(texels, faces[rows].reshape(-1), uv[rows].reshape(-1, 2)).reshape(len(rows), k, 3)
        actual = _actual(texels, (req_faces[rows], req_uv[rows]), own_rows[rows], own[rows])
        cmp = compare(actual, acceptable, np.broadcast_to(np.asarray(tol, np.float64), (n,))[rows])
        ok[rows], error[rows] = itself[rows] & cmp.ok, cmp.error
    stray = np.full((n, 3), np.nan)
    astray = np.flatnonzero(case == NO_FACE_START)
    if len(astray):
        k = tagged.returned[astray]
        stray[astray, 0] = tagged.offsets[astray, k]
        stray[astray, 1:] = tagged.uv[astray, k]
    return Judgement(ok=ok, error=error, case=case, unreadable=np.zeros(n, bool), requested=(req_faces, req_uv),
                     own=own, own_rows=own_rows, texels=texels, touching=(faces, uv), stray=stray)


# The plain recording (answered by the student's own readTexture) is made
# for a sample of PLAIN_SAMPLE directions of a larger set, drawn after the
# tagged recording from a hash of the directions (deterministic, and unknown
# to fetchColor while it is recorded tagged: it cannot be honest on the
# sample only). Honest code asks alike on every direction, so the sample
# finds nothing and the rest is never recorded plainly (issue 29: the
# second recording was most of the record's cost). A fetchColor that asks
# otherwise on a share q of the directions escapes the sample with
# probability (1 - q) ** PLAIN_SAMPLE: 3e-5 at q = 1%, 4e-3 at q = 0.5%,
# and below q = 1% it could gain at most 1% of a check. Once the sample
# finds one direction that asks otherwise or returns no answer, every
# direction is recorded plainly and judged as if no sample had been drawn
# (tests/unit/checks/instruments/test_fetch_record.py,
# tests/security/test_recording_attacks.py).
PLAIN_SAMPLE = 1024


def observe(lookups, dirs: np.ndarray, texels: np.ndarray, tol, fresh: bool = True) -> tuple[Record, Judgement]:
    """fetchColor recorded on `texels` (the faces currently set: tagged, then
    answered by the student's own readTexture, on a sample) and judged: (the
    tagged record, whose outcome has fetchColor's own failures; the judgement)."""
    dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
    tagged = record(lookups, dirs, fresh=fresh)
    return tagged, judge(tagged, plain_record(lookups, dirs, tagged, fresh), dirs, texels, tol)


def plain_record(lookups, dirs: np.ndarray, tagged: Record, fresh: bool = True) -> Record:
    """The plain recording of `dirs` (PLAIN_SAMPLE): all of them, or a
    sample, the rest marked not run (calls -1: cases() goes by the tagged
    record alone there)."""
    n = len(dirs)
    if n <= PLAIN_SAMPLE:
        return record(lookups, dirs, tagged=False, fresh=fresh)
    import hashlib
    digest = hashlib.blake2b(np.ascontiguousarray(dirs).tobytes(), digest_size=16).digest()
    sample = np.sort(np.random.default_rng(np.frombuffer(digest, np.uint32)).choice(n, PLAIN_SAMPLE, replace=False))
    seen = record(lookups, dirs[sample], tagged=False, fresh=fresh)
    alone = _rows(tagged, sample)
    if (cases(alone, seen) != cases(alone, _not_run(PLAIN_SAMPLE))).any():
        return record(lookups, dirs, tagged=False, fresh=fresh)
    plain = _not_run(n)
    for name in ("values", "calls", "returned", "faces", "offsets", "uv"):
        getattr(plain, name)[sample] = getattr(seen, name)
    return plain


def _rows(rec: Record, rows: np.ndarray) -> Record:
    return Record(**{name: getattr(rec, name)[rows] for name in ("values", "calls", "returned", "faces", "offsets", "uv")},
                  outcome=None)


def _not_run(n: int) -> Record:
    return Record(values=np.full((n, 3), np.nan), calls=np.full(n, -1, np.int64), returned=np.full(n, -1, np.int64),
                  faces=np.full((n, RECORDED_CALLS), -1, np.int64), offsets=np.full((n, RECORDED_CALLS), np.nan),
                  uv=np.full((n, RECORDED_CALLS, 2), np.nan), outcome=None)


def hits(judgement: Judgement, i: int, size: tuple[int, int]) -> tuple[TexelHit | None, TexelHit | None]:
    """(where the table says, where fetchColor asked) for direction i, as the
    table's and the recorded (u, v) (never computed back from a colour)."""
    w, h = size

    def at(face, uv):
        if face < 0 or not np.isfinite(uv).all():
            return None
        return TexelHit(library.FACE_NAMES[face], (float(uv[0]) * w, float(uv[1]) * h), (float(uv[0]), float(uv[1])))

    asked = at(int(judgement.requested[0][i]), judgement.requested[1][i])
    if asked is None and judgement.stray is not None and np.isfinite(judgement.stray[i]).all():
        # An address where no face starts: what was asked there, not a colour.
        offset, u, v = (float(x) for x in judgement.stray[i])
        asked = TexelHit("", (float("nan"), float("nan")), (u, v), address=offset)
    return at(int(judgement.table[0][i]), judgement.table[1][i]), asked


# ---- readTexture as fetchColor calls it ------------------------------------

# Face sizes (W, H) readTexture is observed on as fetchColor calls it: a small
# one, and each face size of the maps the renders and arrows use (Cubemap/:
# 128 and 256; tests/unit/checks/instruments/test_fetch_record.py holds the
# maps to this list), so that a readTexture that answers fetchColor
# otherwise on large faces only cannot pass the check on small ones and the
# renders on large ones (redteam4/honest_on_small_faces).
IN_CONTEXT_SIZES = ((16, 16), (128, 128), (256, 256))
IN_CONTEXT_DIRECTIONS = 1_000      # per size
IN_CONTEXT_MARGIN = 2.0     # texels from the border where a read is read again (inside_face)
# The share the check keeps is measured on public directions and texels (this
# seed, the same in every grading and in the kit), and held to a draw from
# the grading's own seed (compare.below_by_more_than_chance): a share from
# the draw alone moved the points with it (redteam2/pays_to_be_believed:
# 18.93 in the kit, 18.75 in the grader, issue 30).
IN_CONTEXT_SEED = 0x1C0DE


@dataclass(frozen=True)
class InContext:
    """readTexture as fetchColor calls it, on one set of faces and directions."""
    differ: int             # observed calls answered otherwise than the same call made directly
    observed: int           # calls whose answer fetchColor returned unchanged, inside the face
    called: int             # directions whose first readTexture call was inside a face
    example: tuple | None   # (face, u, v, answer to fetchColor, direct answer) of the first that differed
    hidden: int = 0         # calls counted as differing because their answer was not returned (hiding)

    def hiding(self, public: "InContext") -> "InContext":
        """This draw with the calls whose answers fetchColor did not return
        counted as answered otherwise, where it returned them unchanged less
        often than on the public faces by more than chance: a fetchColor
        that returns no answer it was given on faces it was never shown
        hides its readTexture there (redteam4/hides_from_the_drawn_in_context)."""
        from .compare import below_by_more_than_chance
        rate = lambda c: c.observed / c.called if c.called else 1.0      # noqa: E731
        if not (self.called and public.called and below_by_more_than_chance(rate(self), self.called, rate(public))):
            return self
        hidden = self.called - self.observed
        return InContext(self.differ + hidden, self.called, self.called, self.example, hidden)


def in_context(lookups, seed: int, size: tuple[int, int], k: int = 0) -> InContext:
    """readTexture's answers to fetchColor's own calls (recorded, answered
    by the student's readTexture, on random texels of faces `size`) against
    the same readTexture called directly at the same face and (u, v), bit
    for bit (or through float: returned_as). Honest code computes the same
    thing whoever calls it; one that knows its caller (a flag fetchColor
    sets, the address) shows here. Only calls whose answer fetchColor
    returned (as it came, or through float), IN_CONTEXT_MARGIN
    texels or more inside the face, are observed. Sets its own faces (drawn
    from seed + k), each size in a worker of its own: a size kept in a static
    from larger faces reads past a smaller face, into its neighbour in the
    six-face buffer and into nothing when called alone, and would be taken
    for an answer that depends on its caller (read_texture zoo,
    static-face-size_table)."""
    from .directions import random_directions
    from .textures import random_faces
    w, h = size
    lookups.set_faces(random_faces(w, h, seed + k))
    plain = record(lookups, random_directions(IN_CONTEXT_DIRECTIONS, seed + k), tagged=False)
    faces, uv = plain.request()
    seen = np.flatnonzero((faces >= 0) & inside_face(uv, size))
    called = int(((plain.calls >= 1) & (plain.faces[:, 0] >= 0) & inside_face(plain.uv[:, 0], size)).sum())
    same, read = read_again(lookups, faces[seen], uv[seen], plain.values[seen])
    example = None
    if not same.all():
        i = first_differing(faces[seen], same)
        j = seen[i]
        example = (int(faces[j]), float(uv[j, 0]), float(uv[j, 1]), plain.values[j], read[i])
    return InContext(int((~same).sum()), len(seen), called, example)


def inside_face(uv: np.ndarray, size: tuple[int, int], margin: float = IN_CONTEXT_MARGIN) -> np.ndarray:
    """(n,) whether each (u, v) lies `margin` texels or more inside a face
    of `size` (W, H). There honest code reads the same texels whether the
    face sits in the six-face buffer (fetchColor's calls) or alone in a
    window of its own (direct calls); at the border a read past the face
    finds a neighbour in one and the window's edge in the other."""
    extent = np.asarray(size, np.float64)
    with np.errstate(invalid="ignore"):
        p = np.asarray(uv, np.float64) * extent
        return ((p >= margin) & (p <= extent - margin)).all(axis=1)


def read_again(lookups, faces: np.ndarray, uv: np.ndarray, answers: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(same (n,), read (n, 3)): the student's readTexture called directly at
    each row's face and (u, v) (one call per face) on the faces currently
    set, and whether `answers` are its reads as fetchColor may return them
    (returned_as); a read that failed differs."""
    same, read = np.ones(len(faces), bool), np.full((len(faces), 3), np.nan)
    for face in range(6):
        rows = np.flatnonzero(faces == face)
        if not len(rows):
            continue
        direct = lookups.read_texture(face, uv[rows])
        read[rows] = np.asarray(direct.values, np.float64)
        same[rows] = returned_as(read[rows], answers[rows]) & np.asarray(direct.evaluated, bool)
    return same, read


def first_differing(faces: np.ndarray, same: np.ndarray) -> int:
    """The row read_again shows first where any differs: by face, then by row."""
    order = np.argsort(faces, kind="stable")
    return int(order[~same[order]][0])


def judged_in_context(read_texture_check):
    """The read_texture check, then readTexture as fetchColor calls it
    (in_context, on each of IN_CONTEXT_SIZES): where the two differ, the
    check's share is at most the share of fetchColor's calls answered as a
    direct call is, on the face size where that share is lowest (as the
    check itself is scored), and it says which call differed. A readTexture
    that is right only for the grader's direct calls gains nothing."""
    import dataclasses
    import functools

    from ...i18n import _
    from ...grading.results import FAILED, Diagnosis

    from .. import shown
    from .compare import below_by_more_than_chance

    def share_of(c: InContext) -> float:
        return 1.0 - c.differ / c.observed if c.observed else 1.0

    @functools.wraps(read_texture_check)
    def run(ctx, result, *findings):
        finding = read_texture_check(ctx, result, *findings)
        judged = []
        for k, size in enumerate(IN_CONTEXT_SIZES):
            fixed = in_context(ctx.lookups, IN_CONTEXT_SEED, size, k)
            drawn = in_context(ctx.lookups, ctx.seed, size, k).hiding(fixed)
            used = drawn if below_by_more_than_chance(share_of(drawn), drawn.observed, share_of(fixed)) else fixed
            judged.append((share_of(used), size, used, fixed))
        worst, size, used, fixed = min(judged, key=lambda j: j[0])
        if not used.differ:
            return finding
        share = shown(worst)     # as printed, as used
        words = {"observed": used.observed, "differ": used.differ, "share": f"{share:.2%}", "w": size[0],
                 "h": size[1]}
        if used.example is not None and not used.hidden:
            face, u, v, called, direct = used.example
            detail = _(
                "On %(w)d x %(h)d faces, of %(observed)d readTexture calls your fetchColor made, %(differ)d were "
                "answered otherwise than the same call made directly, e.g. at face %(face)s, u = %(u)r, v = %(v)r: "
                "%(called)s to fetchColor, %(direct)s directly. The score is at most the share answered alike on the "
                "face size where it is lowest (%(share)s).") % {
                **words, "face": library.FACE_NAMES[face], "u": u, "v": v, "called": format_vector(called),
                "direct": format_vector(direct)}
        else:
            detail = _(
                "On %(w)d x %(h)d faces drawn for this grading your fetchColor returned readTexture's answer unchanged "
                "less often than on the public faces (%(drawn)d of %(called)d calls, against %(public)d of "
                "%(public_called)d): the %(differ)d answers it did not return count as answered otherwise, since what "
                "readTexture gave fetchColor there cannot be seen. The score is at most the share answered alike on "
                "the face size where it is lowest (%(share)s).") % {
                **words, "drawn": used.called - used.hidden, "called": used.called, "public": fixed.observed,
                "public_called": fixed.called}
        result.diagnoses = list(result.diagnoses) + [Diagnosis("texture-context-dependent", detail)]
        result.status = FAILED
        result.fraction = min(result.fraction, share)
        return dataclasses.replace(finding, ok=False, fraction=min(finding.fraction, share))

    return run
