"""Where fetchColor samples, recovered from a coordinate-encoding cube map,
and the mistake that explains it, face by face.

For each face the reference would pick, the submission's answers tell which
face it sampled and at which (u, v) (grader.checks.textures). Candidate
mistakes are tried as transformations of the reference's (u, v), each looked
up through the reference itself, so no part of the lookup is written twice.
"""
from __future__ import annotations

import itertools

import numpy as np

from .. import reference
from ..results import CheckResult, FAILED, Diagnosis
from . import check
from .context import CheckContext
from .directions import fibonacci_sphere, tied_axes
from .read_texture import ReadTextureFinding, read_texture
from .textures import coordinate_faces, decode_sample_coordinates

FACE_SIZE = 32
SHARE = 0.9     # a mistake must explain 90% of a face's directions


def dihedral(swap: bool, flip_u: bool, flip_v: bool):
    """The student's (u, v) as the reference's, swapped and/or flipped."""
    def transform(uv):
        a, b = (uv[:, 1], uv[:, 0]) if swap else (uv[:, 0], uv[:, 1])
        return np.stack([1 - a if flip_u else a, 1 - b if flip_v else b], axis=1)
    ids = [name for name, on in (("uv-swapped", swap), ("u-flipped", flip_u), ("v-flipped", flip_v)) if on]
    return ids, transform


TRANSFORMS = [dihedral(*flags) for flags in itertools.product((False, True), repeat=3)]


def positions(cube, faces, uv, filter):
    """Lattice positions the reference samples at (u, v) on the given faces."""
    rgb = np.empty((len(uv), 3))
    for f in np.unique(faces):
        rows = faces == f
        rgb[rows] = cube.read_texture(int(f), uv[rows], filter)
    return decode_sample_coordinates(rgb)[1:]


def best_transform(cube, faces, uv, px, py, filter, tol):
    """(ids, share) of the dihedral transform that best explains (px, py)."""
    best = ([], -1.0)
    for ids, transform in TRANSFORMS:
        qx, qy = positions(cube, faces, np.clip(transform(uv), 0, 1), filter)
        share = float(np.mean((np.abs(qx - px) <= tol) & (np.abs(qy - py) <= tol)))
        if share > best[1]:
            best = (ids, share)
    return best


def face_name(k: int) -> str:
    return reference.FACE_NAMES[k]


@check(requires=(read_texture,))
def diagnosis(ctx: CheckContext, result: CheckResult, texture: ReadTextureFinding) -> None:
    """fetchColor samples the face the direction exits through, with u and v running the right way."""
    cube = reference.CubeMap(coordinate_faces(FACE_SIZE, FACE_SIZE))
    ctx.lookups.set_faces(cube.faces)
    filter = texture.judging_filter()[0]
    tol = 1e-3 if texture.ok else 1.01

    dirs = fibonacci_sphere(6000 if ctx.quick else 20_000)
    ref_faces, ref_uv = reference.direction_to_face(dirs)
    sub = ctx.lookups.fetch(dirs)
    sub_faces, px, py = decode_sample_coordinates(sub.values)
    # Away from edges and corners, and only inputs that ran to the end (a
    # crash is diagnosed by the check that met it, not guessed at here).
    clear = (tied_axes(dirs).sum(axis=1) == 1) & sub.evaluated

    diagnoses: list[Diagnosis] = []
    lines = []
    if clear.any() and np.all(sub_faces[clear] < 0):
        diagnoses.append(Diagnosis("not-implemented", "fetchColor returns black (or a colour that is not in the texture) for every direction: it still looks like the starting code."))
    else:
        # Scale invariance: the direction's length must not matter.
        scaled = ctx.lookups.fetch(dirs * 10.0)
        s_faces, sx, sy = decode_sample_coordinates(scaled.values)
        moved = (s_faces != sub_faces) | (np.abs(sx - px) > tol) | (np.abs(sy - py) > tol)
        if np.mean(moved[clear]) > 0.1:
            diagnoses.append(Diagnosis("not-normalized", "The answer changes when the direction is made 10 times longer: divide the face-plane coordinates by the major component's magnitude m."))
        for f in range(6):
            if (clear & (ref_faces == f)).sum() < 20:
                continue        # too few answers toward this face to say anything
            rows = clear & (ref_faces == f) & (sub_faces >= 0)
            if not rows.any():
                diagnoses.append(Diagnosis("wrong-face", f"Directions toward {face_name(f)} return a colour that is not in the texture (black?).", face=face_name(f)))
                continue
            sampled = np.bincount(sub_faces[rows], minlength=6)
            g = int(np.argmax(sampled))
            if g != f and sampled[g] >= SHARE * rows.sum():
                diagnoses.append(Diagnosis("wrong-face", f"Directions toward {face_name(f)} sample the {face_name(g)} face.", face=face_name(f)))
            ids, share = best_transform(cube, sub_faces[rows], ref_uv[rows], px[rows], py[rows], filter, tol)
            if share < SHARE:
                # Divided by the length instead of the major component?
                m_over_len = np.abs(dirs[rows]).max(axis=1) / np.linalg.norm(dirs[rows], axis=1)
                uv_len = 0.5 + (ref_uv[rows] - 0.5) * m_over_len[:, None]
                ids_len, share_len = best_transform(cube, sub_faces[rows], uv_len, px[rows], py[rows], filter, tol)
                if share_len >= SHARE:
                    if not any(d.id == "not-normalized" for d in diagnoses):
                        diagnoses.append(Diagnosis("not-normalized", "fetchColor divides by the direction's length instead of the major component's magnitude m, so (u, v) do not reach the face's edges."))
                    ids, share = ids_len, share_len
            for mistake in ids if share >= SHARE else []:
                diagnoses.append(Diagnosis(mistake, _detail(mistake, f), face=face_name(f)))
            if share < SHARE:
                diagnoses.append(Diagnosis("uv-mismatch", f"On the {face_name(f)} face, (u, v) follow no pattern we recognise ({share:.0%} of directions explained by the best guess).", face=face_name(f)))
            lines.append(f"| {face_name(f)} | {face_name(g)} | {', '.join(ids) if share >= SHARE else '?'} | {share:.0%} |")
    result.diagnoses = diagnoses
    mapping_ok = not diagnoses
    result.fraction = 1.0 if mapping_ok else 0.0
    if not mapping_ok:
        result.status = FAILED
        table = ["| direction toward | face sampled | (u, v) mistakes | explained |", "|---|---|---|---:|"] + lines
        result.output = "\n".join(["What fetchColor does, recovered from a texture whose texels encode their own position:", ""] + (table if lines else []))
    else:
        result.output = "On every face, fetchColor samples the right face with u and v running the right way."


def _detail(mistake: str, f: int) -> str:
    name = face_name(f)
    return {
        "u-flipped": f"On the {name} face, u runs the wrong way (your u is 1 - u of the (u, v) table in README.md).",
        "v-flipped": f"On the {name} face, v runs the wrong way (your v is 1 - v of the (u, v) table in README.md).",
        "uv-swapped": f"On the {name} face, u and v are swapped.",
    }[mistake]
