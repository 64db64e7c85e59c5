"""fetchColor through a calibrated instrument: where it samples, recovered
through the submission's OWN readTexture.

The faces handed over encode position (R = x + 1, G = y + 1, B = face + 1).
What comes back from fetchColor is readTexture's answer at the face and
(u, v) fetchColor chose. Instead of assuming readTexture is the handout's,
the fitted model of the student's readTexture (grader.checks.instruments.texture_model)
predicts, for every candidate fetchColor behaviour (the handout's face and
(u, v), flipped, swapped, remapped, divided by the length), what the
submission would return; the candidate that reproduces the answers names the
fetchColor mistake. So a wrong readTexture never becomes a fetchColor
diagnosis, and fetchColor's mistakes are found whatever readTexture does.

Everything here is independent of how results are scored or reported:
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
from ...envmap.geometry import uv_on_face

# Every id a candidate can give (tests/unit/grading/test_diagnosis_catalogue.py).
DIAGNOSIS_IDS = ("uv-swapped", "u-flipped", "v-flipped", "uv-range", "signed-major", "opengl-table",
                 "face-order", "uv-rotated", "uv-inset", "uv-offset", "uv-mismatch")
from .compare import tolerance
from .directions import fibonacci_sphere, tied_axes
from .texture_model import Fit, TextureModel, evaluate_in_buffer
from .textures import coordinate_faces, decode_sample_coordinates
from .readback import AffineMap, calibrate, fit_affine
from . import readback

FACE_SIZE = 32
SHARE = 0.9          # a candidate must explain 90% of a face's directions
MIN_DIRECTIONS = 20  # fewer answers toward a face than this: not analysed


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
    example: str = ""               # for a face no candidate explains: one direction, its (u, v) and the recovered one
    affine: "AffineMap | None" = None   # the (u, v) read back without a model, when it explains the face

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
        """(swap, flip u, flip v) of the (u, v) read on the sampled face
        against the table's, when the face's map is known (read back, or a
        candidate explains it), whatever else is wrong there."""
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
    instrument: str                           # "fitted", "closest" or "none"
    reason: str = ""                          # why fetchColor could not be analysed (instrument "none")
    faces: list[FaceVerdict] = field(default_factory=list)
    not_implemented: bool = False
    ties_untouched: str | None = None         # an example tie sent to a face it does not touch
    precision: str | None = None              # "tiny" / "huge": float conversion
    overflow: str | None = None               # "huge" / "tiny": squaring overflows / underflows
    length_dependent: bool = False            # answer changes with the direction's length

    def diagnoses(self) -> list[Diagnosis]:
        out: list[Diagnosis] = []
        if self.instrument == "none":
            return [Diagnosis("fetch-not-analysed", self.reason)]
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
        # One (u, v) mistake shared by every face read back (an inset, an offset): told once.
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
                    out.append(Diagnosis(kind, _("On the %(face)s face, fetchColor reads at %(words)s "
                                                 "(read back from your answers) instead of the handout's (u, v).")
                                         % {"face": name, "words": v.affine.words()}, face=name))
                continue
            if v.share >= SHARE and v.candidate is not None:
                for mistake in v.candidate.ids:
                    if (v.face, mistake) not in hidden:
                        out.append(Diagnosis(mistake, _detail(mistake, v), face=name))
            else:
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
                if v.affine is not None:
                    ids = ", ".join(v.affine.orientation_ids + ([v.affine.kind] if v.affine.kind else [])) or _("none")
                    rows.append(f"| {face_name(v.face)} | {sampled} | {ids} ("
                                + _("read back: %(words)s") % {"words": v.affine.words()}
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

class Instrument:
    """The student's readTexture as fitted, over the coordinate cube: what
    fetchColor's answer would be for a face and (u, v)."""

    def __init__(self, model: TextureModel, faces: np.ndarray):
        self.model, self.faces = model, faces
        w, h = faces.shape[2], faces.shape[1]
        self.tol = float(tolerance(w, h, float(max(w, h) + 1)))

    def predict(self, face: np.ndarray, uv: np.ndarray) -> np.ndarray:
        return evaluate_in_buffer(self.model, self.faces, face, uv)[0]

    def explains(self, face: np.ndarray, uv: np.ndarray, answers: np.ndarray) -> np.ndarray:
        pred = self.predict(face, uv)
        with np.errstate(invalid="ignore"):
            return (np.abs(pred - answers) <= self.tol).all(axis=1)


