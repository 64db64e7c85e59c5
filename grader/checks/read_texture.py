"""readTexture against the reference bilinear filter, and what is wrong when
it differs: the lookup is fitted to a family of models (texture_model) to
name its mistakes. The fetchColor checks judge through the student's own
readTexture called live (instruments.own_read), not through the model, so a
readTexture mistake never costs fetchColor's points and being hard to model
buys nothing."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..envmap import oracle, library as reference
from ..i18n import N_, _, and_list
from ..grading.results import FAILED, CheckResult, Diagnosis
from . import check, shown
from .instruments import fetch_record, texture_model as tm
from .instruments.compare import compare, explain, tolerance
from .context import CheckContext, failure_diagnoses, unique_diagnoses
from .instruments.textures import coordinate_faces, random_faces


@dataclass(frozen=True)
class ReadTextureFinding:
    """What the read_texture check tells the fetchColor checks."""
    ok: bool                    # every readTexture call matched the reference
    mistake: str | None = None  # the first diagnosis id of the fitted model's mistakes, if any
    fit: tm.Fit | None = None   # the student's readTexture as a member of the model family
    fraction: float = 1.0       # share of the check's calls that matched the handout's
    by_size: tuple[float, ...] = ()   # that share per face size (FACE_SIZES)
    by_face: tuple[float, ...] = ()   # per face (0-5), the share of the check's answers at generic (u, v) that differed, best size

    @property
    def mismatch(self) -> float:
        """The smallest share of calls that differed from the handout's over
        the face sizes tried: what the judges may expect on faces of their
        own (a readTexture honest on some sizes and not on others is told
        by its best size; instruments.own_read)."""
        return 1.0 - max(self.by_size or (self.fraction,))

    @property
    def face_mismatch(self) -> tuple[float, ...]:
        """(6,) per face, the share of the check's answers at generic (u, v)
        (neither on a texel boundary nor a centre nor in a border texel, as
        most of the judges' are; crashes left out, as the judges leave them
        out) that differed from the
        handout's, on the face size where that share is smallest: about
        what a readTexture that answers the same whoever calls it shows the
        judges on that face (instruments.own_read)."""
        return self.by_face or (1.0 - self.fraction,) * 6

    @property
    def model(self) -> tm.TextureModel | None:
        """The member that reproduces every answer (the handout's when ok), or
        None. For words only: fetchColor is judged through the student's own
        readTexture called live (instruments.own_read), never through this."""
        if self.ok:
            return tm.HANDOUT
        return self.fit.model if self.fit is not None and self.fit.fits else None


# Square and non-square faces, so a W/H mix-up shows; faces one texel tall,
# where every row is the last, so reading x = W faults on a guard page on
# every row (rows are contiguous: elsewhere x = W reads the next row's x = 0).
FACE_SIZES = ((16, 16), (13, 7), (9, 1))
# Every face: a readTexture read on some faces only could answer otherwise
# on the rest, where the judges would believe it (issue 18's red team). The
# last face included: reading past its end leaves the buffer.
FACES = (0, 1, 2, 3, 4, 5)


def generic(uv: np.ndarray, width: int, height: int) -> np.ndarray:
    """(n,) neither u nor v is 0, 1, a texel boundary or a centre, and no
    lattice point is outside the face: the generic points of sample_points
    inside the border texels, where (u, v) are like most of the judges' and
    an edge mistake reads nothing beyond the face (which differs by face:
    past the first and last it faults)."""
    steps = uv * (2 * width, 2 * height)
    p = uv * (width, height)
    inside = ((p >= 1) & (p < np.array([width, height]) - 1)).all(axis=1)
    return inside & (np.abs(steps - np.rint(steps)) > 1e-9).all(axis=1)


# Points between boundaries and centres, the same for every grading: six
# drawn per grading moved a share (an edge mistake's, by whether they fell in
# a border texel) and the score with it by up to a point (issue 30). The
# golden ratio's multiples: spread, and never a boundary or centre of any
# face size. Nothing here can be memorised: the random faces are drawn per grading.
GENERIC = tuple(np.modf(np.arange(1, 7) * (np.sqrt(5.0) - 1) / 2)[0])


def sample_points(width: int, height: int) -> np.ndarray:
    """(n, 2) (u, v): exactly 0 and 1, every texel boundary k/W and centre
    (k+0.5)/W, and generic points (GENERIC), in every combination of u and v kinds."""

    def axis(size):
        k = np.arange(size + 1)
        return np.unique(np.concatenate([[0.0, 1.0], k / size, (k[:-1] + 0.5) / size, GENERIC]))

    u, v = np.meshgrid(axis(width), axis(height), indexing="ij")
    return np.stack([u.ravel(), v.ravel()], axis=1)


# Every id mistake_diagnoses can give (tests/unit/grading/test_diagnosis_catalogue.py).
DIAGNOSIS_IDS = tm.MISTAKE_IDS


def mistake_diagnoses(model: tm.TextureModel) -> list[Diagnosis]:
    """One diagnosis per part of the fitted model that differs from the
    handout, each saying what the code does."""
    words = tm.describe_model(model)
    px, py = tm.axis_formula(model.x, 0), tm.axis_formula(model.y, 1)
    where = f"p = ({px}, {py})"
    detail = {   # %(where)s: the position the fitted model reads at, a formula
        "nearest-neighbor": N_("readTexture returns one texel and never blends (nearest neighbour, or weights that are always 0); it reads at %(where)s."),
        "weights-swapped": N_("readTexture blends with swapped weights: alpha goes to c00 and (1 - alpha) to c10 (or beta to c0)."),
        "constant-weights": N_("readTexture blends with weights that do not follow p (the same weight wherever p is)."),
        "half-texel-offset": N_("readTexture samples half a texel off: it uses %(where)s instead of p = (uW, vH)."),
        "texel-offset": N_("readTexture reads a whole texel off: it uses %(where)s instead of p = (uW, vH)."),
        "truncation-of-negatives": N_("readTexture rounds a negative p toward zero with (int): for p between -1 and 0 it takes x0 = 0 and a negative weight."),
        "unclamped-edge": N_("readTexture does not clamp its lattice points: at the edges it reads the next row, the texels before the face, or past the face."),
        "wrapped-edge": N_("readTexture wraps its lattice points around the face (x = W reads x = 0) instead of clamping them."),
        "scaled-by-size-minus-one": N_("readTexture uses %(where)s: the lattice is scaled by W - 1 instead of W."),
        "scaled-by-size-plus-one": N_("readTexture uses %(where)s: the lattice is scaled by W + 1 instead of W."),
        "rows-flipped": N_("readTexture reads row H-1-y: y = 0 must be the bottom row (v = 0)."),
        "columns-flipped": N_("readTexture reads column W-1-x: x = 0 must be the left column (u = 0)."),
        "texture-u-flipped": N_("readTexture runs u from right to left (it uses 1 - u)."),
        "texture-v-flipped": N_("readTexture runs v from top to bottom (it uses 1 - v; v = 0 must be the bottom row)."),
        "texture-uv-swapped": N_("readTexture uses u for the vertical position and v for the horizontal one."),
        "width-height-swapped": N_("readTexture mixes up the face width and height (u is scaled by the height or v by the width)."),
    }
    return [Diagnosis(i, _(detail[i]) % {"where": where} if i in detail else words) for i in tm.mistake_ids(model)]


# ---- readTexture described by measurement -------------------------------------

# A fit explaining at least this share of the answers is named (with the
# share); below it no model is stated, only what was measured.
NAMED_FIT = 0.9
WORKED_SIZE = (16, 16)


def texel_weights(read, face: int, w: int, h: int) -> np.ndarray | None:
    """(h, w) the weight of each texel of `face` in one readTexture answer,
    measured with impulse textures (one texel 1 per channel, the rest 0;
    three texels per texture): `read(faces)` returns that answer (3,), or
    None when it crashed."""
    n = w * h
    weights = np.zeros(n)
    for first in range(0, n, 3):
        faces = np.zeros((6, h, w, 3), np.float32)
        flat = faces[face].reshape(-1, 3)
        for c in range(min(3, n - first)):
            flat[first + c, c] = 1.0
        rgb = read(faces)
        if rgb is None or not np.isfinite(rgb).all():
            return None
        weights[first:first + 3] = rgb[:min(3, n - first)]
    return weights.reshape(h, w)


def _coordinate(c: float, n: int) -> str:
    k = c * n
    return f"{int(round(k))}/{n}" if abs(k - round(k)) < 1e-9 else f"{c:.4g}"


def _texels_in_words(weights: np.ndarray) -> str:
    ys, xs = np.nonzero(np.abs(weights) > 0.005)
    items = sorted(zip(xs, ys, weights[ys, xs]), key=lambda t: (-abs(t[2]), t[1], t[0]))
    if not items:
        return _("reads no texel of the face (every weight is 0)")
    if len(items) == 1 and abs(items[0][2] - 1) < 0.005:
        return _("reads texel (%(x)s, %(y)s) alone") % {"x": items[0][0], "y": items[0][1]}
    shown = items[:6]
    texels = and_list([f"({x}, {y})" for x, y, _w in shown])
    wts = and_list([f"{wt:.2f}" for _x, _y, wt in shown])
    text = _("mixes %(texels)s with weights %(weights)s") % {"texels": texels, "weights": wts}
    if len(items) > 6:
        text += _(" (and %(count)d more texels)") % {"count": len(items) - 6}
    return text


def worked_case(lookups, face: int, u: float, v: float, among: np.ndarray | None = None) -> str:
    """One readTexture call in numbers: which texels the handout reads at
    (u, v) and which the student's does, with their weights. `among`: the
    (m, 2) points (u, v) was drawn from; the handout is asked at all of them,
    so the question (grader.envmap.oracle) is the same whichever point failed."""
    w, h = WORKED_SIZE
    points = np.array([[u, v]]) if among is None else np.asarray(among, np.float64)
    at = int(np.flatnonzero((points == [u, v]).all(axis=1))[0])

    def theirs(faces):
        lookups.set_faces(faces)
        out = lookups.read_texture(face, np.array([[u, v]]))
        return np.asarray(out.values, np.float64)[0] if bool(np.asarray(out.evaluated)[0]) else None

    def handout(faces):
        return oracle.current().read_texture(faces, face, points, "bilinear")[at]

    ref, sub = texel_weights(handout, face, w, h), texel_weights(theirs, face, w, h)
    values = {"u": _coordinate(u, w), "v": _coordinate(v, h), "w": w, "h": h, "handout": _texels_in_words(ref)}
    if sub is None:
        return _("At u = %(u)s, v = %(v)s on a %(w)d x %(h)d face the handout %(handout)s; yours crashes there.") % values
    return _("At u = %(u)s, v = %(v)s on a %(w)d x %(h)d face the handout %(handout)s; yours %(yours)s.") % {
        **values, "yours": _texels_in_words(sub)}


def _single_texel(values: np.ndarray, texels: np.ndarray) -> np.ndarray:
    """(n,) each answer is exactly one texel's colour (a lookup that never blends)."""
    flat = texels.reshape(-1, 3).astype(np.float64)
    values = np.asarray(values, np.float64)
    with np.errstate(invalid="ignore"):
        # The red channel first, over every (answer, texel) pair; green and blue only where red is close.
        i, t = np.nonzero(np.abs(values[:, None, 0] - flat[None, :, 0]) <= 1e-6)
        close = (np.abs(values[i, 1:] - flat[t, 1:]) <= 1e-6).all(axis=1)
    single = np.zeros(len(values), bool)
    single[i[close]] = True
    return single


def _best_size_per_face(matched: np.ndarray, total: np.ndarray) -> tuple[float, ...]:
    """(6,) per face, the smallest share differing over the sizes with
    generic calls: a readTexture honest on one size and not another tells
    them apart (issue 18), so the judges expect its best."""
    sizes = total.sum(axis=1) > 0
    if not sizes.any():
        return ()
    share = 1.0 - matched[sizes] / np.maximum(total[sizes], 1)
    return tuple(float(x) for x in share.min(axis=0))


def earned(matched: int, given: int, total: int) -> float:
    """The share of the calls the starting code gets wrong (`total - given`
    of `total`: it reads the texel below-left of p, which is the handout's
    answer only where alpha = beta = 0 or the clamp makes it so) that
    readTexture put right, less any it broke: the starting code, and
    whatever behaves as it does, earns nothing (issue 30), the handout's
    earns everything, and each call put right is worth the same."""
    if matched >= total:
        return 1.0
    return max(matched - given, 0) / (total - given) if total > given else 0.0


@check()
@fetch_record.judged_in_context
def read_texture(ctx: CheckContext, result: CheckResult) -> ReadTextureFinding:
    """readTexture blends the four texels around (uW, vH) as the handout's equations (1)-(3) say."""
    total = matched = single = answered = given = 0
    lines, diagnoses = [], []
    worked_at: tuple[int, float, float, np.ndarray] | None = None
    by_size = []
    face_total = np.zeros((len(FACE_SIZES), 6), np.int64)   # generic (u, v) answered, per size and face
    face_matched = np.zeros((len(FACE_SIZES), 6), np.int64)
    for w, h in FACE_SIZES:
        size_total, size_matched = total, matched
        uv = sample_points(w, h)
        like_judges = generic(uv, w, h)
        for kind, faces in (("random", random_faces(w, h, ctx.seed)), ("coordinate", coordinate_faces(w, h))):
            texels = np.ascontiguousarray(faces, np.float32)
            ctx.lookups.set_faces(texels)
            for face in FACES:
                expected = oracle.current().read_texture(texels, face, uv, "bilinear")
                tol = tolerance(w, h, float(np.abs(faces[face]).max()))
                given_here = int(compare(oracle.current().read_texture(texels, face, uv, "nearest"), expected, tol).ok.sum())
                for placement in ("end", "start"):
                    outcome = ctx.lookups.read_texture(face, uv, placement)
                    cmp = compare(outcome.values, expected, tol)
                    total += len(uv)
                    matched += int(cmp.ok.sum())
                    given += given_here
                    answered_here = like_judges & np.asarray(outcome.evaluated, bool) & np.isfinite(outcome.values).all(axis=1)
                    face_total[len(by_size), face] += int(answered_here.sum())
                    face_matched[len(by_size), face] += int((cmp.ok & answered_here).sum())
                    diagnoses += failure_diagnoses(outcome.failures)
                    ran = np.asarray(outcome.evaluated, bool) & np.isfinite(outcome.values).all(axis=1)
                    if kind == "random":
                        answered += int(ran.sum())
                        single += int(_single_texel(outcome.values[ran], faces[face]).sum())
                    if worked_at is None and (w, h) == WORKED_SIZE and kind == "coordinate" and placement == "end":
                        wrong = [i for i in cmp.failures if ran[i]]
                        if wrong:
                            worked_at = (face, float(uv[wrong[0], 0]), float(uv[wrong[0], 1]), uv)
                    if cmp.fraction < 1.0 and len(lines) < 6:
                        name = reference.FACE_NAMES[face]
                        values = {"face": name, "w": w, "h": h}
                        lines.append(_({
                            ("random", "end"): N_("Face %(face)s, %(w)dx%(h)d random texels, inaccessible memory right after them:"),
                            ("random", "start"): N_("Face %(face)s, %(w)dx%(h)d random texels, inaccessible memory right before them:"),
                            ("coordinate", "end"): N_("Face %(face)s, %(w)dx%(h)d coordinate texels, inaccessible memory right after them:"),
                            ("coordinate", "start"): N_("Face %(face)s, %(w)dx%(h)d coordinate texels, inaccessible memory right before them:"),
                        }[kind, placement]) % values)
                        lines.append(explain(cmp, lambda i: f"readTexture(face {name}, u = {uv[i, 0]:.6g}, v = {uv[i, 1]:.6g})",
                                             outcome.values, expected, limit=3))
        by_size.append((matched - size_matched) / max(total - size_total, 1))
    result.fraction = earned(matched, given, total)
    result.metrics["cases"] = total
    result.metrics["given"] = given
    result.metrics["matched"] = matched
    # The lookup as a member of the model family: every mistake it makes, by
    # name (several at once), independent of any crash it also causes.
    fit = tm.fit(ctx.lookups, ctx.seed) if matched < total else None
    found = mistake_diagnoses(fit.model) if fit is not None and fit.fits else []
    named = fit is not None and not fit.fits and not fit.constant and fit.share >= NAMED_FIT
    if named:
        # Near fits are named, with the share they explain (never at a low fit).
        found = [Diagnosis(d.id, d.detail + _(" (The closest lookup the grader can model explains "
                                              "%(share)s of your readTexture's answers.)") % {"share": f"{fit.share:.0%}"})
                 for d in mistake_diagnoses(fit.closest)]
    if (fit is not None and not fit.fits and answered and single == answered
            and not any(d.id == "nearest-neighbor" for d in found)):
        # Measured, not modelled: every answer on random texels is one texel's colour.
        found.append(Diagnosis("nearest-neighbor", _("readTexture never blends: each of its %(count)d answers on "
                                                     "random texels is exactly one texel's colour (nearest neighbour, or weights "
                                                     "that are always 0 or 1).") % {"count": answered}))
    result.diagnoses = unique_diagnoses(found + diagnoses)
    mistake = found[0].id if found else None
    if matched < total:
        result.status = FAILED
        if fit is None or fit.constant:
            model_text = _("readTexture returns the same colour wherever it reads.")
        elif fit.fits:
            model_text = (_("What your readTexture does, found from textures that encode their positions.") + " "
                          + tm.describe_model(fit.model))
        elif named:
            model_text = (_("No lookup the grader can model reproduces all your readTexture's answers. The closest "
                            "explains %(share)s of them:") % {"share": f"{fit.share:.0%}"} + " " + tm.describe_model(fit.closest))
        else:
            # Below NAMED_FIT a model would be a guess: one call, measured.
            model_text = _("No lookup the grader can model reproduces your readTexture's answers.") + " " + (
                worked_case(ctx.lookups, *worked_at) if worked_at is not None else "")
        result.output = (_("%(wrong)d of %(total)d readTexture calls differ from the reference bilinear filter.")
                         % {"wrong": total - matched, "total": total} + " "
                         + _("The starting code already answers %(given)d of the %(total)d calls as the handout does, and points "
                             "are for what differs from it: max(0, %(matched)d - %(given)d) / (%(total)d - %(given)d) = "
                             "%(share)s.") % {"given": given, "matched": matched, "total": total,
                                             "share": f"{shown(result.fraction):.2%}"}
                         + "\n\n" + model_text + "\n\n" + "\n".join(lines))
    else:
        result.output = _("All %(total)d readTexture calls match the reference (u, v at 0, 1, texel boundaries, "
                          "centres and points between them).") % {"total": total}
    return ReadTextureFinding(ok=matched == total, mistake=mistake, fit=fit, fraction=result.fraction,
                              by_size=tuple(by_size),
                              by_face=_best_size_per_face(face_matched, face_total))
