"""What fetchColor asks readTexture for, face by face, read off the record.

fetchColor's readTexture calls are recorded (instruments.fetch_record): the
face and (u, v) of the call whose answer it returns. Per face the recorded
(u, v) are set against the table's (docs/assignment.md): a candidate (u and v
flipped, exchanged, not mapped to [0, 1], divided by |d|) that gives the
recorded (u, v) for nearly every direction names the mistake; otherwise an
affine map fitted to them names an inset or an offset; otherwise the face
is shown as one worked case in numbers. Nothing is inferred from colours,
and the student's readTexture plays no part. Where fetchColor reads the
texels itself (no readTexture call), the faces handed over encode their
positions (textures.coordinate_faces) and its colour gives the place read,
as the handout's bilinear would give it.

`analyse` returns a FetchAnalysis with one FaceVerdict per face (analysed,
or why not) and the whole-lookup findings (ties, precision, overflow).
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from ...envmap import oracle, library as reference
from ...i18n import N_, _, and_list
from ...grading.results import Diagnosis
from . import fetch_record
from .directions import fibonacci_sphere, tied_axes
from .textures import coordinate_faces, decode_sample_coordinates

# Every id the analysis can give from the (u, v) it sees (tests/unit/grading/test_diagnosis_catalogue.py).
DIAGNOSIS_IDS = ("uv-swapped", "u-flipped", "v-flipped", "uv-range", "signed-major", "opengl-table",
                 "face-order", "uv-rotated", "uv-inset", "uv-offset", "uv-mismatch")

FACE_SIZE = 32
SHARE = 0.9          # a candidate (or map) must explain 90% of a face's directions
MIN_DIRECTIONS = 20  # fewer answers toward a face than this: not analysed
PLACE_TOLERANCE = 1e-3   # texels: a recorded (u, v) this close to a candidate's is it (float rounding is ~1e-5)
SCALE_TOLERANCE = 0.02   # |scale - 1| below this is no scale mistake


def face_name(k: int) -> str:
    return reference.FACE_NAMES[k]


# ---- candidate fetchColor behaviours ---------------------------------------

# How fetchColor may turn s = (signed component / m) in [-1, 1] into u: the
# handout's (1 + s)/2, or a remapping mistake.
REMAPS = {   # the names are catalogue ids (grader.i18n), shown with _()
    "handout": lambda s: (1.0 + s) / 2.0,
    N_("not remapped (u = s)"): lambda s: s,
    N_("no division by 2 (u = 1 + s)"): lambda s: 1.0 + s,
    N_("no + 1 (u = s/2)"): lambda s: s / 2.0,
}


@dataclass(frozen=True)
class Candidate:
    swap: bool = False
    flip_u: bool = False
    flip_v: bool = False
    remap: str = "handout"
    by_length: bool = False      # divides by |d| instead of m

    @property
    def ids(self) -> list[str]:
        out = [name for name, on in (("uv-swapped", self.swap), ("u-flipped", self.flip_u), ("v-flipped", self.flip_v)) if on]
        if self.remap != "handout":
            out.append("uv-range")
        return out

    @property
    def cost(self) -> int:
        return self.swap + self.flip_u + self.flip_v + 2 * (self.remap != "handout") + 2 * self.by_length

    def uv(self, ref_uv: np.ndarray, m_over_len: np.ndarray) -> np.ndarray:
        s = 2.0 * ref_uv - 1.0                       # back to the signed ratio
        if self.by_length:
            s = s * m_over_len[:, None]
        uv = REMAPS[self.remap](s)
        a, b = (uv[:, 1], uv[:, 0]) if self.swap else (uv[:, 0], uv[:, 1])
        return np.stack([1 - a if self.flip_u else a, 1 - b if self.flip_v else b], axis=1)


CANDIDATES = sorted((Candidate(*flags) for flags in itertools.product(
    (False, True), (False, True), (False, True), tuple(REMAPS), (False, True))), key=lambda c: c.cost)


# ---- patterns over several faces ---------------------------------------------

# One cause that explains the mistakes of several faces at once is told as
# one diagnosis with its cause and fix (the per-face ids in its detail), so
# the advice does not lead to a compensating fix face by face (issue 19).
# A face's orientation is (swap, flip u, flip v) of the (u, v) it reads
# against the table's.
TURNED_180 = (False, True, True)

# Two sets of faces turned 180 degrees with a known cause; told when those
# faces are turned and no other face is (and, where the words say the other
# faces are right, when their orientation is).
NAMED_TURNS = {
    # m = the signed major component: on -X, -Y, -Z both s/m and t/m change sign.
    "signed-major": ((1, 3, 5), False,
                     N_("u and v both run the wrong way on -X, -Y and -Z and only there: you divide by the "
                        "signed major component, which is negative on those faces. Divide by m = |major "
                        "component| and keep the table's signs.")),
    # OpenGL's table (sc, tc per face) against docs/assignment.md's: +X, -X and -Z turned 180 degrees.
    "opengl-table": ((0, 1, 5), True,
                     N_("+X, -X and -Z are turned 180 degrees (u and v both run the wrong way) and +Y, -Y, +Z "
                        "are right: these are OpenGL's cube-map signs (sc, tc per face), not this assignment's "
                        "table. Use the (u, v) table in README.md for every face.")),
}

# Turns of (u, v) about the face's centre: orientation -> (degrees, your u, your v)
# in the table's u and v. The other orientations are mirror images, told per face.
ROTATIONS = {
    TURNED_180: (180, "1 - u", "1 - v"),
    (True, True, False): (90, "1 - v", "u"),
    (True, False, True): (270, "v", "1 - u"),
}
MIN_ROTATED = 2       # one face turned is told per face: a cause shared by faces needs two
MIN_REORDERED = 3     # one swapped pair of faces is two wrong-faces, not a face order


@dataclass(frozen=True)
class Pattern:
    id: str
    detail: str
    faces: frozenset          # the faces it explains
    hides: tuple              # the per-face ids it tells once ("wrong-face" or the orientation ids)


def _orientation_words(orientation) -> str:
    return ", ".join(name for name, on in zip(("uv-swapped", "u-flipped", "v-flipped"), orientation) if on)


def face_order(faces: list) -> Pattern | None:
    """Every face read from another face of the buffer, one to one: the
    code numbers the faces in another order than faceAddress takes."""
    sampled = {v.face: v.sampled for v in faces if v.analysed and v.sampled is not None}
    moved = sorted(f for f, g in sampled.items() if g != f)
    if len(sampled) != 6 or sorted(sampled.values()) != list(range(6)) or len(moved) < MIN_REORDERED:
        return None
    theirs = [face_name(f) for g in range(6) for f in range(6) if sampled[f] == g]
    per_face = "; ".join(_("%(face)s reads %(sampled)s") % {"face": face_name(f), "sampled": face_name(sampled[f])}
                         for f in moved)
    detail = _("Your face numbers mean %(theirs)s, but faceAddress(k) takes the handout's order %(handout)s, so "
               "directions toward %(moved)s read another face. Number the faces as the "
               "handout does (FACE_POS_X .. FACE_NEG_Z), or map your number to it before calling "
               "faceAddress. (Per face: %(per_face)s.)") % {
        "theirs": ", ".join(theirs), "handout": ", ".join(reference.FACE_NAMES),
        "moved": and_list([face_name(f) for f in moved]), "per_face": per_face}
    return Pattern("face-order", detail, frozenset(moved), ("wrong-face",))


def find_patterns(faces: list) -> list[Pattern]:
    """The patterns that explain several faces at once: a face order, the
    signed major component or OpenGL's table (180 degrees on their three
    faces and on no other), and a turn of (u, v) shared by two faces or more.
    The faces' other mistakes stay per face."""
    out = [p for p in (face_order(faces),) if p is not None]
    orientations = {v.face: v.orientation() for v in faces}
    turns = {f: o for f, o in orientations.items() if o in ROTATIONS}
    for pid, (named, others_right, words) in NAMED_TURNS.items():
        turned = {f for f, o in turns.items() if o == TURNED_180}
        rest = [orientations.get(f) for f in range(6) if f not in named]
        if turned == set(named) and (not others_right or all(o == (False, False, False) for o in rest)):
            out.append(Pattern(pid, _("%(words)s (per face: %(per_face)s.)") % {
                "words": _(words), "per_face": "; ".join(f"{face_name(f)}: {_orientation_words(TURNED_180)}"
                                                         for f in named)},
                frozenset(named), ("u-flipped", "v-flipped")))
            turns = {f: o for f, o in turns.items() if f not in named}
            break
    # Every turn shared by two faces or more, in one diagnosis (one cause: how the faces were taken).
    sentences, rotated, hides = [], set(), set()
    for orientation, (degrees, u, v) in ROTATIONS.items():
        group = sorted(f for f, o in turns.items() if o == orientation)
        if len(group) < MIN_ROTATED:
            continue
        names = [face_name(f) for f in group]
        sentences.append(_(
            "On %(faces)s, (u, v) are turned %(degrees)d degrees about the face's centre: your u is %(u)s and "
            "your v is %(v)s, with u and v from the (u, v) table in README.md. (Per face: %(per_face)s.)") % {
                "faces": and_list(names), "degrees": degrees, "u": u, "v": v,
                "per_face": "; ".join(f"{n}: {_orientation_words(orientation)}" for n in names)})
        rotated |= set(group)
        hides |= {i for i, on in zip(("uv-swapped", "u-flipped", "v-flipped"), orientation) if on}
    if sentences:
        # A turned face's orientation ids are all its turn's: hiding the union hides nothing else.
        out.append(Pattern("uv-rotated", " ".join(sentences), frozenset(rotated), tuple(sorted(hides))))
    return out


