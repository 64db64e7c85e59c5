"""readTexture against the handout's equations (1)-(3), judged and described
on its measured footprint (instruments.footprint): which texels it reads at
each probed (u, v), with what weights, next to the handout's, measured the
same way from the reference. A mistake is named only when the footprint
proves it; otherwise one call is shown in numbers."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..envmap import oracle, library
from ..i18n import N_, _, and_list
from ..grading.results import FAILED, CheckResult, Diagnosis
from . import check, shown
from .instruments import fetch_record
from .context import CheckContext, failure_diagnoses, unique_diagnoses
from .instruments import footprint as fp
from .instruments.compare import compare, tolerance
from .instruments.textures import random_faces


@dataclass(frozen=True)
class ReadTextureFinding:
    """What the read_texture check tells the fetchColor checks."""
    ok: bool                    # every probe's footprint and answers are the handout's
    mistake: str | None = None  # the first diagnosis id the footprint proves, if any
    fraction: float = 1.0       # the check's share (see Probes.scored)
    by_size: tuple[float, ...] = ()   # that share per face size (SIZES)


# Face sizes, in the order measured. The worker keeps one process per
# texel count (grader.worker.runner.set_faces), so 4x3 then 3x4 (and 8x6
# then 6x8) run in one process: a size kept from an earlier call (a static)
# shows there. The last 3x4 runs first in a fresh process: the two 3x4
# footprints differ only if readTexture keeps something between calls.
# Square and not, so a W/H mix-up and a transposed index show.
SIZES = ((4, 3), (3, 4), (8, 6), (6, 8), (5, 5), (3, 4))
STATE = (1, 5)           # the two 3x4 footprints: after 4x3 in one process, first in a fresh one
FACES = (0, 1, 2, 3, 4, 5)
PLACEMENTS = ("end", "start")


# A face larger than any measured, checked on answers alone (a footprint
# there would take a thousand textures): code that answers otherwise on
# large faces, as the judges' are, than on small ones shows here.
BIG = (96, 80)


def big_points(width: int, height: int) -> np.ndarray:
    """(n, 2) (u, v) on a big face where the handout blends: a point inside
    each of a fixed set of texels whose lattice points are inside the face
    (footprint.inside_texels), and the same with one coordinate at 0, 1, just
    below 1 or a texel edge. Fixed, so the score of a mistake made in some
    texels or in part of each does not depend on a draw."""
    cols = np.tile(np.arange(1, width - 1), 3)
    rows = 1 + (cols * np.repeat([7, 11, 13], width - 2)) % (height - 2)
    edges_u = np.concatenate([[0.0, 1.0, 1.0 - 2.0 ** -20], np.arange(1, 10) * (width // 10) / width])
    edges_v = np.concatenate([[0.0, 1.0, 1.0 - 2.0 ** -20], np.arange(1, 10) * (height // 10) / height])
    across_v = 1 + np.arange(8) * (height - 2) // 8
    across_u = 1 + np.arange(8) * (width - 2) // 8
    inside = fp.inside_texels
    return np.concatenate([np.stack([inside(cols, width, 0), inside(rows, height, 1)], axis=1),
                           np.stack([np.repeat(edges_u, 8), inside(np.tile(across_v, len(edges_u)), height, 1)], axis=1),
                           np.stack([inside(np.tile(across_u, len(edges_v)), width, 0), np.repeat(edges_v, 8)], axis=1)])


@dataclass
class Answers:
    """The big face: where every answer on random texels was the handout's."""
    uv: np.ndarray
    right: np.ndarray           # (n,)
    case: tuple | None          # (face, i, expected, actual) of the first that was not


def _answers(ctx: CheckContext, failures: list) -> Answers:
    w, h = BIG
    uv = big_points(w, h)
    texels = np.ascontiguousarray(random_faces(w, h, ctx.seed), np.float32)
    ctx.lookups.set_faces(texels)
    right, case = np.ones(len(uv), bool), None
    for face in FACES:
        expected = oracle.current().read_texture(texels, face, uv, "bilinear")
        tol = tolerance(w, h, float(np.abs(texels[face]).max()))
        for placement in PLACEMENTS:
            out = ctx.lookups.read_texture(face, uv, placement)
            failures.extend(out.failures)
            values = np.asarray(out.values, np.float64)
            same = compare(values, expected, tol).ok & np.asarray(out.evaluated, bool)
            if case is None and not same.all():
                i = int(np.flatnonzero(~same)[0])
                case = (face, i, expected[i], values[i])
            right &= same
    return Answers(uv, right, case)


