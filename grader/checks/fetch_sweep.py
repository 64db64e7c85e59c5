"""fetchColor over direction sweeps, judged through the student's own readTexture, per set and face."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..envmap import library as reference
from ..i18n import _
from ..grading.results import FAILED, CheckResult, Diagnosis
from . import Credit, check, shown
from .instruments.compare import Comparison, describe_direction, tolerance, worst_cases
from .context import CheckContext, failure_diagnoses, unique_diagnoses
from .instruments.directions import FIBONACCI_SET, RANDOM_SET, sweep_sets
from .instruments import own_read
from .read_texture import ReadTextureFinding, read_texture
from .instruments.textures import coordinate_faces

SWEEP_FACE_SIZE = (32, 32)


# Robustness and speed count in proportion to how much of the sweep is right:
# nothing up to WORKING[0] (returning black is fast and never crashes, which
# earns nothing), everything from WORKING[1] (a face or two wrong, 83% and
# 67%, still counts as working), in a straight line between. A line, not a
# threshold: one more direction right never moves those 15 points by more
# than a few hundredths (a 50% threshold put the same code 8 points apart,
# issue 30).
WORKING = (0.3, 0.6)
# The random set keeps the fixed sets honest (a lookup that knows the public
# directions gains nothing by it) but scores nothing itself: 20,000 draws
# put its share within +-0.7% of the sphere's (two standard errors at 50%),
# +-0.03 points of 30, and a score must not hinge on the draw (issue 30).
# Its share below the Fibonacci sphere's by more than STANDARD_ERRORS
# standard errors (chance: 1 in 10^9) is not chance: then it is the share.
STANDARD_ERRORS = 6.0
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
    share_of = {}
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
        # Over the directions it answered: where the worker gave up after a
        # crash, no direction says anything about the set (the later sets lose most).
        share_of[name] = (float(ok[evaluated].mean()), int(evaluated.sum())) if evaluated.any() else (1.0, 0)
        if name != RANDOM_SET:      # the points are on the fixed sets (RANDOM_SET's comment above)
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
    fraction = shown(matched / total) if total else 0.0
    # The random set held to the Fibonacci sphere: both estimate the share of
    # the sphere that is right, the random one within its standard error.
    (drawn, n), even = share_of[RANDOM_SET], share_of[FIBONACCI_SET][0]
    by_chance = STANDARD_ERRORS * np.sqrt(max(even * (1 - even), 1.0 / max(n, 1)) / max(n, 1))
    answers_differ = n >= MIN_ANSWERED and drawn < even - by_chance and drawn < fraction
    if answers_differ:
        fraction = shown(drawn)
    result.fraction = fraction
    result.metrics.update(cases=total, matched=matched, random_share=shown(drawn))
    if unreadable:
        result.metrics["readtexture_crashed"] = unreadable
    not_earned = ("\n\n" + _("%(count)d directions were not earned because your readTexture itself crashes at the "
                               "face and (u, v) they need (its own check says why).") % {"count": unreadable}
                  if unreadable else "")
    table = [f"| {_('direction set')} | {_('cases')} | {_('match')} |", "|---|---:|---:|"]
    table += [f"| {_(name)} | {n} | {ok / n:.2%} |" if n else f"| {_(name)} | 0 | - |" for name, n, ok in rows]
    table += ["", f"| {_('face')} | {_('directions')} | {_('match')} |", "|---|---:|---:|"]
    table += [f"| {reference.FACE_NAMES[k]} | {per_face_all[k]} | {1 - per_face_bad[k] / max(per_face_all[k], 1):.2%} |" for k in range(6)]
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
    if matched < total or answers_differ:
        result.status = FAILED
        result.output = (_("%(wrong)d of %(total)d directions give a colour different from what your own "
                           "readTexture returns at the face and (u, v) the handout's table gives: %(share)s right.")
                         % {"wrong": total - matched, "total": total, "share": f"{shown(matched / total):.2%}"}
                         + "\n\n" + "\n".join(table) + random_words + not_earned)
    else:
        result.output = (_("All %(total)d directions match the reference.") % {"total": total} + "\n\n"
                         + "\n".join(table) + random_words)
    return SweepFinding(fraction=fraction)