# ---- a face's (u, v) as an affine map of the table's -------------------------

@dataclass(frozen=True)
class AffineMap:
    """asked = F(scale * source + offset) per coordinate, F the flip (1 - x)
    where flipped; source the table's (u, v), exchanged when `swap`."""
    swap: bool
    flip_u: bool
    flip_v: bool
    scale: tuple[float, float]
    offset: tuple[float, float]
    explained: float          # share of the face's directions within a texel of the map
    size: tuple[int, int]

    @property
    def orientation_ids(self) -> list[str]:
        return [i for i, on in (("uv-swapped", self.swap), ("u-flipped", self.flip_u), ("v-flipped", self.flip_v)) if on]

    @property
    def kind(self) -> str | None:
        """What is wrong beyond orientation: None, "uv-inset", "uv-offset",
        "uv-range" (not mapped to [0, 1] as the handout says) or "uv-mismatch"."""
        s, o = np.array(self.scale), np.array(self.offset)
        quarter = 0.25 / np.array(self.size, np.float64)
        if (np.abs(s - 1) < SCALE_TOLERANCE).all() and (np.abs(o) < quarter).all():
            return None
        for rs, ro in ((2.0, -1.0), (2.0, 0.0), (1.0, -0.5)):        # REMAPS' mistakes
            if (np.abs(s - rs) < SCALE_TOLERANCE * rs).all() and (np.abs(o - ro) < quarter).all():
                return "uv-range"
        centre_kept = (np.abs(s * 0.5 + o - 0.5) < quarter).all()
        if (s < 1 - SCALE_TOLERANCE).all() and centre_kept:
            return "uv-inset"
        if (np.abs(s - 1) < SCALE_TOLERANCE).all():
            return "uv-offset"
        return "uv-mismatch"

    def words(self) -> str:
        """The map in numbers a student can compare with their formula."""
        names = ("v", "u") if self.swap else ("u", "v")
        parts = []
        for which, (target, source) in enumerate(zip(("u", "v"), names)):
            s, o = self.scale[which], self.offset[which]
            expr = f"{s:.3g} {source} {'+' if o >= 0 else '-'} {abs(o):.3g}"
            flipped = self.flip_u if which == 0 else self.flip_v
            parts.append(f"{target} = {'1 - (' + expr + ')' if flipped else expr}")
        return ", ".join(parts)


