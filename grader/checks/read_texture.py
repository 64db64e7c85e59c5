"""readTexture against the reference bilinear filter, and what is wrong when it differs."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import reference
from ..results import FAILED, CheckResult, Diagnosis
from . import check
from .compare import compare, explain, tolerance
from .context import CheckContext, failure_diagnoses, unique_diagnoses
from .textures import coordinate_faces, random_faces


@dataclass(frozen=True)
class ReadTextureFinding:
    """What the read_texture check tells the fetchColor checks."""
    ok: bool                    # every readTexture call matched the reference
    mistake: str | None = None  # the recognised mistake's diagnosis id, if any

    def judging_filter(self) -> tuple[str, float]:
        """The filter to judge fetchColor with, and the position tolerance in
        texels: fetchColor is judged on its own, so when readTexture is wrong
        its mapping still earns credit if every sample lands within a texel
        of the right spot."""
        if self.ok:
            return "bilinear", 0.0
        if self.mistake == "nearest-neighbor":
            return "nearest", 1.01
        return "bilinear", 1.01

# Square and non-square faces, so a W/H mix-up shows; faces one texel tall,
# where every row is the last, so reading x = W faults on a guard page on
# every row (rows are contiguous: elsewhere x = W reads the next row's x = 0).
FACE_SIZES = ((16, 16), (13, 7), (9, 1))
# The first and last face: reading past the last face's end leaves the buffer.
FACES = (0, 5)


def sample_points(width: int, height: int, seed: int) -> np.ndarray:
    """(n, 2) (u, v): exactly 0 and 1, every texel boundary k/W and centre
    (k+0.5)/W, and random points, in every combination of u and v kinds."""
    rng = np.random.default_rng(seed)

    def axis(size):
        k = np.arange(size + 1)
        return np.unique(np.concatenate([[0.0, 1.0], k / size, (k[:-1] + 0.5) / size, rng.random(6)]))

    u, v = np.meshgrid(axis(width), axis(height), indexing="ij")
    return np.stack([u.ravel(), v.ravel()], axis=1)


# Mistakes we recognise, each as the (u, v) at which the reference would give
# the same answer (or the reference's other filter). What a student sees is the id.
def _weights_swapped(uv, w, h):
    p = uv * (w, h)
    return np.clip((2 * np.floor(p) + 1 - p) / (w, h), 0.0, 1.0)


HYPOTHESES = {
    "nearest-neighbor": ("nearest", lambda uv, w, h: uv),
    "half-texel-offset": ("bilinear", lambda uv, w, h: np.clip(uv - 0.5 / np.array([w, h]), 0.0, 1.0)),
    "weights-swapped": ("bilinear", _weights_swapped),
    "width-height-swapped": ("bilinear", lambda uv, w, h: np.clip(uv * (h / w, w / h), 0.0, 1.0)),
    "scaled-by-size-minus-one": ("bilinear", lambda uv, w, h: uv * ((w - 1) / w, (h - 1) / h)),
    "uv-swapped": ("bilinear", lambda uv, w, h: uv[:, ::-1]),
    "u-flipped": ("bilinear", lambda uv, w, h: np.stack([1 - uv[:, 0], uv[:, 1]], 1)),
    "v-flipped": ("bilinear", lambda uv, w, h: np.stack([uv[:, 0], 1 - uv[:, 1]], 1)),
}

DETAILS = {
    "nearest-neighbor": "readTexture returns the nearest texel instead of blending the four around p = (uW, vH).",
    "half-texel-offset": "readTexture samples half a texel off: it uses p = (uW - 0.5, vH - 0.5) instead of p = (uW, vH).",
    "weights-swapped": "readTexture blends with swapped weights: alpha goes to c00 and (1 - alpha) to c10.",
    "width-height-swapped": "readTexture mixes up the face width and height (u is scaled by the height or v by the width).",
    "scaled-by-size-minus-one": "readTexture uses p = (u(W-1), v(H-1)) instead of the handout's p = (uW, vH).",
    "uv-swapped": "readTexture uses u for the vertical position and v for the horizontal one.",
    "u-flipped": "readTexture runs u from right to left.",
    "v-flipped": "readTexture runs v from top to bottom (v = 0 must be the bottom row).",
}


def recognise(ctx: CheckContext, cube: reference.CubeMap, face: int, uv: np.ndarray, actual: np.ndarray, tol) -> tuple[str, float] | None:
    """The mistake that explains the submission's answers on the coordinate
    texture best, with the share of points it explains; None when none
    explains 90%."""
    w, h = cube.face_width, cube.face_height
    best = None
    for name, (filter, transform) in HYPOTHESES.items():
        predicted = cube.read_texture(face, transform(uv, w, h), filter)
        share = compare(actual, predicted, tol).fraction
        if best is None or share > best[1]:
            best = (name, share)
    return best if best and best[1] >= 0.9 else None


@check()
def read_texture(ctx: CheckContext, result: CheckResult) -> ReadTextureFinding:
    """readTexture blends the four texels around (uW, vH) as the handout's equations (1)-(3) say."""
    total = matched = 0
    lines, diagnoses = [], []
    recognised: dict[str, int] = {}
    for w, h in FACE_SIZES:
        uv = sample_points(w, h, ctx.seed)
        for kind, faces in (("random", random_faces(w, h, ctx.seed)), ("coordinate", coordinate_faces(w, h))):
            cube = reference.CubeMap(faces)
            ctx.lookups.set_faces(cube.faces)
            for face in FACES:
                expected = cube.read_texture(face, uv, "bilinear")
                tol = tolerance(w, h, float(np.abs(faces[face]).max()))
                for placement in ("end", "start"):
                    outcome = ctx.lookups.read_texture(face, uv, placement)
                    cmp = compare(outcome.values, expected, tol)
                    total += len(uv)
                    matched += int(cmp.ok.sum())
                    diagnoses += failure_diagnoses(outcome.failures)
                    if cmp.fraction < 1.0 and len(lines) < 6:
                        name = reference.FACE_NAMES[face]
                        side = "after" if placement == "end" else "before"
                        lines.append(f"Face {name}, {w}x{h} {kind} texels, inaccessible memory right {side} them:")
                        lines.append(explain(cmp, lambda i: f"readTexture(face {name}, u = {uv[i, 0]:.6g}, v = {uv[i, 1]:.6g})",
                                             outcome.values, expected, limit=3))
                    if kind == "coordinate" and placement == "end" and cmp.fraction < 0.99:
                        found = recognise(ctx, cube, face, uv, outcome.values, tol)
                        if found:
                            recognised[found[0]] = recognised.get(found[0], 0) + 1
    result.fraction = matched / total if total else 0.0
    result.metrics["cases"] = total
    result.metrics["matched"] = matched
    # Report the mistake that explains most cases (one readTexture has one mistake).
    mistake = None
    if recognised:
        mistake = max(sorted(recognised), key=recognised.get)
        diagnoses.insert(0, Diagnosis(mistake, DETAILS[mistake]))
    result.diagnoses = unique_diagnoses(diagnoses)
    if matched < total:
        result.status = FAILED
        result.output = (f"{total - matched} of {total} readTexture calls differ from the reference bilinear filter.\n\n"
                         + "\n".join(lines))
    else:
        result.output = f"All {total} readTexture calls match the reference (u, v at 0, 1, texel boundaries, centres and random points)."
    return ReadTextureFinding(ok=matched == total, mistake=mistake)

