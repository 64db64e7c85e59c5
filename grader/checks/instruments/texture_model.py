"""readTexture modelled on its own: a small family of lookups, an evaluator
for each member written in numpy (independent of the C reference), and a fit
that finds the member reproducing a submission's answers on textures that
encode position.

A member is two axis models (x from one face coordinate, y from the other)
plus nothing else: each axis says which coordinate drives it (u or v), which
size scales it (W or H), the lattice scale (N, N - 1, N + 1), an offset in
texels, how p becomes a lattice index (floor, truncation toward zero,
rounding), the edge handling (clamp, wrap, none = read wherever the index
points), the weights (linear, swapped, nearest = one texel, constant 0.5)
and whether the index runs backwards (rows read top-down) or the coordinate
does (1 - v). The handout's bilinear filter is the member with every part at
its default (`HANDOUT`).

Why a family rather than a list of known mistakes: students combine them
(rows flipped + W - 1 + half a texel + truncation), and a mistake the grader
does not know must never be blamed on fetchColor. The fit is cheap because
position-encoding textures (R = x + 1, G = y + 1) separate the axes: each
axis is fitted on its own channel, then the few combinations that survive
are checked in two dimensions on the coordinate texture and on a random one
(which exposes the weights: a ramp is reproduced by many blends).
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np

from ...i18n import _
from .compare import tolerance
from .textures import coordinate_faces, random_faces

SCALES = ("N", "N-1", "N+1")
OFFSETS = (0.0, -0.5, 0.5, -1.0, 1.0)
ROUNDINGS = ("floor", "trunc", "round")
EDGES = ("clamp", "wrap", "none")
WEIGHTS = ("linear", "swapped", "nearest", "half")
FLIPS = ("no", "index", "coordinate")


@dataclass(frozen=True)
class Axis:
    """How one lattice axis (x: columns, y: rows) is computed."""
    source: str = "own"        # "own": x from u, y from v; "other": swapped
    size: str = "own"          # "own": x scaled by W, y by H; "other": by the other size
    scale: str = "N"           # p = c * (N + this)
    offset: float = 0.0        # texels added to p
    rounding: str = "floor"    # lattice point below p: floor, trunc (toward zero), round
    edge: str = "clamp"        # clamp to [0, N-1], wrap mod N, none (read out of the face)
    weights: str = "linear"    # linear (handout), swapped, nearest (one texel), half (0.5)
    flip: str = "no"           # "index": N-1-i (rows top-down), "coordinate": 1 - c

    @property
    def cost(self) -> float:
        """How far from the handout: among members that explain the same
        answers, the simplest is reported."""
        c = 0.0
        c += self.source != "own"
        c += self.size != "own"
        c += self.scale != "N"
        c += 0 if self.offset == 0 else 1.0 if abs(self.offset) == 0.5 else 1.2
        c += {"floor": 0.0, "trunc": 0.6, "round": 1.1}[self.rounding]
        c += {"clamp": 0.0, "wrap": 1.0, "none": 0.9}[self.edge]
        c += {"linear": 0.0, "swapped": 1.0, "nearest": 1.0, "half": 1.0}[self.weights]
        c += {"no": 0.0, "index": 1.0, "coordinate": 1.05}[self.flip]
        return c


@dataclass(frozen=True)
class TextureModel:
    x: Axis = Axis()
    y: Axis = Axis()

    @property
    def cost(self) -> float:
        return self.x.cost + self.y.cost

    @property
    def single_texel(self) -> bool:
        return self.x.weights == "nearest" and self.y.weights == "nearest"


HANDOUT = TextureModel()


def all_axes():
    for parts in itertools.product(("own", "other"), ("own", "other"), SCALES, OFFSETS, ROUNDINGS,
                                   EDGES, WEIGHTS, FLIPS):
        yield Axis(*parts)


# ---- the evaluator --------------------------------------------------------

def _round(p: np.ndarray, how: str) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        if how == "floor":
            return np.floor(p)
        if how == "trunc":
            return np.trunc(p)
        return np.floor(p + 0.5)


def axis_taps(axis: Axis, c: np.ndarray, size: int, n: int):
    """(i0, i1, w1, inside): the two lattice indices read along this axis,
    the weight of i1, and where both indices are inside [0, n). `size` is the
    face size that scales p, `n` the number of texels along the axis."""
    c = np.asarray(c, np.float64)
    if axis.flip == "coordinate":
        c = 1.0 - c
    s = size + {"N": 0, "N-1": -1, "N+1": 1}[axis.scale]
    p = c * s + axis.offset
    base = _round(p, axis.rounding)
    frac = p - base
    i0 = base.astype(np.int64)
    if axis.weights == "nearest":
        i1, w1 = i0, np.zeros_like(p)
    else:
        i1 = i0 + 1
        w1 = {"linear": frac, "swapped": 1.0 - frac, "half": np.full_like(p, 0.5)}[axis.weights]
    if axis.edge == "clamp":
        i0, i1 = np.clip(i0, 0, n - 1), np.clip(i1, 0, n - 1)
    elif axis.edge == "wrap":
        i0, i1 = np.mod(i0, n), np.mod(i1, n)
    if axis.flip == "index":
        i0, i1 = n - 1 - i0, n - 1 - i1
    inside = (i0 >= 0) & (i0 < n) & (i1 >= 0) & (i1 < n)
    return i0, i1, w1, inside


def _axis_inputs(axis: Axis, uv: np.ndarray, which: int, width: int, height: int):
    own, other = (uv[:, 0], uv[:, 1]) if which == 0 else (uv[:, 1], uv[:, 0])
    sizes = (width, height) if which == 0 else (height, width)
    c = own if axis.source == "own" else other
    size = sizes[0] if axis.size == "own" else sizes[1]
    return c, size, sizes[0]


def evaluate(model: TextureModel, face_texels: np.ndarray, uv: np.ndarray):
    """(values (n, 3), past_end (n,)) of `model` on one face (H, W, 3) at
    (u, v) (n, 2), with the face in memory as the worker places it for
    probing ("end"): an unclamped index reads the neighbouring row while it
    stays inside the face's memory, zeros before the face's first texel (the
    page the face sits on is zero-filled), and faults after its last one.
    Rows that read past the end are NaN and flagged."""
    texels = np.asarray(face_texels)
    return evaluate_in_buffer(model, texels[None], np.zeros(len(np.reshape(uv, (-1, 2))), np.int64), uv)


def evaluate_in_buffer(model: TextureModel, faces: np.ndarray, face: np.ndarray, uv: np.ndarray):
    """As `evaluate`, with readTexture given the address of face `face[i]`
    (n,) of the buffer `faces` (k, H, W, 3) holding k faces one after the
    other, as fetchColor sees them: an unclamped read past one face reads
    the next one."""
    faces = np.asarray(faces, np.float64)
    count, height, width = faces.shape[:3]
    flat = np.concatenate([np.zeros((1, 3)), faces.reshape(-1, 3)])
    uv = np.asarray(uv, np.float64).reshape(-1, 2)
    base = np.asarray(face, np.int64) * (width * height)
    x0, x1, a, _ = axis_taps(model.x, *_axis_inputs(model.x, uv, 0, width, height))
    y0, y1, b, _ = axis_taps(model.y, *_axis_inputs(model.y, uv, 1, width, height))
    total = count * width * height

    def read(x, y):
        k = base + y * width + x
        return flat[np.where(k < 0, 0, np.minimum(k, total - 1) + 1)], k >= total

    a, b = a[:, None], b[:, None]
    if model.x.weights == "nearest" and model.y.weights == "nearest":
        out, past = read(x0, y0)
    else:
        # The handout's order of operations: (1), (2), then (3).
        c00, o00 = read(x0, y0)
        c10, o10 = read(x1, y0)
        c01, o01 = read(x0, y1)
        c11, o11 = read(x1, y1)
        c0 = (1.0 - a) * c00 + a * c10
        c1 = (1.0 - a) * c01 + a * c11
        out = (1.0 - b) * c0 + b * c1
        past = o00 | o10 | o01 | o11
    out = np.where(past[:, None], np.nan, out)
    return out, past


def fake_read_texture(model: TextureModel) -> Callable:
    """A readTexture with the model's behaviour, shaped like the probes take
    it: read(face, uv, faces) -> (n, 3), NaN where it read past the face's
    end (where the worker's guard page makes it fault)."""
    def read(face: int, uv: np.ndarray, faces: np.ndarray) -> np.ndarray:
        return evaluate(model, faces[face], uv)[0]
    return read


# ---- probing a submission -------------------------------------------------

@dataclass
class Probe:
    """What the submission returned on one face of one texture."""
    kind: str                    # "coordinate" or "random"
    faces: np.ndarray            # (6, H, W, 3) float32 as handed over
    face: int
    uv: np.ndarray               # (n, 2)
    values: np.ndarray           # (n, 3), NaN where not evaluated
    evaluated: np.ndarray        # (n,) bool
    faulted: np.ndarray          # (n,) bool: a failure (crash, out-of-bounds read) at this input
    failures: list = field(default_factory=list)

    @property
    def size(self) -> tuple[int, int]:
        return self.faces.shape[2], self.faces.shape[1]

    @property
    def tol(self) -> float:
        w, h = self.size
        return float(tolerance(w, h, float(np.abs(self.faces).max())))


# Non-square faces, wider and taller, so which size scales which axis shows.
PROBE_SIZES = ((13, 7), (6, 11))
PROBE_FACE = 2


def probe_points(width: int, height: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(interior, edge) (u, v) points: texel boundaries, centres and quarter
    points on both axes, plus random ones; the edge set holds every point
    within a texel of the border (where unclamped lookups fault), run as a
    separate batch so its failures cannot stop the interior from being read."""
    rng = np.random.default_rng(seed)

    def axis(n):
        k = np.arange(n + 1)
        return np.unique(np.concatenate([k / n, (k[:-1] + 0.25) / n, (k[:-1] + 0.5) / n,
                                         (k[:-1] + 0.75) / n, [1e-9, 1 - 1e-9], rng.random(3)]))

    u, v = np.meshgrid(axis(width), axis(height), indexing="ij")
    uv = np.stack([u.ravel(), v.ravel()], axis=1)
    margin = np.array([1.0 / width, 1.0 / height])
    edge = ((uv < margin) | (uv > 1 - margin)).any(axis=1)
    return uv[~edge], uv[edge]


class _CallableLookups:
    """A plain read(face, uv, faces) -> (n, 3) as the probes use lookups:
    NaN rows are inputs that faulted."""

    def __init__(self, read: Callable):
        self.read, self.faces = read, None

    def set_faces(self, faces):
        self.faces = np.asarray(faces, np.float32)

    def read_texture(self, face, uv, placement="end"):
        values = np.asarray(self.read(face, np.asarray(uv, np.float64), self.faces), np.float64)
        ok = np.isfinite(values).all(axis=1)
        return _Outcome(values, ok, np.flatnonzero(~ok))


@dataclass
class _Outcome:
    values: np.ndarray
    evaluated: np.ndarray
    fault_rows: np.ndarray

    @property
    def failures(self):
        return []


def as_lookups(lookups):
    """A SubmissionLookups (set_faces + read_texture -> Outcome) as it is, or
    a plain callable wrapped."""
    return lookups if hasattr(lookups, "read_texture") else _CallableLookups(lookups)


def probe(lookups, seed: int = 0) -> list[Probe]:
    """Run the probes: for each probe size, the coordinate texture and a
    random one, interior and edge points as separate batches."""
    lookups = as_lookups(lookups)
    probes = []
    for w, h in PROBE_SIZES:
        interior, edge = probe_points(w, h, seed)
        for kind, faces in (("coordinate", coordinate_faces(w, h)), ("random", random_faces(w, h, seed))):
            lookups.set_faces(faces)
            for uv in (interior, edge):
                out = lookups.read_texture(PROBE_FACE, uv, "end")
                faulted = np.zeros(len(uv), bool)
                rows = getattr(out, "fault_rows", None)
                if rows is None:
                    rows = [f.index for f in out.failures if f.index is not None]
                faulted[np.asarray(rows, np.int64)] = True
                values = np.asarray(out.values, np.float64)
                evaluated = np.asarray(out.evaluated, bool) & np.isfinite(values).all(axis=1)
                probes.append(Probe(kind, faces, PROBE_FACE, uv, values, evaluated, faulted,
                                    list(out.failures)))
    return probes


# ---- the fit -------------------------------------------------------------

@dataclass
class Fit:
    model: TextureModel | None          # the member that reproduces every answer, or None
    closest: TextureModel               # the best member (== model when it fits)
    share: float                        # share of answers the closest member explains
    points: int                         # answers compared
    constant: bool = False              # the same colour whatever (u, v): no position can be read back

    @property
    def fits(self) -> bool:
        return self.model is not None


def _judge(model: TextureModel, p: Probe) -> tuple[int, int]:
    """(explained, contradicted) answers of one probe under `model`."""
    pred, past = evaluate(model, p.faces[p.face], p.uv)
    with np.errstate(invalid="ignore"):
        close = (np.abs(p.values - pred) <= p.tol).all(axis=1)
    good = (p.evaluated & ~past & close) | (p.faulted & past)
    # A wrong value, an answer where the model reads past the face's end, or
    # a fault the model does not predict.
    bad = (p.evaluated & (past | ~close)) | (p.faulted & ~past)
    return int(good.sum()), int(bad.sum())


class _AxisData:
    """The coordinate probes concatenated, per axis and per choice of
    coordinate and size, so each axis model is judged in one pass."""

    def __init__(self, probes: list[Probe], which: int):
        coord = [p for p in probes if p.kind == "coordinate"]
        self.inputs = {}
        for source, size in itertools.product(("own", "other"), ("own", "other")):
            axis = Axis(source=source, size=size)
            parts = [_axis_inputs(axis, p.uv, which, *p.size) for p in coord]
            self.inputs[source, size] = (np.concatenate([c for c, _, _ in parts]),
                                         np.concatenate([np.full(len(c), s) for c, s, _ in parts]),
                                         np.concatenate([np.full(len(c), n) for c, _, n in parts]))
        self.observed = np.concatenate([p.values[:, which] for p in coord])
        self.evaluated = np.concatenate([p.evaluated for p in coord])
        self.faulted = np.concatenate([p.faulted for p in coord])
        self.tol = np.concatenate([np.full(len(p.uv), p.tol) for p in coord])

    def mismatches(self, axis: Axis) -> int:
        """Answers whose channel for this axis (R for x, G for y) the axis
        model contradicts; reads outside the axis's range (an unclamped
        edge) are judged only in two dimensions."""
        c, size, n = self.inputs[axis.source, axis.size]
        i0, i1, w1, inside = axis_taps(axis, c, size, n)
        pred = (1.0 - w1) * (i0 + 1) + w1 * (i1 + 1)
        with np.errstate(invalid="ignore"):
            far = ~(np.abs(self.observed - pred) <= self.tol)
        bad = self.evaluated & inside & far
        if axis.edge != "none":
            bad |= self.faulted
        return int(bad.sum())


    def all_mismatches(self, axes: list[Axis]) -> np.ndarray:
        """`mismatches` of every axis model in `axes` at once (the fit judges
        all 6,480 of them, one numpy call each cost ~1 s): each model's
        prediction is computed on the distinct (c, size, n) of the probes
        only, and judged once per distinct answer there (an answer: its
        point, observed channel, tolerance, evaluated and faulted; the six
        faces and both placements mostly repeat each other, ~3,500 answers
        are ~100-200 distinct ones), counted as often as it was given, a few
        hundred models at a time. Equal to `mismatches` model by model
        (tests/unit/checks/instruments/test_texture_model.py)."""
        out = np.zeros(len(axes), np.int64)
        groups: dict[tuple[str, str], list[int]] = {}
        for i, a in enumerate(axes):
            groups.setdefault((a.source, a.size), []).append(i)
        for key, members in groups.items():
            c, size, n = self.inputs[key]
            distinct, spread = np.unique(np.stack([c, size, n], axis=1), axis=0, return_inverse=True)
            answers = np.stack([spread.reshape(-1), self.observed, self.tol, self.evaluated, self.faulted], axis=1)
            answers, times = np.unique(answers, axis=0, return_counts=True)
            point, observed, tol = answers[:, 0].astype(np.intp), answers[:, 1], answers[:, 2]
            evaluated, faulted = answers[:, 3] == 1, answers[:, 4] == 1
            weight = times.astype(np.float32)     # a float32 sum of whole numbers is exact below 2**24
            for chunk in np.array_split(np.asarray(members), max(1, len(members) // 400)):
                pred, inside = _many_axis_predictions([axes[i] for i in chunk], distinct)
                with np.errstate(invalid="ignore"):
                    gap = np.abs(pred[:, point] - observed)
                bad = inside[:, point]
                bad &= evaluated
                bad &= ~(gap <= tol)
                edged = np.array([axes[i].edge != "none" for i in chunk])
                bad |= edged[:, None] & faulted
                out[chunk] = (bad.astype(np.float32) @ weight).astype(np.int64)    # 2x an int64 product
        return out


def _many_axis_predictions(axes: list[Axis], points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(predicted channel (k, m), both taps inside (k, m)) of k axis models at
    m points (c, size, n): axis_taps for many models in one pass, on a
    coordinate texture (channel = index + 1)."""
    c, size, n = points[:, 0][None], points[:, 1][None], points[:, 2][None]

    def column(values) -> np.ndarray:
        return np.asarray(values)[:, None]

    c = np.where(column([a.flip == "coordinate" for a in axes]), 1.0 - c, c)
    p = c * (size + column([{"N": 0, "N-1": -1, "N+1": 1}[a.scale] for a in axes])) + column([a.offset for a in axes])
    rounding = column([a.rounding for a in axes])
    with np.errstate(invalid="ignore"):
        base = np.where(rounding == "floor", np.floor(p), np.where(rounding == "trunc", np.trunc(p), np.floor(p + 0.5)))
    frac = p - base
    weights = column([a.weights for a in axes])
    nearest = weights == "nearest"
    i0 = base
    i1 = np.where(nearest, base, base + 1)
    w1 = np.where(nearest, 0.0, np.where(weights == "linear", frac, np.where(weights == "swapped", 1.0 - frac, 0.5)))
    edge = column([a.edge for a in axes])

    def edged(i: np.ndarray) -> np.ndarray:
        return np.where(edge == "clamp", np.clip(i, 0, n - 1), np.where(edge == "wrap", np.mod(i, n), i))

    i0, i1 = edged(i0), edged(i1)
    flipped = column([a.flip == "index" for a in axes])
    i0, i1 = np.where(flipped, n - 1 - i0, i0), np.where(flipped, n - 1 - i1, i1)
    inside = (i0 >= 0) & (i0 < n) & (i1 >= 0) & (i1 < n)
    return (1.0 - w1) * (i0 + 1) + w1 * (i1 + 1), inside


def _is_constant(probes: list[Probe]) -> bool:
    vals = np.concatenate([p.values[p.evaluated] for p in probes if p.kind == "coordinate"])
    return len(vals) > 0 and bool(np.all(np.abs(vals - vals[0]) <= 1e-6))


def fit(lookups_or_probes, seed: int = 0, keep: int = 12) -> Fit:
    """The simplest member of the family that explains every answer on the
    probes, or the closest one."""
    probes = lookups_or_probes if isinstance(lookups_or_probes, list) else probe(lookups_or_probes, seed)
    points = sum(int((p.evaluated | p.faulted).sum()) for p in probes)
    if _is_constant(probes):
        return Fit(None, HANDOUT, 0.0, points, constant=True)
    axes = list(all_axes())
    ranked = []
    for which in (0, 1):
        data = _AxisData(probes, which)
        bad = data.all_mismatches(axes)
        scored = sorted(((int(bad[i]), a.cost, i, a) for i, a in enumerate(axes)), key=lambda t: t[:3])
        ranked.append([t[3] for t in scored[:keep]])
    combos = sorted(itertools.product(*ranked), key=lambda xy: xy[0].cost + xy[1].cost)
    best, best_share = None, -1.0
    for ax, ay in combos:
        for model in _edge_variants(TextureModel(ax, ay)):
            good = bad = 0
            for p in probes:
                g, b = _judge(model, p)
                good, bad = good + g, bad + b
            share = good / max(good + bad, 1)
            if bad == 0 and good > 0:
                return Fit(model, model, 1.0, points)
            if share > best_share:
                best, best_share = model, share
    return Fit(None, best, best_share, points)


def replace_edge(axis: Axis) -> Axis:
    """The axis with an unclamped edge read as clamped (for inverting it)."""
    return replace(axis, edge="clamp") if axis.edge == "none" else axis


def _edge_variants(model: TextureModel):
    """The model, then with unclamped edges: per-axis fits cannot tell an
    unclamped edge from a clamped one where the read stays inside the face."""
    yield model
    for ex, ey in (("none", model.y.edge), (model.x.edge, "none"), ("none", "none")):
        if (ex, ey) != (model.x.edge, model.y.edge):
            yield TextureModel(replace(model.x, edge=ex), replace(model.y, edge=ey))


# ---- words ----------------------------------------------------------------

MISTAKE_IDS = ("nearest-neighbor", "weights-swapped", "constant-weights", "half-texel-offset", "texel-offset",
               "truncation-of-negatives", "unclamped-edge", "wrapped-edge", "scaled-by-size-minus-one",
               "scaled-by-size-plus-one", "rows-flipped", "columns-flipped", "texture-u-flipped",
               "texture-v-flipped", "texture-uv-swapped", "width-height-swapped")


def mistake_ids(model: TextureModel) -> list[str]:
    """Diagnosis ids of the parts of `model` that differ from the handout."""
    ids = []
    axes = (model.x, model.y)
    if any(a.weights == "nearest" for a in axes):
        ids.append("nearest-neighbor")
    if any(a.weights == "swapped" for a in axes):
        ids.append("weights-swapped")
    if any(a.weights == "half" for a in axes):
        ids.append("constant-weights")
    if any(abs(a.offset) == 0.5 or a.rounding == "round" for a in axes):
        ids.append("half-texel-offset")
    if any(abs(a.offset) == 1.0 for a in axes):
        ids.append("texel-offset")
    if any(a.rounding == "trunc" for a in axes):
        ids.append("truncation-of-negatives")
    if any(a.edge == "none" for a in axes):
        ids.append("unclamped-edge")
    if any(a.edge == "wrap" for a in axes):
        ids.append("wrapped-edge")
    if any(a.scale == "N-1" for a in axes):
        ids.append("scaled-by-size-minus-one")
    if any(a.scale == "N+1" for a in axes):
        ids.append("scaled-by-size-plus-one")
    if model.y.flip == "index":
        ids.append("rows-flipped")
    if model.x.flip == "index":
        ids.append("columns-flipped")
    # readTexture's own ids: u-flipped and the like are fetchColor's (one id, one meaning).
    if model.x.flip == "coordinate":
        ids.append("texture-u-flipped")
    if model.y.flip == "coordinate":
        ids.append("texture-v-flipped")
    if any(a.source == "other" for a in axes):
        ids.append("texture-uv-swapped")
    if any(a.size == "other" for a in axes):
        ids.append("width-height-swapped")
    return ids


def _number(x: float) -> str:
    return f"{x:+g}".replace("+", "+ ").replace("-", "- ")


def axis_formula(a: Axis, which: int) -> str:
    c = ("u", "v")[which] if a.source == "own" else ("v", "u")[which]
    if a.flip == "coordinate":
        c = f"(1 - {c})"
    n = ("W", "H")[which] if a.size == "own" else ("H", "W")[which]
    n = {"N": n, "N-1": f"({n} - 1)", "N+1": f"({n} + 1)"}[a.scale]
    text = f"{c}{n}"
    if a.offset:
        text += f" {_number(a.offset)}"
    return text


def describe_model(model: TextureModel) -> str:
    """The model in one or two sentences a student can check against their code."""
    if model == HANDOUT:
        return _("readTexture blends the four texels around p = (uW, vH) as the handout says.")
    p = {"p": f"p = ({axis_formula(model.x, 0)}, {axis_formula(model.y, 1)})"}
    parts = []
    left_below = (model.x.offset, model.y.offset) == (-1.0, -1.0)
    if model.single_texel:
        if model.x.rounding == "round":
            parts.append(_("Your lookup reads the texel nearest to %(p)s, and returns that one texel, never a blend") % p)
        elif left_below:
            parts.append(_("Your lookup reads the texel one to the left and below: %(p)s, and returns that one texel, "
                           "never a blend") % p)
        else:
            parts.append(_("Your lookup reads the texel at %(p)s, and returns that one texel, never a blend") % p)
    elif left_below:
        parts.append(_("Your lookup blends the four texels around %(p)s, one texel to the left and below where the "
                       "handout reads") % p)
    else:
        parts.append(_("Your lookup blends the four texels around %(p)s") % p)
    if any(a.rounding == "trunc" for a in (model.x, model.y)):
        parts.append(_("(int) truncates toward zero, so for p between -1 and 0 it gives 0, not -1") if model.single_texel
                     else _("(int) truncates toward zero, so for p between -1 and 0 it gives 0, not -1, and the weight "
                            "goes negative"))
    if any(a.weights == "swapped" for a in (model.x, model.y)):
        parts.append(_("the weights are swapped: (1 - alpha) goes to c10 and alpha to c00"))
    if any(a.weights == "half" for a in (model.x, model.y)):
        parts.append(_("the weights do not follow p: every texel gets the same weight"))
    if any(a.weights == "nearest" for a in (model.x, model.y)) and not model.single_texel:
        parts.append(_("one axis is not blended"))
    if model.y.flip == "index":
        parts.append(_("rows are read top-down (row H-1-y): y = 0 must be the bottom row"))
    if model.x.flip == "index":
        parts.append(_("columns are read right to left (column W-1-x)"))
    if model.y.flip == "coordinate":
        parts.append(_("v runs from top to bottom (1 - v): v = 0 must be the bottom row"))
    if model.x.flip == "coordinate":
        parts.append(_("u runs from right to left (1 - u)"))
    edges = {a.edge for a in (model.x, model.y)}
    if "none" in edges:
        parts.append(_("the lattice points are not clamped to [0, W-1] x [0, H-1], so at the edges it reads the "
                       "neighbouring row or outside the face"))
    if "wrap" in edges:
        parts.append(_("the lattice points wrap around the face (x = W reads x = 0) instead of being clamped"))
    return _("; ").join(parts) + _(".")