def fit_affine(ref_uv: np.ndarray, asked_uv: np.ndarray, size: tuple[int, int]) -> AffineMap | None:
    """The affine map from the table's (u, v) to the asked ones, fitted
    where neither is within two texels of the border (code that reads the
    texels itself clamps there); None with too few points."""
    w, h = size
    margin = np.array([2.0 / w, 2.0 / h])
    ok = (np.isfinite(asked_uv).all(axis=1) & (ref_uv > margin).all(axis=1) & (ref_uv < 1 - margin).all(axis=1)
          & (asked_uv > margin / 2).all(axis=1) & (asked_uv < 1 - margin / 2).all(axis=1))
    if ok.sum() < 20:
        return None
    x = np.column_stack([ref_uv[ok], np.ones(int(ok.sum()))])
    coef, *_ = np.linalg.lstsq(x, asked_uv[ok], rcond=None)          # (3, 2): asked = x @ coef
    a, b, c, d = coef[0, 0], coef[1, 0], coef[0, 1], coef[1, 1]       # du/du, du/dv, dv/du, dv/dv
    swap = abs(b) + abs(c) > abs(a) + abs(d)
    slope_u, slope_v = (b, c) if swap else (a, d)
    flip_u, flip_v = slope_u < 0, slope_v < 0
    icpt = coef[2]
    offset = (1 - icpt[0] if flip_u else icpt[0], 1 - icpt[1] if flip_v else icpt[1])
    residual = np.abs(x @ coef - asked_uv[ok]) * (w, h)
    explained = float(np.mean((residual <= 0.75).all(axis=1)))
    return AffineMap(bool(swap), bool(flip_u), bool(flip_v), (float(abs(slope_u)), float(abs(slope_v))),
                     (float(offset[0]), float(offset[1])), explained, size)