@dataclass
class Measured:
    """One face size: both footprints and what the random texture showed."""
    student: fp.Footprint
    handout: fp.Footprint
    right: np.ndarray       # (n,) every answer on the random texture was the handout's
    unlinear_case: tuple | None     # (face, placement, i, predicted, actual): an answer no blend of the footprint

    @property
    def matched(self) -> np.ndarray:
        """(n,) the footprint is the handout's and every answer is too."""
        return self.student.equals(self.handout) & self.right

    @property
    def blends(self) -> np.ndarray:
        """(n,) the handout reads more than one texel here."""
        return (np.abs(self.handout.weights) > fp.TAP).sum(axis=(1, 2)) > 1

    def counted(self) -> tuple[int, int]:
        """(matched, counted): a probe where the handout blends counts; one
        where it reads a single texel counts only when yours differs (there
        the starting code already answers as the handout does, and a score
        there would be points for the code students were given)."""
        counted = self.blends | ~self.matched
        return int((self.matched & counted).sum()), int(counted.sum())


def _measure(ctx: CheckContext, size: tuple[int, int], failures: list) -> Measured:
    w, h = size
    uv = fp.probe_points(w, h)

    def theirs(faces):
        ctx.lookups.set_faces(faces)
        out = ctx.lookups.read_texture(fp.FACE, uv, "end")
        failures.extend(out.failures)
        values = np.asarray(out.values, np.float64).copy()
        values[~np.asarray(out.evaluated, bool)] = np.nan
        return values

    def handout(faces):
        return oracle.current().read_texture(faces, fp.FACE, uv, "bilinear")

    student, ref = fp.measure(theirs, size, uv), fp.measure(handout, size, uv)
    texels = np.ascontiguousarray(random_faces(w, h, ctx.seed), np.float32)
    ctx.lookups.set_faces(texels)
    right = np.ones(len(uv), bool)
    unlinear_case = None
    for face in FACES:
        expected = oracle.current().read_texture(texels, face, uv, "bilinear")
        predicted = fp.predict(student, texels[face])
        tol = tolerance(w, h, float(np.abs(texels[face]).max()))
        for placement in PLACEMENTS:
            out = ctx.lookups.read_texture(face, uv, placement)
            failures.extend(out.failures)
            values = np.asarray(out.values, np.float64)
            finite = np.asarray(out.evaluated, bool) & np.isfinite(values).all(axis=1)
            same = compare(values, expected, tol).ok & finite
            with np.errstate(invalid="ignore"):
                blend = (np.abs(values - predicted) <= tol).all(axis=1)
            odd = finite & student.answered & ~blend
            if unlinear_case is None and odd.any():
                i = int(np.flatnonzero(odd)[0])
                unlinear_case = (face, placement, i, predicted[i], values[i])
            right &= same
    return Measured(student, ref, right, unlinear_case)


# ---- readTexture described from its footprint -------------------------------

@dataclass(frozen=True)
class Lattice:
    """A statement about one axis of the footprint: the lattice point below
    t = S * c + offset, with c the face parameter `source` (0: u, 1: v),
    flipped to 1 - c or not, S the face size `size` (0: W, 1: H) plus
    `scale`, and the texels counted from the far end (`flip` "index")."""
    source: int
    size: int
    scale: int = 0
    offset: float = 0.0
    flip: str = ""

    def cost(self, which: int) -> float:
        return ((self.source != which) + (self.size != which) + (self.scale != 0) + (self.flip != "")
                + (0 if self.offset == 0 else 1))

    def formula(self, which: int) -> str:
        c = "uv"[self.source]
        if self.flip == "coordinate":
            c = f"(1 - {c})"
        n = "WH"[self.size]
        n = n if self.scale == 0 else f"({n} {'-' if self.scale < 0 else '+'} 1)"
        text = f"{c}{n}"
        if self.offset:
            text += f" {'-' if self.offset < 0 else '+'} {abs(self.offset):g}"
        return text


LATTICES = tuple(Lattice(source, size, scale, offset, flip)
                 for source in (0, 1) for size in (0, 1) for scale in (0, -1, 1)
                 for offset in (0.0, -0.5, 0.5, -1.0, 1.0) for flip in ("", "index", "coordinate"))
# How the weight of the texel above the lattice point follows f = t - floor(t):
# "rounded" (with offset 0.5 only) is the handout's blend from the lattice
# point round(t) instead of floor(t), weights 1.5 - f and f - 0.5; "other"
# follows the other axis's fraction instead of this one's.
MODES = ("linear", "swapped", "constant", "nearest", "rounded", "other")


