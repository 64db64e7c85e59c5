"""fetchColor over direction sweeps, compared per face with the reference."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import reference
from ..results import FAILED, CheckResult, Diagnosis
from . import check
from .compare import compare, describe_direction, tie_alternatives, tolerance, worst_cases
from .context import CheckContext, failure_diagnoses, unique_diagnoses
from .directions import sweep_sets
from .read_texture import ReadTextureFinding, read_texture
from .textures import coordinate_faces

SWEEP_FACE_SIZE = (32, 32)


@dataclass(frozen=True)
class SweepFinding:
    """What the fetch_sweep check tells later checks."""
    fraction: float             # share of sweep directions that match the reference


@check(requires=(read_texture,))
def fetch_sweep(ctx: CheckContext, result: CheckResult, texture: ReadTextureFinding) -> SweepFinding:
    """fetchColor picks the right face and (u, v) for every direction: the whole sphere, each face, edge, corner and axis, at any length."""
    w, h = SWEEP_FACE_SIZE
    faces = coordinate_faces(w, h)
    cube = texture.instrument(reference.CubeMap(faces))   # through the student's own readTexture when it is modelled
    ctx.lookups.set_faces(cube.faces)
    filter, slack = texture.judging_filter()
    sets = sweep_sets(ctx.seed, fibonacci=20_000 if ctx.quick else 100_000)

    rows, diagnoses = [], []
    total = matched = skipped = 0
    per_face_bad = np.zeros(6, np.int64)
    per_face_all = np.zeros(6, np.int64)
    nan_inputs = []
    for name, dirs in sets.items():
        outcome = ctx.lookups.fetch(dirs)
        diagnoses += failure_diagnoses(outcome.failures)
        expected, ref_faces = cube.fetch_with_faces(dirs, filter)
        # The fitted readTexture model reads past the face here (NaN): the
        # student's own readTexture crashes or reads garbage there, and that
        # is charged to readTexture, so fetchColor is not judged on these rows.
        judged = np.isfinite(expected).all(axis=1)
        skipped += int((~judged).sum())
        dirs, expected, ref_faces = dirs[judged], expected[judged], ref_faces[judged]
        values, evaluated = outcome.values[judged], outcome.evaluated[judged]
        acceptable = np.concatenate([expected[:, None, :], tie_alternatives(cube, dirs, filter)], axis=1)
        tol = tolerance(w, h, float(max(w, h) + 1)) + slack
        cmp = compare(values, acceptable, tol)
        # NaN from an input that ran to the end (not one that crashed or was never run).
        fresh_nan = np.flatnonzero(evaluated & ~np.isfinite(values).all(axis=1))
        if len(fresh_nan) and not nan_inputs:
            nan_inputs.append(dirs[fresh_nan[0]])
        total += len(dirs)
        matched += int(cmp.ok.sum())
        np.add.at(per_face_all, ref_faces[ref_faces >= 0], 1)
        np.add.at(per_face_bad, ref_faces[(ref_faces >= 0) & ~cmp.ok], 1)
        rows.append((name, len(dirs), int(cmp.ok.sum())))
        if cmp.fraction < 1.0:
            # The worst cases as data: reports say where each lookup landed (face, texel, (u, v)).
            result.mismatches += worst_cases(cmp, lambda i, dirs=dirs: describe_direction(dirs[i]), values, expected,
                                             group=name, face_size=(w, h))
            result.mismatch_counts[name] = len(cmp.failures)
    if nan_inputs:
        diagnoses.append(Diagnosis("nan-output", f"{describe_direction(nan_inputs[0])} returned NaN or infinity for a finite, non-zero direction."))
    result.fraction = matched / total if total else 0.0
    result.metrics.update(cases=total, matched=matched)
    not_judged = (f"\n\n{skipped} directions were not judged: there your readTexture (as fitted) reads past the "
                  "face, which its own check charges." if skipped else "")
    table = ["| direction set | cases | match |", "|---|---:|---:|"]
    table += [f"| {name} | {n} | {ok / n:.1%} |" if n else f"| {name} | 0 | - |" for name, n, ok in rows]
    table += ["", "| face | directions | match |", "|---|---:|---:|"]
    table += [f"| {reference.FACE_NAMES[k]} | {per_face_all[k]} | {1 - per_face_bad[k] / max(per_face_all[k], 1):.1%} |" for k in range(6)]
    result.diagnoses = unique_diagnoses(diagnoses)
    if matched < total:
        result.status = FAILED
        result.output = (f"{total - matched} of {total} directions give a colour different from the reference.\n\n"
                         + "\n".join(table) + not_judged)
    else:
        result.output = f"All {total} directions match the reference.\n\n" + "\n".join(table) + not_judged
    return SweepFinding(fraction=result.fraction)