# ---- results ---------------------------------------------------------------

@dataclass
class FaceVerdict:
    face: int                       # the face the reference picks
    directions: int                 # clear directions toward it
    answered: int                   # of those, answered (no crash)
    sampled: int | None = None      # the face fetchColor sampled (majority), None: unknown
    candidate: Candidate | None = None
    share: float = 0.0              # directions the best candidate explains
    crash: str | None = None        # the input that crashed, when it kept the face from being analysed
    example: str = ""               # for a face nothing explains: one direction, the table's and the asked (face, u, v)
    affine: AffineMap | None = None   # the affine map of the table's (u, v), when it explains the face
    elsewhere: int = 0              # directions asked of another face than the one it mostly asks

    @property
    def analysed(self) -> bool:
        return self.crash is None and self.answered >= MIN_DIRECTIONS

    @property
    def correct(self) -> bool:
        if self.affine is not None:
            return self.analysed and self.sampled == self.face and not self.affine.orientation_ids and self.affine.kind is None
        return (self.analysed and self.sampled == self.face and self.candidate is not None
                and not self.candidate.ids and not self.candidate.by_length)

    def orientation(self) -> tuple[bool, bool, bool] | None:
        """(swap, flip u, flip v) of the (u, v) asked on the sampled face
        against the table's, when the face's map is known (a candidate or
        the affine map explains it), whatever else is wrong there."""
        if not self.analysed or self.sampled is None:
            return None
        if self.affine is not None:
            return self.affine.swap, self.affine.flip_u, self.affine.flip_v
        c = self.candidate
        if c is None or self.share < SHARE:
            return None
        return c.swap, c.flip_u, c.flip_v