def _lattice_point(lattice: Lattice, which: int, m: Measured) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(L, f, inside): the lattice point below t, t - L, and whether L and
    L + 1 both lie on the face, at each probe of `m`."""
    w, h = m.student.size
    c = m.student.uv[:, lattice.source]
    if lattice.flip == "coordinate":
        c = 1.0 - c
    t = ((w, h)[lattice.size] + lattice.scale) * c + lattice.offset
    low = np.floor(t)
    return low, t - low, (low >= 0) & (low <= (w, h)[which] - 2)


def _other_fraction(lattice: Lattice, m: Measured) -> np.ndarray:
    """(n,) the fraction of the other axis's p (the other coordinate times
    the other size) at each probe of `m`."""
    t = m.student.uv[:, 1 - lattice.source] * m.student.size[1 - lattice.size]
    return t - np.floor(t)


def _axis_modes(lattice: Lattice, which: int, measured: list[Measured],
                other: Lattice | None = None) -> tuple[set[str], int]:
    """(the weight modes consistent with every probe where `lattice` puts
    both taps inside the face, how many such probes): the footprint summed
    over the other axis reads only the lattice point L and L + 1. With
    `other`, the other axis's statement, only where that one's taps are
    inside the face too (an edge read on one axis moves the other's)."""
    modes, seen = set(MODES), 0
    for m in measured:
        low, f, inside = _lattice_point(lattice, which, m)
        if other is not None:
            inside &= _lattice_point(other, 1 - which, m)[2]
        axis = m.student.axis(which)
        if lattice.flip == "index":
            axis = axis[:, ::-1]
        usable = inside & m.student.separable
        if lattice.offset == 0.5:
            # Where p is exactly halfway between texels, rounding has a tie:
            # half up (floor(p + 0.5), std::round) and half to even
            # (nearbyint, lrint) differ there and nowhere else. Either is rounding.
            usable &= f != 0
        rows = np.flatnonzero(usable)
        if not len(rows):
            continue
        seen += len(rows)
        low = low[rows].astype(np.int64)
        a = axis[rows]
        at0, at1 = a[np.arange(len(rows)), low], a[np.arange(len(rows)), low + 1]
        rest = np.abs(a).sum(axis=1) - np.abs(at0) - np.abs(at1)
        if (rest > fp.TAP).any():
            return set(), seen
        f = f[rows]
        g = _other_fraction(lattice, m)[rows]
        near = lambda x, y: bool((np.abs(x - y) <= fp.WEIGHT_TOL).all())   # noqa: E731
        checks = {"linear": near(at1, f) and near(at0, 1 - f), "swapped": near(at1, 1 - f) and near(at0, f),
                  "constant": near(at0, 0.5) and near(at1, 0.5), "nearest": near(at0, 1.0) and near(at1, 0.0),
                  "rounded": lattice.offset == 0.5 and near(at1, f - 0.5) and near(at0, 1.5 - f),
                  "other": near(at1, g) and near(at0, 1 - g)}
        modes &= {k for k, ok in checks.items() if ok}
        if not modes:
            return set(), seen
    return modes, seen


def axis_statement(which: int, measured: list[Measured], other: Lattice | None = None) -> tuple[Lattice, str] | None:
    """The simplest lattice and weight mode that every probe of every size
    agrees with, along x (which = 0) or y (1), or None."""
    best = None
    for lattice in LATTICES:
        modes, seen = _axis_modes(lattice, which, measured, other)
        if seen < 8:
            continue
        for mode in modes:
            # A nearest texel at t + 0.5 is the rounded one: no offset in the code (a
            # rounded lattice point likewise).
            cost = lattice.cost(which) + (mode != "linear") - (_rounds(lattice, mode)) * 0.9
            if best is None or cost < best[0]:
                best = (cost, lattice, mode)
    return None if best is None else (best[1], best[2])


def _rounds(lattice: Lattice, mode: str) -> bool:
    """The statement's offset of 0.5 is a rounding in the code (the nearest
    texel, or a blend from the rounded lattice point), not an offset."""
    return mode in ("nearest", "rounded") and lattice.offset == 0.5


def lattice_ids(which: int, lattice: Lattice, mode: str) -> list[str]:
    """What one axis statement proves, as catalogue ids."""
    ids = []
    if mode == "swapped":
        ids.append("weights-swapped")
    if mode == "constant":
        ids.append("constant-weights")
    if mode == "rounded":
        ids.append("lattice-rounded")
    if mode == "other":
        ids.append("fractions-exchanged")
    if lattice.offset in (-0.5, 0.5) and not _rounds(lattice, mode):
        ids.append("half-texel-offset")
    if lattice.offset in (-1.0, 1.0):
        ids.append("texel-offset")
    if lattice.scale:
        ids.append("scaled-by-size-minus-one" if lattice.scale < 0 else "scaled-by-size-plus-one")
    if lattice.flip == "index":
        ids.append(("columns-flipped", "rows-flipped")[which])
    if lattice.flip == "coordinate":
        ids.append(("texture-u-flipped", "texture-v-flipped")[which])
    if lattice.source != which:
        ids.append("texture-uv-swapped")
    if lattice.size != which:
        ids.append("width-height-swapped")
    return ids


# What each axis statement proves, one sentence per id (the measurement follows it).
PROVES = {
    "weights-swapped": N_("readTexture gives the texel nearer to p the smaller weight."),
    "lattice-rounded": N_("readTexture takes its lattice point as p rounded, not floor(p): where the fraction of "
                          "p is 0.5 or more it reads the texel above p and the next one, with a weight above 1 and "
                          "a negative one (it extrapolates instead of blending the two texels around p)."),
    "fractions-exchanged": N_("readTexture weighs the texels along one axis by the other axis's fraction: beta "
                              "(of vH) where alpha (of uW) belongs, or alpha where beta belongs (alpha and beta, or "
                              "c01 and c10, exchanged)."),
    "constant-weights": N_("readTexture gives the texels it blends the same weight wherever p is."),
    "half-texel-offset": N_("readTexture reads half a texel away from p = (uW, vH)."),
    "texel-offset": N_("readTexture reads a whole texel away from p = (uW, vH)."),
    "scaled-by-size-minus-one": N_("readTexture scales u or v by the size minus 1."),
    "scaled-by-size-plus-one": N_("readTexture scales u or v by the size plus 1."),
    "rows-flipped": N_("readTexture counts rows from the top (row H - 1 - y)."),
    "columns-flipped": N_("readTexture counts columns from the right (column W - 1 - x)."),
    "texture-u-flipped": N_("readTexture runs u from right to left (1 - u)."),
    "texture-v-flipped": N_("readTexture runs v from top to bottom (1 - v)."),
    "texture-uv-swapped": N_("readTexture picks the column with v and the row with u."),
    "width-height-swapped": N_("readTexture scales one coordinate by the other axis's size."),
}


def axis_words(lattice: Lattice, mode: str, which: int) -> str:
    """One axis of the footprint in words: where and how it reads."""
    t = lattice.formula(which)
    unrounded = Lattice(lattice.source, lattice.size, lattice.scale, 0.0, lattice.flip).formula(which)
    if mode == "nearest":
        if lattice.offset == 0.5:
            text = _("reads the one texel nearest to %(t)s") % {"t": unrounded}
        else:
            text = _("reads the one texel at floor(%(t)s)") % {"t": t}
    elif mode == "rounded":
        text = _("blends texel round(%(t)s) and the next one with weights 1 - a and a, a = %(t)s - round(%(t)s) "
                 "(negative where the fraction of %(t)s is 0.5 or more)") % {"t": unrounded}
    elif mode == "other":
        other = f"{'uv'[1 - lattice.source]}{'WH'[1 - lattice.size]}"
        text = _("blends the two texels around %(t)s with weights that follow the fraction of %(other)s") % {
            "t": t, "other": other}
    else:
        text = {"linear": _("blends the two texels around %(t)s with weights that follow it"),
                "swapped": _("blends the two texels around %(t)s with the weights swapped"),
                "constant": _("blends the two texels around %(t)s with equal weights")}[mode] % {"t": t}
    if lattice.flip == "index":
        text += " " + (_("(columns counted from the right)"), _("(rows counted from the top)"))[which]
    return text


def transposed(measured: list[Measured]) -> bool:
    """Every answered probe reads the handout's texels (x, y) at flat index
    x * W + y instead of y * W + x (where that index is inside the face),
    and the footprint is not the handout's: a transposed texel index."""
    agree = 0
    for m in measured:
        w, h = m.student.size
        n = w * h
        ref = m.handout.weights.reshape(len(m.handout.uv), h, w)
        mapped = np.zeros((len(ref), n))
        inside = np.ones(len(ref), bool)
        ys, xs = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
        k = (xs * w + ys).ravel()
        flat = ref.reshape(len(ref), -1)
        for j, target in enumerate(k):
            col = flat[:, j]
            if target >= n:
                inside &= np.abs(col) <= fp.TAP
            else:
                mapped[:, target] += col
        rows = inside & m.student.answered
        with np.errstate(invalid="ignore"):
            same = (np.abs(m.student.weights.reshape(len(ref), -1)[rows] - mapped[rows]) <= fp.WEIGHT_TOL).all(axis=1)
        if not same.all():
            return False
        agree += int(rows.sum())
    return agree > 0 and not all(m.student.equals(m.handout).all() for m in measured)


def _number(x: float) -> str:
    return f"{x:.4g}"


def _coordinate(c: float, n: int) -> str:
    k = c * n
    if abs(k - round(k)) >= 1e-9:
        return _number(c)
    return {0: "0", n: "1"}.get(int(round(k)), f"{int(round(k))}/{n}")


def texels_in_words(taps: list[tuple[int, int, float]]) -> str:
    if not taps:
        return _("reads no texel of the face (every weight is 0)")
    if len(taps) == 1 and abs(taps[0][2] - 1) <= fp.WEIGHT_TOL:
        return _("reads texel (%(x)s, %(y)s) alone") % {"x": taps[0][0], "y": taps[0][1]}
    shown = taps[:6]
    text = _("mixes %(texels)s with weights %(weights)s") % {
        "texels": and_list([f"({x}, {y})" for x, y, _w in shown]),
        "weights": and_list([f"{wt:.4g}" for _x, _y, wt in shown])}
    if len(taps) > 6:
        text += _(" (and %(count)d more texels)") % {"count": len(taps) - 6}
    return text


def worked_case(m: Measured, i: int) -> str:
    """Probe i in numbers: the texels and weights the handout's equations
    read, and the student's."""
    w, h = m.student.size
    u, v = m.student.uv[i]
    values = {"u": _coordinate(u, w), "v": _coordinate(v, h), "w": w, "h": h,
              "handout": texels_in_words(m.handout.taps(i))}
    if not m.student.answered[i]:
        return _("At u = %(u)s, v = %(v)s on a %(w)d x %(h)d face the handout %(handout)s; "
                 "yours crashes there.") % values
    return _("At u = %(u)s, v = %(v)s on a %(w)d x %(h)d face the handout %(handout)s; yours %(yours)s.") % {
        **values, "yours": texels_in_words(m.student.taps(i))}


def _first_wrong(measured: list[Measured]) -> tuple[Measured, int] | None:
    """The first probe whose footprint differs, preferring one where the
    handout blends inside the face (the plainest case to read)."""
    for want_blend in (True, False):
        for m in measured:
            wrong = ~m.student.equals(m.handout) & (m.blends if want_blend else True)
            if wrong.any():
                return m, int(np.flatnonzero(wrong)[0])
    return None


def equal_weights(measured: list[Measured]) -> tuple[Measured, int, int, int] | None:
    """(a size, a probe there, k, how many probes) where every probe that
    reads the most texels (k >= 2) gives each of them weight 1/k, at least 8
    such probes, and the handout's weights differ there: fixed weights of
    any window (two taps at 1/2 are the lattice statements' "constant")."""
    k = max(int((np.abs(m.student.weights[m.student.answered]) > fp.TAP).sum(axis=(1, 2)).max(initial=0))
            for m in measured)
    if k < 2:
        return None
    rows, example = 0, None
    for m in measured:
        weights = np.nan_to_num(m.student.weights)
        taps = np.abs(weights) > fp.TAP
        widest = m.student.answered & (taps.sum(axis=(1, 2)) == k)
        if not (np.abs(np.where(taps, weights, 1.0 / k) - 1.0 / k) <= fp.WEIGHT_TOL)[widest].all():
            return None
        rows += int(widest.sum())
        unequal = widest & _unequal(np.nan_to_num(m.handout.weights))
        if example is None and unequal.any():
            example = (m, int(np.flatnonzero(unequal)[0]))
    if rows < 8 or example is None:
        return None
    return example[0], example[1], k, rows


def _unequal(weights: np.ndarray) -> np.ndarray:
    """(n,) the footprint's taps do not all have one weight."""
    taps = np.abs(weights) > fp.TAP
    big = np.where(taps, weights, -np.inf).max(axis=(1, 2))
    small = np.where(taps, weights, np.inf).min(axis=(1, 2))
    return big - small > fp.WEIGHT_TOL


def handout_lattice(m: Measured) -> tuple[np.ndarray, np.ndarray]:
    """(x0, y0) at each probe of `m`: the handout's lower lattice point,
    clamp(floor(uW), 0, W - 1) and clamp(floor(vH), 0, H - 1)."""
    w, h = m.student.size
    x0 = np.clip(np.floor(m.student.uv[:, 0] * w), 0, w - 1).astype(np.int64)
    y0 = np.clip(np.floor(m.student.uv[:, 1] * h), 0, h - 1).astype(np.int64)
    return x0, y0


# edge-single-texel's proof, by the borders where the footprint differs.
EDGE_WORDS = {
    "both": N_("On the last column (x0 = W - 1) and the last row (y0 = H - 1) readTexture returns texel (x0, y0) "
               "alone; the handout blends there too: its clamped lattice points read column W - 1 twice, so it still "
               "blends the two rows around vH by beta (and, on the last row, the two columns around uW by alpha). "
               "Every one of the %(count)d probes that differ from the handout's is such a probe."),
    "column": N_("On the last column (x0 = W - 1) readTexture returns texel (x0, y0) alone; the handout blends there "
                 "too: its clamped lattice points read column W - 1 twice, so it still blends the two rows around vH "
                 "by beta. Every one of the %(count)d probes that differ from the handout's is such a probe; on the "
                 "last row yours blends as the handout does."),
    "row": N_("On the last row (y0 = H - 1) readTexture returns texel (x0, y0) alone; the handout blends there too: "
              "its clamped lattice points read row H - 1 twice, so it still blends the two columns around uW by "
              "alpha. Every one of the %(count)d probes that differ from the handout's is such a probe; on the last "
              "column yours blends as the handout does."),
}


def single_texel_at_edges(measured: list[Measured]) -> tuple[Measured, int, int, str] | None:
    """(a size, a probe there, how many probes, the borders: "both",
    "column" or "row") where every probe whose footprint differs from the
    handout's lies on the last column or the last row (x0 = W - 1 or
    y0 = H - 1), where the handout still blends along the other axis, and
    reads texel (x0, y0) alone there: an early return at the border instead
    of clamped lattice points. None unless every differing probe is such a
    probe (and one is)."""
    count, example, column, row = 0, None, False, False
    for m in measured:
        w, h = m.student.size
        differs = ~m.student.equals(m.handout)
        if not differs.any():
            continue
        x0, y0 = handout_lattice(m)
        border = (x0 == w - 1) | (y0 == h - 1)
        alone = np.zeros(len(x0), bool)
        weights = np.nan_to_num(m.student.weights)
        for i in np.flatnonzero(differs & border & m.student.answered):
            expected = np.zeros((h, w))
            expected[y0[i], x0[i]] = 1.0
            alone[i] = bool((np.abs(weights[i] - expected) <= fp.WEIGHT_TOL).all())
        if not (alone[differs]).all():
            return None
        count += int(differs.sum())
        column |= bool((differs & (x0 == w - 1)).any())
        row |= bool((differs & (y0 == h - 1)).any())
        if example is None:
            example = (m, int(np.flatnonzero(differs)[0]))
    if example is None:
        return None
    return (*example, count, "both" if column and row else "column" if column else "row")


def edge_ids(measured: list[Measured], failures: list) -> list[Diagnosis]:
    """What the footprint shows at the face's edges, where the handout
    clamps its lattice points: texels from both ends of one row or column
    (wrapped), the next row's first texel after a row's last (unclamped),
    or a read outside the face the worker caught at a border (u, v)."""
    found = []
    for m in measured:
        w, h = m.student.size
        read = np.abs(np.nan_to_num(m.student.weights)) > fp.TAP      # (n, H, W)
        # Both ends of one row, in the same rows (columns), as x mod W reads
        # them, with a column between them not read: a window as wide as the
        # face (a 3x3 box on a 3-texel face) reads both ends without wrapping.
        cols, rows = read.any(axis=1), read.any(axis=2)                   # (n, W), (n, H)
        wraps_x = (read[:, :, 0].any(axis=1) & (read[:, :, 0] == read[:, :, w - 1]).all(axis=1)
                   & ~cols.all(axis=1)) if w >= 3 else None
        wraps_y = (read[:, 0, :].any(axis=1) & (read[:, 0, :] == read[:, h - 1, :]).all(axis=1)
                   & ~rows.all(axis=1)) if h >= 3 else None
        for wraps in (wraps_x, wraps_y):
            if wraps is not None and wraps.any():
                found.append(("wrapped-edge", m, int(np.flatnonzero(wraps)[0])))
        # A row's last texel with the next row's first, the rows of one one above
        # the other's: x = W (or x = -1) read as the memory lies.
        last, first = read[:, :, w - 1], read[:, :, 0]
        jump = (last.any(axis=1) & (first[:, 1:] == last[:, :-1]).all(axis=1) & ~first[:, 0] & ~last[:, h - 1]
                if w >= 3 and h >= 2 else np.zeros(len(read), bool))
        if jump.any():
            found.append(("unclamped-edge", m, int(np.flatnonzero(jump)[0])))
    out = []
    for ident, m, i in found:
        if ident not in {d.id for d in out}:
            detail = {"wrapped-edge": N_("readTexture reads both ends of a row or column at once: it wraps its "
                                         "lattice points around the face instead of clamping them."),
                      "unclamped-edge": N_("readTexture reads a row's last texel together with the next row's "
                                           "first: x = W (or x = -1) is not clamped to the face.")}[ident]
            out.append(Diagnosis(ident, _(detail) + " " + worked_case(m, i)))
    outside = [f for f in failures if f.kind == "out-of-bounds-read"]
    if outside and "unclamped-edge" not in {d.id for d in out}:
        out.append(Diagnosis("unclamped-edge", _("readTexture reads outside the face (the worker caught %(call)s "
                                                 "reading memory before or after the face's texels): its lattice "
                                                 "points are not clamped to the face.") % {"call": outside[0].input}))
    return out


# Every id the description can give (tests/unit/grading/test_diagnosis_catalogue.py).
DIAGNOSIS_IDS = ("nearest-neighbor", "weights-swapped", "constant-weights", "half-texel-offset", "texel-offset",
                 "lattice-rounded", "fractions-exchanged", "edge-single-texel",
                 "truncation-of-negatives", "unclamped-edge", "wrapped-edge", "scaled-by-size-minus-one",
                 "scaled-by-size-plus-one", "rows-flipped", "columns-flipped", "texture-u-flipped",
                 "texture-v-flipped", "texture-uv-swapped", "width-height-swapped", "texel-index-transposed",
                 "not-a-blend", "kept-between-calls", "face-size-dependent")


def describe(measured: list[Measured], failures: list) -> tuple[list[Diagnosis], list[str]]:
    """The diagnoses the footprints prove, and the sentences that show them."""
    found: list[Diagnosis] = []
    lines: list[str] = []
    first, again = measured[STATE[0]], measured[STATE[1]]
    kept = first.student.answered & again.student.answered & ~first.student.equals(again.student)
    naming = measured
    if kept.any():
        i = int(np.flatnonzero(kept)[0])
        w, h = first.student.size
        u, v = first.student.uv[i]
        found.append(Diagnosis("kept-between-calls", _(
            "On the same %(w)d x %(h)d face and texels, readTexture reads differently after a %(pw)d x %(ph)d face "
            "in the same process than it does first in a fresh one: at u = %(u)s, v = %(v)s it %(after)s after "
            "it, and %(fresh)s when fresh. Something is kept from an earlier call (a static, a cache).") % {
            "w": w, "h": h, "pw": measured[STATE[0] - 1].student.size[0], "ph": measured[STATE[0] - 1].student.size[1],
            "u": _coordinate(u, w), "v": _coordinate(v, h),
            "after": texels_in_words(first.student.taps(i)), "fresh": texels_in_words(again.student.taps(i))}))
        # Describe it from the sizes each process saw first.
        naming = [m for k, m in enumerate(measured) if k == 0 or SIZES[k][0] * SIZES[k][1] != SIZES[k - 1][0] * SIZES[k - 1][1]]
    unlinear = [m for m in measured if m.unlinear_case is not None]
    if unlinear:
        m = unlinear[0]
        face, placement, i, predicted, actual = m.unlinear_case
        w, h = m.student.size
        u, v = m.student.uv[i]
        found.append(Diagnosis("not-a-blend", _(
            "readTexture's answer is not a fixed blend of the texels it reads: at u = %(u)s, v = %(v)s on face "
            "%(face)s of a %(w)d x %(h)d random texture, the weights measured with one-texel textures (it %(taps)s) "
            "give %(predicted)s, and it returned %(actual)s.") % {
            "u": _coordinate(u, w), "v": _coordinate(v, h), "face": library.FACE_NAMES[face], "w": w, "h": h,
            "taps": texels_in_words(m.student.taps(i)),
            "predicted": "(" + ", ".join(_number(x) for x in predicted) + ")",
            "actual": "(" + ", ".join(_number(x) for x in actual) + ")"}))
    answered = [m for m in naming if m.student.answered.any()]
    single = all(((np.abs(m.student.weights[m.student.answered]) > fp.TAP).sum(axis=(1, 2)) == 1).all()
                 for m in answered)
    if answered and single:
        found.append(Diagnosis("nearest-neighbor", _(
            "readTexture never blends: at every one of the %(count)d (u, v) probed it reads a single texel.")
            % {"count": sum(int(m.student.answered.sum()) for m in answered)}))
    if answered and transposed(answered):
        found.append(Diagnosis("texel-index-transposed", _(
            "readTexture reads the texels the handout reads at (x, y) from index x * W + y: the texel index is "
            "transposed (on a square face it reads texel (y, x); on others, texels of other rows or past the face).")))
    else:
        statements = [axis_statement(which, answered) if answered else None for which in (0, 1)]
        for which in (0, 1):
            if statements[which] is None and statements[1 - which] is not None:
                statements[which] = axis_statement(which, answered, statements[1 - which][0])
        if all(s is not None for s in statements):
            ids = []
            for which, (lattice, mode) in enumerate(statements):
                ids += [i for i in lattice_ids(which, lattice, mode) if i not in ids]
            if ids:
                (lx, mx), (ly, my) = statements
                measured_words = _("Measured on every face size, along x it %(x)s; along y it %(y)s.") % {
                    "x": axis_words(lx, mx, 0), "y": axis_words(ly, my, 1)}
                for i in ids:
                    found.append(Diagnosis(i, _(PROVES[i]) + " " + measured_words))
                negative = [m for m in answered if (np.nan_to_num(m.student.weights) < -fp.TAP).any()]
                if negative and any(lat.offset < 0 for lat in (lx, ly)):
                    m = negative[0]
                    i = int(np.flatnonzero((np.nan_to_num(m.student.weights) < -fp.TAP).any(axis=(1, 2)))[0])
                    found.append(Diagnosis("truncation-of-negatives", _(
                        "readTexture gives a texel a negative weight where p is below 0: (int) truncates toward "
                        "zero. ") + worked_case(m, i)))
    if answered and not single and "constant-weights" not in {d.id for d in found}:
        equal = equal_weights(answered)
        if equal is not None:
            m, i, k, count = equal
            found.append(Diagnosis("constant-weights", _(PROVES["constant-weights"]) + " " + _(
                "At %(count)d of the (u, v) probed it reads %(k)d texels, each with weight 1/%(k)d, whatever the "
                "fraction of p.") % {"count": count, "k": k} + " " + worked_case(m, i)))
    if not any(d.id in ("kept-between-calls", "texel-index-transposed") for d in found):
        # (Either reads texels the edges' words would misread.)
        found += [d for d in edge_ids(measured, failures) if d.id not in {f.id for f in found}]
        alone = single_texel_at_edges(naming) if not found else None
        if alone is not None:
            m, i, count, sides = alone
            found.append(Diagnosis("edge-single-texel", _(EDGE_WORDS[sides]) % {"count": count} + " "
                                   + worked_case(m, i)))
    wrong = _first_wrong(measured)
    if wrong is not None:
        lines.append(worked_case(*wrong))
    return found, lines


@check()
@fetch_record.judged_in_context
def read_texture(ctx: CheckContext, result: CheckResult) -> ReadTextureFinding:
    """readTexture blends the four texels around (uW, vH) as the handout's equations (1)-(3) say."""
    failures: list = []
    measured = [_measure(ctx, size, failures) for size in SIZES]
    big = _answers(ctx, failures)
    counts = [m.counted() for m in measured] + [(int(big.right.sum()), len(big.uv))]
    matched, counted = sum(c[0] for c in counts), sum(c[1] for c in counts)
    probes = sum(len(m.student.uv) for m in measured)
    exact = all(m.matched.all() for m in measured) and big.right.all() and not failures
    # Scored on the face size where it does worst: code right on some sizes
    # only (a static, a path for small faces) is not right on the judges'.
    result.fraction = min(c[0] / c[1] for c in counts if c[1]) if counted else 1.0
    result.metrics["cases"] = counted
    result.metrics["matched"] = matched
    by_size = tuple(c[0] / c[1] if c[1] else 1.0 for c in counts[:len(SIZES)])
    if exact:
        result.output = _("At all %(total)d (u, v) probed on %(sizes)d face sizes, readTexture reads the texels the "
                          "handout reads with its weights (u, v at 0, 1, just below 1, texel edges, centres, quarters "
                          "and one more point inside each texel), and blends random texels as those weights say; at all %(big)d (u, v) on a "
                          "%(w)d x %(h)d face of random texels it answers as the handout does.") % {
            "total": probes, "sizes": len(set(SIZES)), "big": len(big.uv), "w": BIG[0], "h": BIG[1]}
        return ReadTextureFinding(ok=True, fraction=result.fraction, by_size=by_size)
    found, lines = describe(measured, failures)
    if big.case is not None and all(m.matched.all() for m in measured):
        face, i, expected, actual = big.case
        found.append(Diagnosis("face-size-dependent", _(
            "readTexture answers as the handout does on every small face measured, and otherwise on a "
            "%(w)d x %(h)d face: at u = %(u)s, v = %(v)s on face %(face)s of random texels the handout gives "
            "%(expected)s, yours %(actual)s.") % {
            "w": BIG[0], "h": BIG[1], "u": _number(big.uv[i, 0]), "v": _number(big.uv[i, 1]),
            "face": library.FACE_NAMES[face], "expected": "(" + ", ".join(_number(x) for x in expected) + ")",
            "actual": "(" + ", ".join(_number(x) for x in actual) + ")"}))
    result.status = FAILED
    caught = failure_diagnoses(failures)
    explains = [d for d in found if d.id in ("texel-index-transposed", "kept-between-calls")]
    if explains:
        # Its reads past the face are what the proven mistake reads there:
        # the worker's words ("clamp the lattice points") would send the fix
        # elsewhere. The observation stays, in the mistake's detail.
        outside = [d for d in caught if d.id == "out-of-bounds-read"]
        if outside:
            first = explains[0]
            found[found.index(first)] = Diagnosis(first.id, first.detail + " " + _(
                "This is also why it reads outside the face: %(caught)s") % {"caught": outside[0].detail})
        caught = [d for d in caught if d.id != "out-of-bounds-read"]
    result.diagnoses = unique_diagnoses(found + caught)
    sizes = and_list([f"{w} x {h}" for w, h in dict.fromkeys(SIZES)])
    result.output = "\n\n".join([
        _("%(wrong)d of %(counted)d (u, v) probes that count read other texels or weights than the handout's "
          "(faces %(sizes)s; the weights of every texel were measured with textures that are 1 on one texel and 0 "
          "elsewhere), or answered otherwise on a %(w)d x %(h)d face of random texels. A probe counts where the "
          "handout blends texels, and where it reads one texel only if yours differs. The score is the share right "
          "on the face size where it is lowest (%(worst)s).") % {
            "counted": counted, "wrong": counted - matched, "sizes": sizes, "w": BIG[0], "h": BIG[1],
            "worst": f"{shown(result.fraction):.2%}"},
        *([_("What the measurements prove:") + "\n" + "\n".join(f"- {d.detail}" for d in found)] if found else
          [_("No single mistake explains every measurement; one of them, in numbers:")]),
        *lines])
    mistake = found[0].id if found else None
    return ReadTextureFinding(ok=False, mistake=mistake, fraction=result.fraction, by_size=by_size)