def _instrument(fit: Fit) -> tuple[str, TextureModel | None, str]:
    if fit.constant:
        return "none", None, _("fetchColor could not be analysed: readTexture returns the same colour wherever it "
                               "reads, so its answers do not tell which face or (u, v) fetchColor asked for. Fix "
                               "readTexture first.")
    if fit.fits:
        return "fitted", fit.model, ""
    if fit.share >= 0.9:
        return "closest", fit.closest, ""
    return "none", None, _("fetchColor could not be analysed: readTexture follows no pattern the grader knows "
                           "(the closest explains %(share)s of its answers), so its answers cannot be read "
                           "back as a face and (u, v). Fix readTexture first.") % {"share": f"{fit.share:.0%}"}


NOT_READ_BACK = N_("fetchColor could not be analysed: readTexture returns the same colour wherever it reads, or "
                 "crashes on most of a face, so its answers do not tell which face or (u, v) fetchColor asked "
                 "for. Fix readTexture first.")


def analyse(lookups, fit: Fit, quick: bool = False) -> FetchAnalysis:
    """Face by face, what fetchColor does: through the fitted readTexture
    when one fits, and otherwise (or where no candidate explains a face) read
    back without a model (instruments.readback)."""
    kind, model, _reason = _instrument(fit)
    faces = coordinate_faces(FACE_SIZE, FACE_SIZE)
    lookups.set_faces(faces)
    calibration: list = []          # computed once, when first needed

    def calibrated():
        if not calibration:
            calibration.append(calibrate(lookups, faces))
        return calibration[0]

    if model is None:
        if fit.constant or calibrated() is None:
            return FetchAnalysis("none", _(NOT_READ_BACK))
        kind = "read back"
    inst = Instrument(model, faces) if model is not None else None
    out = FetchAnalysis(kind)

    dirs = fibonacci_sphere(6000 if quick else 20_000)
    ref_faces, ref_uv = oracle.current().direction_to_face(dirs)
    # One batch per face, its centre first: crashes near one face's edges
    # (the runner stops a batch after a few) cannot starve another face, nor
    # that face's own centre.
    order = np.lexsort((np.abs(ref_uv - 0.5).max(axis=1), ref_faces))
    values = np.full((len(dirs), 3), np.nan)
    evaluated = np.zeros(len(dirs), bool)
    crashes: dict[int, str] = {}
    for f in range(6):
        rows = order[ref_faces[order] == f]
        if not len(rows):
            continue
        got = lookups.fetch(dirs[rows])
        values[rows] = np.asarray(got.values, np.float64)
        evaluated[rows] = np.asarray(got.evaluated, bool)
        for failure in got.failures:
            if failure.index is not None:
                crashes.setdefault(f, failure.input)
                break
    sub_faces, _px, _py = decode_sample_coordinates(values)
    answered = evaluated & np.isfinite(values).all(axis=1)
    clear = tied_axes(dirs).sum(axis=1) == 1
    m_over_len = np.abs(dirs).max(axis=1) / np.linalg.norm(dirs, axis=1)

    if (clear & answered).any() and np.all(sub_faces[clear & answered] < 0):
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
        known = rows & (sub_faces >= 0)
        if known.sum() < SHARE * rows.sum():
            verdict.sampled = None
            continue
        sampled = np.bincount(sub_faces[known], minlength=6)
        g = int(np.argmax(sampled))
        verdict.sampled = g
        idx = np.flatnonzero(rows)
        best, best_share = None, -1.0
        for cand in (CANDIDATES if inst is not None else ()):
            ok = inst.explains(np.full(len(idx), g), cand.uv(ref_uv[idx], m_over_len[idx]), values[idx])
            share = float(ok.mean())
            if share > best_share + 1e-12:
                best, best_share = cand, share
            if share >= 0.999:
                break
        verdict.candidate, verdict.share = best, max(best_share, 0.0)
        if best_share >= SHARE:
            continue
        # No candidate explains it (or no model): read (u, v) back and fit a map.
        cal = calibrated()
        if cal is not None:
            read_face, read_uv = cal.read_back(values[idx])
            on_g = read_face == g
            affine = fit_affine(ref_uv[idx][on_g], read_uv[on_g], cal.size) if on_g.sum() >= SHARE * len(idx) else None
            if affine is not None and affine.explained >= readback.EXPLAINED and affine.kind != "uv-mismatch":
                # The read-back map, not the model's best (failed) candidate, describes the face.
                verdict.affine, verdict.share, verdict.candidate = affine, affine.explained, None
                continue
            if affine is not None:
                verdict.share = max(verdict.share, affine.explained)
                verdict.example = _read_back_example(dirs, idx, g, ref_uv, read_uv, on_g)
        if inst is not None and not verdict.example:
            verdict.example = _example(inst, dirs, idx, g, ref_uv, values, best, m_over_len)

    tol = inst.tol if inst is not None else float(tolerance(FACE_SIZE, FACE_SIZE, float(FACE_SIZE + 1)))
    _lengths(lookups, dirs[clear][:: max(1, int(clear.sum()) // 1500)], tol, out)
    _ties(lookups, inst, out)
    return out


def _read_back_example(dirs, idx, g: int, ref_uv, read_uv, on_g) -> str:
    """One direction in words: the (u, v) the handout gives, and where it was read."""
    rows = np.flatnonzero(on_g & np.isfinite(read_uv).all(axis=1))
    if not len(rows):
        return ""
    j = rows[len(rows) // 2]
    i = int(idx[j])
    d = ", ".join(f"{x:.4g}" for x in dirs[i])
    return _("For example fetchColor(Vector3(%(d)s)) should read (u, v) = %(want)s on %(face)s; it read about %(got)s.") % {
        "d": d, "want": f"({ref_uv[i, 0]:.3f}, {ref_uv[i, 1]:.3f})", "face": face_name(g),
        "got": f"({read_uv[j, 0]:.3f}, {read_uv[j, 1]:.3f})"}


def recover_uv(inst: Instrument, face: int, answer: np.ndarray, steps: int = 2048):
    """The (u, v) ranges at which the fitted readTexture gives `answer` on a
    coordinate-encoding face: each lattice axis inverted on its own channel
    (R tells x, G tells y) by searching [-0.5, 1.5] for where the model's
    channel equals the answer or crosses it. Exact for any member of the
    family, however it rounds, blends or flips. None when no (u, v) gives it."""
    from .texture_model import axis_taps, replace_edge
    model = inst.model
    h, w = inst.faces.shape[1:3]
    c = np.linspace(-0.5, 1.5, 2 * steps + 1)
    found = [None, None]
    for which, axis in enumerate((model.x, model.y)):
        axis = replace_edge(axis)            # reads past the edge say nothing about c
        n = (w, h)[which]
        size = ((w, h) if axis.size == "own" else (h, w))[which]
        i0, i1, w1, _ = axis_taps(axis, c, size, n)
        pred = (1.0 - w1) * (i0 + 1) + w1 * (i1 + 1)
        diff = pred - answer[which]
        hit = np.abs(diff) <= inst.tol
        cross = np.flatnonzero(np.sign(diff[:-1]) * np.sign(diff[1:]) < 0)
        values = list(c[hit]) + list(c[cross] - diff[cross] * (c[cross + 1] - c[cross]) / (diff[cross + 1] - diff[cross]))
        if not values:
            return None
        # The coordinate this axis reads: u for x unless readTexture swaps them.
        coordinate = which if axis.source == "own" else 1 - which
        found[coordinate] = (min(values), max(values))
    if found[0] is None or found[1] is None:
        return None
    return np.array([found[0][0], found[1][0]]), np.array([found[0][1], found[1][1]])


def _example(inst: Instrument, dirs, idx, g: int, ref_uv, values, best: Candidate | None, m_over_len) -> str:
    """One direction the best candidate does not explain, in words: the
    (u, v) the handout gives and the (u, v) the student's answer comes from."""
    cand = best or Candidate()
    ok = inst.explains(np.full(len(idx), g), cand.uv(ref_uv[idx], m_over_len[idx]), values[idx])
    misses = idx[~ok]
    if not len(misses):
        return ""
    i = int(misses[len(misses) // 2])
    box = recover_uv(inst, g, values[i])
    d = ", ".join(f"{x:.4g}" for x in dirs[i])
    want = f"({ref_uv[i, 0]:.3f}, {ref_uv[i, 1]:.3f})"
    if box is None:
        return _("For example fetchColor(Vector3(%(d)s)) should read (u, v) = %(want)s; its answer comes from no (u, v) "
                 "on %(face)s.") % {"d": d, "want": want, "face": face_name(g)}
    lo, hi = box
    got = ", ".join(f"{a:.3f}" if abs(a - b) < 2e-3 else f"{a:.3f}..{b:.3f}" for a, b in zip(lo, hi))
    return _("For example fetchColor(Vector3(%(d)s)) should read (u, v) = %(want)s on %(face)s; "
             "your answer is what your readTexture returns at (u, v) = (%(got)s).") % {
        "d": d, "want": want, "face": face_name(int(g)), "got": got}


def _consistent(a: np.ndarray, b: np.ndarray, tol: float) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        return np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1) & (np.abs(a - b) <= tol).all(axis=1)


# Lengths that break a lookup computing in float (|component| below float's
# normal range, or above its largest value) and one that squares the
# components (x*x overflows above 1.3e154, underflows to 0 below 1e-162).
FLOAT_TINY, FLOAT_HUGE = 1e-41, 1e39
SQUARE_HUGE, SQUARE_TINY = 1e155, 1e-170


def _lengths(lookups, dirs: np.ndarray, tol: float, out: FetchAnalysis) -> None:
    base = np.asarray(lookups.fetch(dirs).values, np.float64)
    broken = {}
    for scale in (10.0, FLOAT_TINY, FLOAT_HUGE, SQUARE_HUGE, SQUARE_TINY):
        got = np.asarray(lookups.fetch(dirs * scale).values, np.float64)
        ok = _consistent(got, base, tol)
        judged = np.isfinite(base).all(axis=1)
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


def _edge_read(faces: np.ndarray, px: np.ndarray, py: np.ndarray, touched: np.ndarray,
               column: np.ndarray) -> np.ndarray:
    """Answers explained by readTexture's own edge behaviour: a read past a
    touched face's last row lands in the next face's first row of the buffer
    (faces one above the other, docs/assignment.md), one before its first row in
    the previous face's last row, in the column that face's u gives
    (`column` (n, 6): u W per touched face). Not a tie sent astray."""
    h = FACE_SIZE
    rows = np.arange(len(faces))
    out = np.zeros(len(faces), bool)
    for step, row_ok in ((1, py <= 1.0), (-1, py >= h - 2.0)):
        k = faces - step                                   # the touched face it would have read past
        valid = (faces >= 0) & (k >= 0) & (k <= 5) & row_ok
        kk = np.clip(k, 0, 5)
        with np.errstate(invalid="ignore"):
            same_column = np.abs(column[rows, kk] - px) <= 1.5
        out |= valid & touched[rows, kk] & same_column
    return out


TIE_BATCH = 4   # tie directions per fetch: a crash at one (a read past the face) cannot starve the rest


def _ties(lookups, inst: Instrument | None, out: FetchAnalysis) -> None:
    """Ties sent to a face the direction does not touch. An answer counts as
    right when it comes from a touched face (or the face fetchColor samples
    for that face elsewhere), when the fitted readTexture gives it on a
    touched face at the handout's (u, v), or when readTexture's own edge
    behaviour explains it (an unclamped read at u = 1 or v = 1 reading into
    the next face): those are readTexture's mistakes, not a wrong face."""
    dirs = tie_directions()
    verdicts = {v.face: v for v in out.faces if v.analysed}
    values = np.full((len(dirs), 3), np.nan)
    evaluated = np.zeros(len(dirs), bool)
    for lo in range(0, len(dirs), TIE_BATCH):
        got = lookups.fetch(dirs[lo:lo + TIE_BATCH])
        values[lo:lo + TIE_BATCH] = np.asarray(got.values, np.float64)
        evaluated[lo:lo + TIE_BATCH] = np.asarray(got.evaluated, bool)
    faces, px, py = decode_sample_coordinates(values)
    a = np.abs(dirs)
    m = a.max(axis=1)
    touched = np.zeros((len(dirs), 6), bool)
    column = np.full((len(dirs), 6), np.nan)
    explained = np.zeros(len(dirs), bool)
    for axis in range(3):
        at_max = a[:, axis] == m
        touched[at_max & (dirs[:, axis] > 0), 2 * axis] = True
        touched[at_max & (dirs[:, axis] < 0), 2 * axis + 1] = True
        rows = np.flatnonzero(at_max)
        if len(rows):
            d = dirs[rows]
            k = 2 * axis + (d[:, axis] < 0)
            uv = uv_on_face(d, k)
            column[rows, k] = np.clip(uv[:, 0] * FACE_SIZE, 0, FACE_SIZE - 1)
            m_over_len = np.abs(d).max(axis=1) / np.linalg.norm(d, axis=1)
            # As fetchColor treats that face elsewhere: its (u, v) mistake and
            # the face it samples instead, so a wrong face or a flip is not
            # also reported as a tie sent astray.
            for f in np.unique(k):
                sel = k == f
                v = verdicts.get(int(f))
                g = np.full(int(sel.sum()), v.sampled if v is not None and v.sampled is not None else f)
                cand = v.candidate if v is not None and v.candidate is not None and v.share >= SHARE else Candidate()
                if inst is not None:
                    explained[rows[sel]] |= inst.explains(g, cand.uv(uv[sel], m_over_len[sel]), values[rows[sel]])
                if v is not None and v.sampled is not None:
                    touched[rows[sel], v.sampled] = True
    explained |= _edge_read(faces, px, py, touched, column)
    answered = evaluated & (faces >= 0)
    wrong = answered & ~explained & ~touched[np.arange(len(dirs)), np.maximum(faces, 0)]
    if wrong.sum() >= max(1, 0.1 * answered.sum()):
        i = int(np.flatnonzero(wrong)[0])
        text = ", ".join(f"{x:g}" for x in dirs[i])
        ok = _(" or ").join(face_name(k) for k in np.flatnonzero(touched[i]))
        out.ties_untouched = _("fetchColor(Vector3(%(d)s)) samples the %(face)s face, which this "
                               "direction does not touch (it lies on the edge of %(touched)s). With strict "
                               "comparisons (>) a tie fails every test and falls through to the last branch; use "
                               ">= so that a tied direction picks one of the faces it touches.") % {
            "d": text, "face": face_name(int(faces[i])), "touched": ok, "wrong": int(wrong.sum()), "total": len(dirs)}