@dataclass
class FetchAnalysis:
    faces: list[FaceVerdict] = field(default_factory=list)
    not_implemented: bool = False
    ties_untouched: str | None = None         # an example tie sent to a face it does not touch
    precision: str | None = None              # "tiny" / "huge": float conversion
    overflow: str | None = None               # "huge" / "tiny": squaring overflows / underflows
    length_dependent: bool = False            # answer changes with the direction's length
    directions: int = 0                       # the Fibonacci sphere's directions recorded

    def diagnoses(self) -> list[Diagnosis]:
        out: list[Diagnosis] = []
        if self.not_implemented:
            return [Diagnosis("not-implemented", _("fetchColor returns black (or a colour that is not in the texture) "
                                                   "for every direction: it still looks like the starting code."))]
        if self.length_dependent or any(v.candidate is not None and v.candidate.by_length and v.share >= SHARE
                                        for v in self.faces):
            out.append(Diagnosis("not-divided-by-m", _("The answer changes with the direction's length, or (u, v) do "
                                                     "not reach the face's edges: divide the face-plane coordinates by the major "
                                                     "component's magnitude m.")))
        patterns = find_patterns(self.faces)
        out += [Diagnosis(p.id, p.detail) for p in patterns]
        hidden = {(f, i) for p in patterns for f in p.faces for i in p.hides}   # told once, by the pattern
        # One (u, v) mistake shared by every face mapped (an inset, an offset): told once.
        read_back = [v for v in self.faces if v.analysed and v.affine is not None]
        kinds = {v.affine.kind for v in read_back}
        shared = next(iter(kinds)) if (len(kinds) == 1 and len(read_back) >= 2 and None not in kinds
                                       and len(read_back) == sum(v.analysed for v in self.faces)) else None
        if shared in ("uv-inset", "uv-offset"):
            example = read_back[0].affine
            what = {"uv-inset": N_("On every face fetchColor moves (u, v) inward, toward the face's centre: it reads at "
                                   "%(words)s (on %(face)s; %(w)d x %(h)d texels). The handout's (u, v) run from exactly "
                                   "0 to 1 across the face."),
                    "uv-offset": N_("On every face fetchColor shifts (u, v) by a constant: it reads at %(words)s "
                                    "(on %(face)s; %(w)d x %(h)d texels). The handout's (u, v) run from exactly 0 to 1 "
                                    "across the face.")}[shared]
            out.append(Diagnosis(shared, _(what) % {"words": example.words(), "face": face_name(read_back[0].face),
                                                    "w": example.size[0], "h": example.size[1]}))
        for v in self.faces:
            name = face_name(v.face)
            if v.crash is not None:
                out.append(Diagnosis("face-not-analysed", _("Directions toward %(face)s could not be analysed "
                                                            "(crash at %(crash)s).") % {"face": name, "crash": v.crash},
                                     face=name))
                continue
            if not v.analysed:
                continue
            if v.sampled is None:
                out.append(Diagnosis("wrong-face", _("Directions toward %(face)s return a colour that is not in "
                                                     "the texture (black?).") % {"face": name}, face=name))
                continue
            if v.sampled != v.face and (v.face, "wrong-face") not in hidden:
                out.append(Diagnosis("wrong-face", _("Directions toward %(face)s sample the %(sampled)s face.")
                                     % {"face": name, "sampled": face_name(v.sampled)}, face=name))
            if v.affine is not None:
                for mistake in v.affine.orientation_ids:
                    if (v.face, mistake) not in hidden:
                        out.append(Diagnosis(mistake, _detail(mistake, v), face=name))
                kind = v.affine.kind
                if kind is not None and kind != shared:
                    out.append(Diagnosis(kind, _("On the %(face)s face, fetchColor asks readTexture for %(words)s "
                                                 "instead of the handout's (u, v).")
                                         % {"face": name, "words": v.affine.words()}, face=name))
                continue
            if v.share >= SHARE and v.candidate is not None:
                for mistake in v.candidate.ids:
                    if (v.face, mistake) not in hidden:
                        out.append(Diagnosis(mistake, _detail(mistake, v), face=name))
            elif v.sampled == v.face:
                # (On another face the table's (u, v) for this one are no
                # measure: wrong-face above says where it reads.)
                out.append(Diagnosis("uv-mismatch", _("On the %(face)s face, (u, v) follow no pattern we recognise "
                                                      "(%(share)s of directions explained by the best guess).")
                                     % {"face": name, "share": f"{v.share:.0%}"}
                                     + (f" {v.example}" if v.example else ""), face=name))
        if self.ties_untouched:
            out.append(Diagnosis("tie-untouched-face", self.ties_untouched))
        if self.precision:
            out.append(Diagnosis("float-precision", self.precision))
        elif self.overflow and not any(d.id == "not-divided-by-m" for d in out):
            # Dividing by the length squares the components too: one mistake, one fix (divide by m).
            out.append(Diagnosis("length-overflow", self.overflow))
        return out

    def table(self) -> list[str]:
        rows = [f"| {_('direction toward')} | {_('face sampled')} | {_('(u, v) mistakes')} | {_('explained')} |",
                "|---|---|---|---:|"]
        for v in self.faces:
            if v.crash is not None:
                rows.append(f"| {face_name(v.face)} | " + _("could not be analysed (crash at %(crash)s)") % {"crash": v.crash}
                            + " | | |")
            elif not v.analysed:
                rows.append(f"| {face_name(v.face)} | " + _("too few answers (%(count)d)") % {"count": v.answered} + " | | |")
            else:
                sampled = face_name(v.sampled) if v.sampled is not None else _("none")
                if v.elsewhere:
                    sampled += " (" + _("%(count)d of %(total)d directions asked of other faces") % {
                        "count": v.elsewhere, "total": v.answered} + ")"
                if v.affine is not None:
                    ids = ", ".join(v.affine.orientation_ids + ([v.affine.kind] if v.affine.kind else [])) or _("none")
                    rows.append(f"| {face_name(v.face)} | {sampled} | {ids} ("
                                + _("asked: %(words)s") % {"words": v.affine.words()}
                                + f") | {v.affine.explained:.0%} |")
                    continue
                if v.candidate is not None and v.share >= SHARE:
                    ids = ", ".join(v.candidate.ids + ([_("divides by |d|, not m")] if v.candidate.by_length else [])) or _("none")
                else:
                    ids = "?"
                rows.append(f"| {face_name(v.face)} | {sampled} | {ids} | {v.share:.0%} |")
        return rows


