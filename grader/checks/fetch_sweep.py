"""fetchColor over direction sweeps, judged on what it asks readTexture for, per set and face."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..envmap import library
from ..i18n import N_, _, and_list
from ..grading.results import FAILED, CheckResult, Diagnosis
from . import Credit, check, shown
from .instruments.compare import below_by_more_than_chance, chance_margin, describe_direction, format_vector, tolerance, worst_cases
from .context import CheckContext, failure_diagnoses, unique_diagnoses
from .instruments.directions import FIBONACCI_SET, RANDOM_SET, fibonacci_sphere, sweep_sets
from .instruments import fetch_record
from .read_texture import ReadTextureFinding, read_texture
from .instruments.textures import coordinate_faces

SWEEP_FACE_SIZE = (32, 32)
# A fixed set recorded on faces of a second size (W, H), not square, in the
# worker that ran the others (pattern 12: a face size kept in a static).
SECOND_FACE_SIZE = (24, 16)
SECOND_SIZE_DIRECTIONS = 2_000
SECOND_SIZE_SET = N_("Fibonacci sphere, 24 x 16 faces after 32 x 32")
# The same set where fetchColor answers otherwise in a process whose first
# faces these are (instruments.process_state), and fewer of its answers are right there.
SECOND_SIZE_FIRST_SET = N_("Fibonacci sphere, 24 x 16 faces first in a process")


# Robustness and speed count in proportion to how much of the sweep is right:
# nothing up to WORKING[0] (returning black is fast and never crashes, which
# earns nothing), everything from WORKING[1] (a face or two wrong, 83% and
# 67%, still counts as working), in a straight line between. A line, not a
# threshold: one more direction right never moves those 15 points by more
# than a few hundredths (a 50% threshold put the same code 8 points apart,
# issue 30).
WORKING = (0.3, 0.6)
# The random set keeps the fixed sets honest but scores nothing itself
# (compare.below_by_more_than_chance): 20,000 draws put its share within
# +-0.7% of the sphere's (two standard errors at 50%), +-0.03 points of 30.
MIN_ANSWERED = 1_000    # fewer random directions answered than this say nothing either way


def working_share(fraction: float) -> float:
    """The share of their points robustness and speed can earn after a sweep
    `fraction` right (WORKING), as shown."""
    low, high = WORKING
    return shown(min(max((shown(fraction) - low) / (high - low), 0.0), 1.0))


@dataclass(frozen=True)
class SweepFinding:
    """What the fetch_sweep check tells later checks."""
    fraction: float             # share of the fixed sets' directions that match the reference, as shown
    # Share of the Fibonacci sphere's (unit directions, as the speed check
    # draws them: a lookup right only at other lengths is compared like with like).
    sphere: float | None = None

    @property
    def working(self) -> float:
        """The share of their points the checks that need a working lookup can earn."""
        return working_share(self.fraction)

    def working_words(self) -> str:
        """Why a dependent earns `working` of its points, with the numbers used."""
        return (_("Robustness and speed count in proportion to how much of the sweep fetchColor gets right: "
                  "nothing up to %(low)s, all from %(high)s, in a straight line between. Your sweep: %(share)s "
                  "right, so this check earns %(working)s of what it finds.")
                % {"low": f"{WORKING[0]:.0%}", "high": f"{WORKING[1]:.0%}", "share": f"{self.fraction:.2%}",
                   "working": f"{self.working:.2%}"})


# What a check that needs a working lookup can earn (grader.checks.Needs.credit).
WORKING_CREDIT = Credit(share=lambda sweep: sweep.working, words=lambda sweep: sweep.working_words())


@check(requires=(read_texture,))
def fetch_sweep(ctx: CheckContext, result: CheckResult, texture: ReadTextureFinding) -> SweepFinding:
    """fetchColor picks the right face and (u, v) for every direction: the whole sphere, each face, edge, corner and axis, at any length."""
    # Judged on the record of what fetchColor asks readTexture
    # (instruments.fetch_record), as if its readTexture were the handout's:
    # the student's readTexture plays no part (`texture` only orders the checks).
    sets = sweep_sets(ctx.seed, fibonacci=20_000 if ctx.quick else 100_000)
    # Each set on the sweep's faces, then a fixed one on faces of a second
    # size in the same process, so a face size kept from an earlier call shows.
    observed = [(name, dirs, SWEEP_FACE_SIZE, False) for name, dirs in sets.items()]
    observed.append((SECOND_SIZE_SET, fibonacci_sphere(SECOND_SIZE_DIRECTIONS), SECOND_FACE_SIZE, True))

    diagnoses, parts = [], []
    for name, dirs, (w, h), same_process in observed:
        faces = coordinate_faces(w, h)
        if same_process or not parts:
            ctx.lookups.set_faces(faces, same_process=same_process)
        tol = tolerance(w, h, float(max(w, h) + 1))
        rec, verdict = fetch_record.observe(ctx.lookups, dirs, faces, tol)
        if same_process and ctx.states().depends:
            # fetchColor answers otherwise in a process whose first faces
            # they are (instruments.process_state): this set in that state
            # too, the one with fewer right answers kept, as for the end-to-end checks.
            ctx.lookups.restart()
            ctx.lookups.set_faces(faces)
            first = fetch_record.observe(ctx.lookups, dirs, faces, tol)
            if first[1].ok.sum() < verdict.ok.sum():
                (rec, verdict), name = first, SECOND_SIZE_FIRST_SET
                diagnoses.append(ctx.states().diagnosis())
        diagnoses += failure_diagnoses(rec.outcome.failures)
        parts.append((name, dirs, (w, h), rec, verdict))

    rows = []
    total = matched = 0
    per_face_bad = np.zeros(6, np.int64)
    per_face_all = np.zeros(6, np.int64)
    nan_inputs = []
    share_of = {}
    for name, dirs, size, rec, verdict in parts:
        ok, ref_faces = verdict.ok, verdict.table[0]
        evaluated = rec.calls >= 0
        fresh_nan, seen = fetch_record.not_finite(rec)
        if len(fresh_nan) and not nan_inputs:
            nan_inputs.append((dirs[fresh_nan[0]], seen[0]))
        # Over the directions it answered: where the worker gave up after a
        # crash, no direction says anything about the set (the later sets lose most).
        share_of[name] = (float(ok[evaluated].mean()), int(evaluated.sum())) if evaluated.any() else (1.0, 0)
        if name != RANDOM_SET:      # the points are on the fixed sets (RANDOM_SET's comment above)
            total += len(dirs)
            matched += int(ok.sum())
            np.add.at(per_face_all, ref_faces[ref_faces >= 0], 1)
            np.add.at(per_face_bad, ref_faces[(ref_faces >= 0) & ~ok], 1)
        rows.append((name, len(dirs), int(ok.sum())))
        if not ok.all():
            # The worst cases as data: reports print the table's and the recorded (face, u, v).
            result.mismatches += worst_cases(verdict, lambda i, dirs=dirs: describe_direction(dirs[i]),
                                             verdict.actual, verdict.expected, group=name,
                                             hits=lambda i, v=verdict, size=size: fetch_record.hits(v, i, size))
            result.mismatch_counts[name] = len(verdict.failures)
    if nan_inputs:
        diagnoses.append(Diagnosis("nan-output", _("%(call)s %(seen)s: NaN or infinity, for a direction that is finite "
                                                   "and not zero.")
                                   % {"call": describe_direction(nan_inputs[0][0]), "seen": nan_inputs[0][1]}))
    for name, dirs, size, rec, verdict in parts:
        diagnoses += _record_diagnoses(verdict, rec, dirs, size)
    fraction = shown(matched / total) if total else 0.0
    # The random set held to the Fibonacci sphere: both estimate the share of
    # the sphere that is right, the random one within its standard error.
    (drawn, n), even = share_of[RANDOM_SET], share_of[FIBONACCI_SET][0]
    by_chance = chance_margin(n, even)        # printed below
    answers_differ = n >= MIN_ANSWERED and below_by_more_than_chance(drawn, n, even) and drawn < fraction
    if answers_differ:
        fraction = shown(drawn)
    result.fraction = fraction
    result.metrics.update(cases=total, matched=matched, random_share=shown(drawn))
    scored = [part for part in parts if part[0] != RANDOM_SET]
    black = np.concatenate([black_without_lookup(verdict, rec) for *_, rec, verdict in scored])
    all_dirs = np.concatenate([dirs for _name, dirs, *_ in scored])
    if black.any() and not black.all():      # black everywhere is the starting code (not-implemented)
        diagnoses.append(Diagnosis("black-without-lookup", _black_words(
            black, np.concatenate([verdict.ok for *_, verdict in scored]),
            np.concatenate([verdict.table[0] for *_, verdict in scored]),
            np.concatenate([verdict.table[1] for *_, verdict in scored]), all_dirs)))
    diagnoses += border_diagnoses(scored)
    itself = np.concatenate([verdict.case == fetch_record.READS_ITSELF for *_, verdict in scored])
    notes = ""
    # Those that returned black with no call are told by black-without-lookup, not here.
    if (itself & ~black).any():
        result.metrics["reads_itself"] = int(itself.sum())
        notes = "\n\n" + _("For %(count)d directions your fetchColor made no readTexture call (it reads the texels "
                            "itself, or calls EnvironmentMap::readTexture by its qualified name), e.g. %(call)s: "
                            "their colours are judged end to end against the handout's readTexture.") % {
            "count": int((itself & ~black).sum()),
            "call": describe_direction(all_dirs[np.flatnonzero(itself & ~black)[0]])}
    table = [f"| {_('direction set')} | {_('cases')} | {_('match')} |", "|---|---:|---:|"]
    table += [f"| {_(name)} | {n} | {ok / n:.2%} |" if n else f"| {_(name)} | 0 | - |" for name, n, ok in rows]
    table += ["", f"| {_('face')} | {_('directions')} | {_('match')} |", "|---|---:|---:|"]
    table += [f"| {library.FACE_NAMES[k]} | {per_face_all[k]} | {1 - per_face_bad[k] / max(per_face_all[k], 1):.2%} |" for k in range(6)]
    random_words = "\n\n" + (
        _("The random directions, drawn for this grading, match on %(drawn)s of those answered: short of the "
          "Fibonacci sphere's %(even)s by more than chance allows (%(chance)s). Your fetchColor answers the fixed "
          "directions better than others, so the sweep counts %(drawn)s.")
        if answers_differ else
        _("The points are on the fixed sets (%(total)d directions, the same for everyone); the random directions, "
          "drawn for this grading, are held to the Fibonacci sphere: %(drawn)s against %(even)s of those "
          "answered.")) % {
        "drawn": f"{shown(drawn):.2%}", "even": f"{shown(even):.2%}", "chance": f"{shown(by_chance):.2%}", "total": total}
    result.diagnoses = unique_diagnoses(diagnoses)
    # The first sentence says only what the record saw: directions that made
    # no readTexture call are not said to ask it anything.
    words = {"wrong": total - matched, "total": total, "share": f"{shown(matched / total):.2%}",
             "itself": int(itself.sum())}
    if matched < total or answers_differ:
        result.status = FAILED
        first = (_("%(wrong)d of %(total)d directions do not ask readTexture for the face and (u, v) the handout's "
                   "table gives, or do not return what it answered: %(share)s right.") if not itself.any() else
                 _("%(wrong)d of %(total)d directions are wrong: they ask readTexture for another face or (u, v) "
                   "than the handout's table gives, do not return what it answered, or (of the %(itself)d that make "
                   "no readTexture call) give another colour than the handout's readTexture there: %(share)s right."))
    elif not itself.any():
        first = _("All %(total)d directions ask readTexture for the face and (u, v) the handout's table gives and "
                  "return what it answered.")
    elif itself.all():
        first = _("All %(total)d directions give the colour the handout's readTexture gives at the face and (u, v) "
                  "the handout's table gives (your fetchColor makes no readTexture call).")
    else:
        first = _("All %(total)d directions are right: those that call readTexture ask for the face and (u, v) "
                  "the handout's table gives and return what it answered; the %(itself)d that make no call give "
                  "the colour the handout's readTexture gives there.")
    result.output = first % words + "\n\n" + "\n".join(table) + random_words + notes
    return SweepFinding(fraction=fraction, sphere=shown(even))


def black_without_lookup(verdict, rec) -> np.ndarray:
    """(n,) directions for which fetchColor made no readTexture call and
    returned exact black where the reference is not black: on the sweep's
    faces no texel is black, so nothing was read (a guard returned it)."""
    return (verdict.case == fetch_record.READS_ITSELF) & ~verdict.ok & (rec.values == 0).all(axis=1)


def _black_words(black: np.ndarray, ok: np.ndarray, faces: np.ndarray, uv: np.ndarray, dirs: np.ndarray) -> str:
    """The count, one direction with the table's request, and what the
    directions share where the record shows it: u or v exactly 0 or 1, or a
    length below every direction that was looked up."""
    rows = np.flatnonzero(black)
    i = rows[0]
    words = _("For %(count)d of %(total)d directions fetchColor made no readTexture call and returned black, e.g. "
              "%(call)s, where the table asks face %(face)s at (u, v) = (%(u)s, %(v)s).") % {
        "count": len(rows), "total": len(black), "call": describe_direction(dirs[i]),
        "face": library.FACE_NAMES[int(faces[i])] if faces[i] >= 0 else "-",
        "u": f"{uv[i, 0]:.6g}", "v": f"{uv[i, 1]:.6g}"}
    edge = (uv[rows] == 0) | (uv[rows] == 1)
    if edge.any(axis=1).all():
        words += " " + _("Each of them lies on a face's border: the table gives u or v exactly 0 or 1 there "
                         "(%(ones)d with a 1, %(zeros)d with a 0).") % {
            "ones": int((uv[rows] == 1).any(axis=1).sum()), "zeros": int((uv[rows] == 0).any(axis=1).sum())}
    length = np.abs(dirs).max(axis=1)
    looked_up = ~black & ok
    if looked_up.any() and length[rows].max() < length[looked_up].min():
        words += " " + _("Each of them is shorter than every direction that was looked up: largest |component| "
                         "at most %(short)s, against %(long)s and above.") % {
            "short": f"{length[rows].max():.3g}", "long": f"{length[looked_up].min():.3g}"}
    return words


# The ids border_diagnoses gives from a variable (tests/unit/grading/test_diagnosis_catalogue.py).
DIAGNOSIS_IDS = ("coordinate-wraps", "uv-clamped-inward")
# A border statement is made of a face only where this share of the directions
# that ask it are right.
BORDER_SHARE = 0.9


def border_diagnoses(parts) -> list[Diagnosis]:
    """What fetchColor does at faces' borders, where the record proves it:
    on a face, every direction it gets wrong asks the table's face and (u, v)
    but for a coordinate of exactly 1 asked as 0 (or 0 as 1): coordinate-wraps;
    or asks the table's (u, v) clamped to the narrowest range it ever asks
    on those faces (per coordinate and face size: a clamp to the border
    texels' centres depends on both), which is not [0, 1]: uv-clamped-inward.
    Each named with the faces where it is every mistake and nearly every
    direction asking the face is right (BORDER_SHARE), and one direction in
    numbers."""
    tol = fetch_record.UV_TOLERANCE
    # Per face size, over every set asked on it: the range asked per coordinate
    # (lo_u, lo_v, hi_u, hi_v), and which of those bounds a direction was moved
    # to (asked above the table's coordinate there, or below): the clamp's own
    # values, as the record shows them.
    # Per set: the directions judged on a recorded call at a face, with a (u, v).
    reads = [(verdict.case == fetch_record.READ) & (verdict.requested[0] >= 0)
             & np.isfinite(verdict.requested[1]).all(axis=1) for *_, verdict in parts]
    ranges: dict[tuple, np.ndarray] = {}
    for (_name, _dirs, size, _rec, verdict), read in zip(parts, reads):
        faces, uv = verdict.requested
        if not read.any():
            continue
        same = (read & (faces == verdict.table[0]))[:, None]
        with np.errstate(invalid="ignore"):
            moved = np.concatenate([(same & (uv > verdict.table[1] + tol)).any(axis=0),
                                    (same & (uv < verdict.table[1] - tol)).any(axis=0)])
        here = np.concatenate([uv[read].min(axis=0), uv[read].max(axis=0), moved])
        if tuple(size) in ranges:
            old = ranges[tuple(size)]
            here = np.concatenate([np.minimum(old[:2], here[:2]), np.maximum(old[2:4], here[2:4]),
                                   np.maximum(old[4:], here[4:])])
        ranges[tuple(size)] = here
    wrong_dirs, asked_faces, asked, table, bounds, sizes = [], [], [], [], [], []
    right_on = np.zeros(6, np.int64)        # directions that asked each face and are right
    for (_name, dirs, size, _rec, verdict), read in zip(parts, reads):
        faces, uv = verdict.requested
        np.add.at(right_on, faces[read & verdict.ok], 1)
        rows = np.flatnonzero(read & ~verdict.ok)
        if not len(rows):
            continue
        t_faces, t_uv = (x[rows] for x in verdict.touching)
        k = np.argmax(t_faces == faces[rows, None], axis=1)
        on = (t_faces == faces[rows, None]).any(axis=1)
        wrong_dirs.append(dirs[rows])
        asked_faces.append(np.where(on, faces[rows], -1))
        asked.append(uv[rows])
        table.append(np.where(on[:, None], t_uv[np.arange(len(rows)), k], np.nan))
        bounds.append(np.broadcast_to(ranges[tuple(size)], (len(rows), 8)))
        sizes.append(np.broadcast_to(np.asarray(size, np.float64), (len(rows), 2)))
    if not wrong_dirs:
        return []
    dirs, faces, got, want, bounds, sizes = (np.concatenate(x) for x in (wrong_dirs, asked_faces, asked, table,
                                                                           bounds, sizes))
    lo, hi, moved = bounds[:, :2], bounds[:, 2:4], bounds[:, 4:].astype(bool)
    with np.errstate(invalid="ignore"):
        close = np.abs(got - want) <= tol
        wrapped = (np.abs(want - 1) <= tol) & (np.abs(got) <= tol) | (np.abs(want) <= tol) & (np.abs(got - 1) <= tol)
        wraps = (close | wrapped).all(axis=1) & wrapped.any(axis=1)
        inward = ((lo > tol) | (hi < 1 - tol)).any(axis=1)
        clamps = inward & (np.abs(got - np.clip(want, lo, hi)) <= tol).all(axis=1) & ~close.all(axis=1)
    out = []
    # A face whose border is the only place it is wrong: nearly every direction that
    # asks it is right (not a face asked only at ties, as a face-order mistake does).
    mostly_right = [f for f in range(6) if right_on[f] >= BORDER_SHARE * (right_on[f] + (faces == f).sum())]
    for ident, explained in (("coordinate-wraps", wraps), ("uv-clamped-inward", clamps)):
        whole = [f for f in mostly_right if (faces == f).any() and explained[faces == f].all()]
        rows = np.flatnonzero(np.isin(faces, whole) & explained)
        if not len(rows):
            continue
        i = rows[0]
        words = {"count": len(rows), "faces": ", ".join(library.FACE_NAMES[f] for f in whole),
                 "call": describe_direction(dirs[i]), "face": library.FACE_NAMES[int(faces[i])],
                 "want": f"({want[i, 0]:.6g}, {want[i, 1]:.6g})", "got": f"({got[i, 0]:.6g}, {got[i, 1]:.6g})"}
        if ident == "coordinate-wraps":
            with np.errstate(invalid="ignore"):
                one_to_zero = ((np.abs(want[rows] - 1) <= tol) & (np.abs(got[rows]) <= tol)).any(axis=1)
            words.update(down=int(one_to_zero.sum()), up=int((~one_to_zero).sum()))
            text = _("%(call)s asks face %(face)s at (u, v) = %(got)s, where the table gives %(want)s: the opposite "
                     "side of the same face. Every wrong direction on %(faces)s is one of these %(count)d, each on a "
                     "face's border: %(down)d ask 0 where the table gives exactly 1, %(up)d ask 1 where it gives "
                     "0.") % words
        else:
            w, h = (int(x) for x in sizes[i])
            sides = []
            for k, (c, n, bound, word) in enumerate((("u", w, lo[i, 0], N_("at least")), ("v", h, lo[i, 1], N_("at least")),
                                                     ("u", w, hi[i, 0], N_("at most")), ("v", h, hi[i, 1], N_("at most")))):
                if moved[i, k]:
                    texels = (bound if k < 2 else 1 - bound) * n
                    sides.append(_("%(c)s %(word)s %(bound)s (%(texels)s texels from the border)") % {
                        "c": c, "word": _(word), "bound": f"{bound:.6g}", "texels": f"{texels:.3g}"})
            words.update(w=w, h=h, sides=and_list(sides))
            text = _("On %(w)d x %(h)d faces fetchColor asks for the table's (u, v) clamped: %(sides)s. %(call)s asks "
                     "face %(face)s at (u, v) = %(got)s, where the table gives %(want)s. Every wrong direction on "
                     "%(faces)s is one of these %(count)d, nearer a face's border than that.") % words
        out.append(Diagnosis(ident, text))
    return out


def _record_diagnoses(verdict, rec, dirs: np.ndarray, size: tuple[int, int]) -> list[Diagnosis]:
    """What the record shows beyond wrong requests, each with a direction that shows it."""
    out = []
    w, h = size
    not_returned = np.flatnonzero(verdict.case == fetch_record.NOT_RETURNED)
    if len(not_returned):
        i = not_returned[0]
        out.append(Diagnosis("fetch-not-returned", _(
            "%(call)s called readTexture %(calls)d times and returned %(got)s, which is none of the colours "
            "readTexture answered (%(answers)s).") % {
            "call": describe_direction(dirs[i]), "calls": int(rec.calls[i]), "got": format_vector(rec.values[i]),
            "answers": ", ".join(format_vector(t) for t in fetch_record.TAGS[:min(int(rec.calls[i]), len(fetch_record.TAGS))])}))
    otherwise = np.flatnonzero(verdict.case == fetch_record.ASKS_OTHERWISE)
    if len(otherwise):
        i = otherwise[0]
        out.append(Diagnosis("asks-otherwise", _(
            "%(call)s asks readTexture for something else when your own readTexture answers it than when the "
            "grader's recording does: %(count)d directions like it are judged wrong.") % {
            "call": describe_direction(dirs[i]), "count": len(otherwise)}))
    stray = np.flatnonzero(verdict.case == fetch_record.NO_FACE_START)
    if len(stray):
        i = stray[0]
        k = int(rec.returned[i])
        out.append(Diagnosis("address-not-face-start", _(
            "%(call)s called readTexture with an address %(offset)s floats after the first face's first texel: "
            "no face starts there (on these %(w)dx%(h)d faces one starts every %(stride)d floats).") % {
            "call": describe_direction(dirs[i]), "offset": f"{rec.offsets[i, k]:.0f}", "w": w, "h": h,
            "stride": w * h * 3}))
    return out
