"""fetchColor over direction sweeps, judged through the student's own readTexture, per set and face."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..envmap import library as reference
from ..i18n import _
from ..grading.results import FAILED, CheckResult, Diagnosis
from . import check
from .instruments.compare import Comparison, describe_direction, tolerance, worst_cases
from .context import CheckContext, failure_diagnoses, unique_diagnoses
from .instruments.directions import sweep_sets
from .instruments import own_read
from .read_texture import ReadTextureFinding, read_texture
from .instruments.textures import coordinate_faces

SWEEP_FACE_SIZE = (32, 32)


# Share of sweep directions right before speed and robustness are scored (a
# face or two wrong still counts as working): returning black is fast and
# never crashes, which earns nothing.
WORKING = 0.5


@dataclass(frozen=True)
class SweepFinding:
    """What the fetch_sweep check tells later checks."""
    fraction: float             # share of sweep directions that match the reference

    @property
    def works(self) -> bool:
        return self.fraction >= WORKING


@check(requires=(read_texture,))
def fetch_sweep(ctx: CheckContext, result: CheckResult, texture: ReadTextureFinding) -> SweepFinding:
    """fetchColor picks the right face and (u, v) for every direction: the whole sphere, each face, edge, corner and axis, at any length."""
    # Judged through the student's own readTexture, called live at the
    # reference's face and (u, v) (instruments.own_read): the same strict
    # judge whatever readTexture does, fitted by a model or not.
    w, h = SWEEP_FACE_SIZE
    faces = coordinate_faces(w, h)
    ctx.lookups.set_faces(faces)
    sets = sweep_sets(ctx.seed, fibonacci=20_000 if ctx.quick else 100_000)

    diagnoses, outcomes = [], {}
    for name, dirs in sets.items():
        outcomes[name] = ctx.lookups.fetch(dirs)
        diagnoses += failure_diagnoses(outcomes[name].failures)
    all_dirs = np.concatenate(list(sets.values()))
    all_values = np.concatenate([np.asarray(o.values, np.float64) for o in outcomes.values()])
    verdict = own_read.judge(ctx.lookups, all_dirs, all_values, tolerance(w, h, float(max(w, h) + 1)), (w, h),
                             texels=faces, texture_mismatch=texture.face_mismatch)
    if verdict.context_dependent:
        diagnoses.append(Diagnosis("texture-context-dependent",
                                   _("Called on its own on these faces, your readTexture differs from the handout's "
                                     "far more often than in the readTexture check, so fetchColor is judged against "
                                     "the handout's readTexture here.")))
    ref_faces_all = own_read.reference_faces(all_dirs)

    rows = []
    total = matched = unreadable = 0
    per_face_bad = np.zeros(6, np.int64)
    per_face_all = np.zeros(6, np.int64)
    nan_inputs = []
    lo = 0
    for name, dirs in sets.items():
        part = slice(lo, lo + len(dirs))
        lo += len(dirs)
        outcome, ok, ref_faces = outcomes[name], verdict.ok[part], ref_faces_all[part]
        values, evaluated = np.asarray(outcome.values, np.float64), np.asarray(outcome.evaluated, bool)
        # NaN from an input that ran to the end (not one that crashed or was never run).
        fresh_nan = np.flatnonzero(evaluated & ~np.isfinite(values).all(axis=1))
        if len(fresh_nan) and not nan_inputs:
            nan_inputs.append(dirs[fresh_nan[0]])
        total += len(dirs)
        matched += int(ok.sum())
        unreadable += int((verdict.unreadable[part] & ~ok).sum())
        np.add.at(per_face_all, ref_faces[ref_faces >= 0], 1)
        np.add.at(per_face_bad, ref_faces[(ref_faces >= 0) & ~ok], 1)
        rows.append((name, len(dirs), int(ok.sum())))
        if not ok.all():
            # The worst cases as data: reports say where each lookup landed (face, texel, (u, v)).
            cmp = Comparison(ok=ok, error=verdict.error[part], tolerance=np.zeros(len(dirs)))
            result.mismatches += worst_cases(cmp, lambda i, dirs=dirs: describe_direction(dirs[i]), values,
                                             verdict.expected[part], group=name, face_size=(w, h))
            result.mismatch_counts[name] = len(cmp.failures)
    if nan_inputs:
        diagnoses.append(Diagnosis("nan-output", _("%(call)s returned NaN or infinity for a finite, non-zero direction.")
                                   % {"call": describe_direction(nan_inputs[0])}))
    result.fraction = matched / total if total else 0.0
    result.metrics.update(cases=total, matched=matched)
    if unreadable:
        result.metrics["readtexture_crashed"] = unreadable
    not_earned = ("\n\n" + _("%(count)d directions were not earned because your readTexture itself crashes at the "
                               "face and (u, v) they need (its own check says why).") % {"count": unreadable}
                  if unreadable else "")
    table = [f"| {_('direction set')} | {_('cases')} | {_('match')} |", "|---|---:|---:|"]
    table += [f"| {_(name)} | {n} | {ok / n:.1%} |" if n else f"| {_(name)} | 0 | - |" for name, n, ok in rows]
    table += ["", f"| {_('face')} | {_('directions')} | {_('match')} |", "|---|---:|---:|"]
    table += [f"| {reference.FACE_NAMES[k]} | {per_face_all[k]} | {1 - per_face_bad[k] / max(per_face_all[k], 1):.1%} |" for k in range(6)]
    result.diagnoses = unique_diagnoses(diagnoses)
    if matched < total:
        result.status = FAILED
        result.output = (_("%(wrong)d of %(total)d directions give a colour different from what your own "
                           "readTexture returns at the face and (u, v) the handout's table gives.")
                         % {"wrong": total - matched, "total": total}
                         + "\n\n" + "\n".join(table) + not_earned)
    else:
        result.output = _("All %(total)d directions match the reference.") % {"total": total} + "\n\n" + "\n".join(table)
    return SweepFinding(fraction=result.fraction)