def _detail(mistake: str, v: FaceVerdict) -> str:
    name = face_name(v.face)
    if mistake == "uv-range":
        return _("On the %(face)s face, (u, v) are not mapped to [0, 1] as the handout says: %(remap)s.") % {
            "face": name, "remap": _(v.candidate.remap)}
    return _({
        "u-flipped": N_("On the %(face)s face, u runs the wrong way (your u is 1 - u of the (u, v) table in README.md)."),
        "v-flipped": N_("On the %(face)s face, v runs the wrong way (your v is 1 - v of the (u, v) table in README.md)."),
        "uv-swapped": N_("On the %(face)s face, u and v are swapped."),
    }[mistake]) % {"face": name}


# ---- the analysis ----------------------------------------------------------

def places(rec: fetch_record.Record, size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(face (n,), uv (n, 2), read itself (n,)): the face and (u, v) of the
    call whose answer fetchColor returned; where it made no call, the place
    its own colour comes from on the coordinate faces (p = (uW, vH) clamped
    to the face, as the handout's bilinear reads it). -1 / NaN: neither."""
    faces, uv = rec.request()
    itself = rec.calls == 0
    own_face, px, py = decode_sample_coordinates(rec.values[itself])
    faces[itself] = own_face
    with np.errstate(invalid="ignore"):
        uv[itself] = np.where((own_face >= 0)[:, None], np.stack([px / size[0], py / size[1]], axis=1), np.nan)
    return faces, uv, itself


def _close(want_uv: np.ndarray, got_uv: np.ndarray, itself: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """The asked (u, v) is `want_uv` within PLACE_TOLERANCE texels; where
    fetchColor read itself, after the clamp its colour went through."""
    s = np.asarray(size, np.float64)
    want = want_uv * s
    want = np.where(itself[:, None], np.clip(want, 0.0, s - 1.0), want)
    with np.errstate(invalid="ignore"):
        return (np.abs(want - got_uv * s) <= PLACE_TOLERANCE).all(axis=1)


def analyse(lookups, quick: bool = False) -> FetchAnalysis:
    """Face by face, what fetchColor asks readTexture for (or, reading the
    texels itself, where its colour comes from), against the table."""
    size = (FACE_SIZE, FACE_SIZE)
    lookups.set_faces(coordinate_faces(*size))
    dirs = fibonacci_sphere(6000 if quick else 20_000)
    out = FetchAnalysis(directions=len(dirs))
    ref_faces, ref_uv = oracle.current().direction_to_face(dirs)
    # One recording per face, its centre first: crashes near one face's
    # edges (the runner stops a batch after a few) cannot starve another
    # face, nor that face's own centre.
    order = np.lexsort((np.abs(ref_uv - 0.5).max(axis=1), ref_faces))
    faces = np.full(len(dirs), -1, np.int64)
    uv = np.full((len(dirs), 2), np.nan)
    itself = np.zeros(len(dirs), bool)
    answered = np.zeros(len(dirs), bool)
    crashes: dict[int, str] = {}
    for f in range(6):
        rows = order[ref_faces[order] == f]
        if not len(rows):
            continue
        rec = fetch_record.record(lookups, dirs[rows])
        faces[rows], uv[rows], itself[rows] = places(rec, size)
        # Answered: a tag returned from a face, or a colour of its own.
        answered[rows] = (((rec.returned >= 0) & (faces[rows] >= 0)) | (rec.calls == 0)) \
            & np.isfinite(rec.values).all(axis=1)
        for failure in rec.outcome.failures:
            if failure.index is not None:
                crashes.setdefault(f, failure.input)
                break
    clear = tied_axes(dirs).sum(axis=1) == 1
    m_over_len = np.abs(dirs).max(axis=1) / np.linalg.norm(dirs, axis=1)

    if (clear & answered).any() and np.all(faces[clear & answered] < 0):
        out.not_implemented = True
        return out

    for f in range(6):
        toward = clear & (ref_faces == f)
        rows = toward & answered
        verdict = FaceVerdict(f, int(toward.sum()), int(rows.sum()))
        out.faces.append(verdict)
        if verdict.answered < MIN_DIRECTIONS:
            if f in crashes:
                verdict.crash = crashes[f]
            continue
        known = rows & (faces >= 0)
        if known.sum() < SHARE * rows.sum():
            continue
        g = int(np.argmax(np.bincount(faces[known], minlength=6)))
        verdict.sampled = g
        idx = np.flatnonzero(rows)
        on_g = faces[idx] == g
        verdict.elsewhere = int((faces[idx] >= 0).sum() - on_g.sum())
        best, best_share = None, -1.0
        for cand in CANDIDATES:
            ok = on_g & _close(cand.uv(ref_uv[idx], m_over_len[idx]), uv[idx], itself[idx], size)
            share = float(ok.mean())
            if share > best_share + 1e-12:
                best, best_share = cand, share
            if share >= 0.999:
                break
        verdict.candidate, verdict.share = best, max(best_share, 0.0)
        if best_share >= SHARE:
            continue
        affine = fit_affine(ref_uv[idx][on_g], uv[idx][on_g], size) if on_g.sum() >= SHARE * len(idx) else None
        if affine is not None and affine.explained >= SHARE and affine.kind != "uv-mismatch":
            verdict.affine, verdict.share, verdict.candidate = affine, affine.explained, None
            continue
        if affine is not None:
            verdict.share = max(verdict.share, affine.explained)
        verdict.example = _example(dirs, idx, f, ref_uv, faces, uv, best, m_over_len, size, itself)

    _lengths(lookups, dirs[clear][:: max(1, int(clear.sum()) // 1500)], size, out)
    _ties(lookups, size, out)
    return out


def _example(dirs, idx, f: int, ref_uv, faces, uv, best: Candidate | None, m_over_len, size, itself) -> str:
    """One direction the best candidate does not explain, in numbers: the
    table's face and (u, v), and the recorded ones."""
    cand = best or Candidate()
    ok = (faces[idx] == f) & _close(cand.uv(ref_uv[idx], m_over_len[idx]), uv[idx], itself[idx], size)
    misses = idx[~ok]
    if not len(misses):
        return ""
    i = int(misses[len(misses) // 2])
    return _("For example fetchColor(Vector3(%(d)s)): the table gives %(face)s at (u, v) = %(want)s; fetchColor "
             "asked for %(asked)s at (u, v) = %(got)s.") % {
        "d": ", ".join(f"{x:.4g}" for x in dirs[i]), "face": face_name(f),
        "want": f"({ref_uv[i, 0]:.4f}, {ref_uv[i, 1]:.4f})",
        "asked": face_name(int(faces[i])) if faces[i] >= 0 else _("none"),
        "got": f"({uv[i, 0]:.4f}, {uv[i, 1]:.4f})"}


# Lengths that break a lookup computing in float (|component| below float's
# normal range, or above its largest value) and one that squares the
# components (x*x overflows above 1.3e154, underflows to 0 below 1e-162).
FLOAT_TINY, FLOAT_HUGE = 1e-41, 1e39
SQUARE_HUGE, SQUARE_TINY = 1e155, 1e-170


def _lengths(lookups, dirs: np.ndarray, size, out: FetchAnalysis) -> None:
    """The same directions at other lengths ask for the same face and (u, v)
    (within half a texel)."""
    scales = (1.0, 10.0, FLOAT_TINY, FLOAT_HUGE, SQUARE_HUGE, SQUARE_TINY)
    n = len(dirs)
    # One recording for every length: fewer round trips to the worker.
    rec = fetch_record.record(lookups, np.concatenate([dirs * s for s in scales]))
    faces, uv, _itself = places(rec, size)
    with np.errstate(invalid="ignore"):
        p = (uv * np.asarray(size, np.float64)).reshape(len(scales), n, 2)
    faces = faces.reshape(len(scales), n)
    judged = (faces[0] >= 0) & np.isfinite(p[0]).all(axis=1)
    # Black with no readTexture call says nothing of the components' type:
    # a guard returned before any arithmetic (fetch_sweep names it
    # black-without-lookup, stability length-dependent); such rows are not
    # counted against float or the squares.
    with np.errstate(invalid="ignore"):
        skipped = ((rec.calls == 0) & (rec.values == 0).all(axis=1)).reshape(len(scales), n)
    broken = {}
    for k, scale in enumerate(scales[1:], 1):
        with np.errstate(invalid="ignore"):
            ok = ((faces[k] == faces[0]) & (np.abs(p[k] - p[0]) <= 0.5).all(axis=1)) | skipped[k]
        broken[scale] = float(np.mean(~ok[judged])) if judged.any() else 0.0
    if broken[10.0] > 0.1:
        out.length_dependent = True
        return
    if broken[FLOAT_TINY] > 0.1 or broken[FLOAT_HUGE] > 0.1:
        which = [_(w) for w, s in ((N_("tiny (|d| = 1e-41)"), FLOAT_TINY), (N_("huge (|d| = 1e39)"), FLOAT_HUGE))
                 if broken[s] > 0.1]
        out.precision = _("fetchColor gives another answer for %(which)s directions than for the same "
                          "directions at length 1, while it handles lengths such as 1e155 and 1e-170 differently or "
                          "not at all: the components go through float (float x = direction.x, or a float "
                          "parameter), which cannot hold magnitudes below 1.2e-38 exactly or above 3.4e38 at all. "
                          "Keep them in double until you have divided by m.") % {"which": and_list(which)}
    elif broken[SQUARE_HUGE] > 0.1 or broken[SQUARE_TINY] > 0.1:
        which = [_(w) for w, s in ((N_("huge (|d| = 1e155)"), SQUARE_HUGE), (N_("tiny (|d| = 1e-170)"), SQUARE_TINY))
                 if broken[s] > 0.1]
        out.overflow = _("fetchColor breaks for %(which)s directions but not for 1e39 or 1e-41: "
                         "x*x + y*y + z*z overflows to infinity above |d| = 1.3e154 (and underflows to 0 below "
                         "about 1e-162), so normalising first divides by infinity or 0. Divide by m, the largest "
                         "|component|, instead: it needs no squares.") % {"which": and_list(which)}


def tie_directions() -> np.ndarray:
    """Directions where two or three components tie as the largest in
    magnitude: edges (random third component) and corners."""
    rng = np.random.default_rng(15)
    out = []
    for free in range(3):
        tied = [i for i in range(3) if i != free]
        for sa, sb in itertools.product((1.0, -1.0), repeat=2):
            d = np.zeros((12, 3))
            d[:, tied[0]], d[:, tied[1]] = sa, sb
            d[:, free] = rng.uniform(-0.9, 0.9, 12)
            out.append(d)
    out.append(np.array(list(itertools.product((1.0, -1.0), repeat=3))))
    return np.concatenate(out)


TIE_BATCH = 4   # tie directions per recording after a failure: a crash at one cannot starve the rest


def _ties(lookups, size, out: FetchAnalysis) -> None:
    """Ties asked of a face the direction does not touch. The face
    fetchColor asks for a face's directions elsewhere counts as touched
    there too: a wrong face is not also a tie sent astray."""
    dirs = tie_directions()
    rec = fetch_record.record(lookups, dirs)
    if rec.outcome.failures:
        # The runner gives a batch up after a few failures: a crash at one tie must not leave the rest unanswered.
        rec = fetch_record.concatenate([fetch_record.record(lookups, dirs[lo:lo + TIE_BATCH])
                                        for lo in range(0, len(dirs), TIE_BATCH)])
    faces, _uv, _itself = places(rec, size)
    a = np.abs(dirs)
    m = a.max(axis=1)
    touched = np.zeros((len(dirs), 6), bool)
    for axis in range(3):
        at_max = a[:, axis] == m
        touched[at_max & (dirs[:, axis] > 0), 2 * axis] = True
        touched[at_max & (dirs[:, axis] < 0), 2 * axis + 1] = True
    for v in out.faces:
        if v.analysed and v.sampled is not None:
            touched[touched[:, v.face], v.sampled] = True
    answered = (rec.calls >= 0) & (faces >= 0)
    wrong = answered & ~touched[np.arange(len(dirs)), np.maximum(faces, 0)]
    if wrong.sum() >= max(1, 0.1 * answered.sum()):
        i = int(np.flatnonzero(wrong)[0])
        text = ", ".join(f"{x:g}" for x in dirs[i])
        ok = _(" or ").join(face_name(k) for k in np.flatnonzero(touched[i]))
        out.ties_untouched = _("fetchColor(Vector3(%(d)s)) samples the %(face)s face, which this "
                               "direction does not touch (it lies on the edge of %(touched)s). With strict "
                               "comparisons (>) a tie fails every test and falls through to the last branch; use "
                               ">= so that a tied direction picks one of the faces it touches.") % {
            "d": text, "face": face_name(int(faces[i])), "touched": ok, "wrong": int(wrong.sum()), "total": len(dirs)}
