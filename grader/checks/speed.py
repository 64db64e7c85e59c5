"""fetchColor's speed against the reference, measured the same way side by side."""
from __future__ import annotations

from .. import PROJECT_ROOT, reference
from ..results import FAILED, CheckResult, Diagnosis
from . import Needs, check
from .context import CheckContext, failure_diagnoses
from .directions import random_directions
from .sweeps import SweepFinding, fetch_sweep
from .textures import random_faces

BASELINE = PROJECT_ROOT / "build" / "reference_submission.so"
ROUNDS = 5          # interleaved rounds: student, reference, student, ...
REPEATS = 2         # timed passes over the batch inside the worker per round
# Each side's time is its fastest round: on a shared machine noise only ever
# adds time, so the minimum is the estimate least moved by other processes.
SWEEP_NEEDED = 0.5  # share of sweep directions right before speed is scored (a face or two wrong still times)
WITHIN = 4.0        # the rubric's `within` overrides this


def baseline_library():
    """build/reference_submission.so, built on first use."""
    reference.ensure_built()
    if not BASELINE.exists():
        import subprocess
        subprocess.run(["make", "-s", "-C", str(PROJECT_ROOT), str(BASELINE.relative_to(PROJECT_ROOT))], check=True)
    return BASELINE


# Returning black is fast: speed only means something for a lookup that works.
@check(requires=(Needs(fetch_sweep, passing=lambda sweep: sweep.fraction >= SWEEP_NEEDED,
                       why=f"speed is scored once fetchColor matches the reference on at least "
                           f"{SWEEP_NEEDED:.0%} of the sweep directions."),))
def speed(ctx: CheckContext, result: CheckResult, sweep: SweepFinding) -> None:
    """fetchColor runs within a few times the reference's time per lookup."""
    from ..worker.lookups import open_lookups
    result.output = ""
    faces = reference.CubeMap(random_faces(256, 256, ctx.seed)).faces
    dirs = random_directions(50_000, ctx.seed + 2)
    within = float(ctx.settings.get("speed", {}).get("within", WITHIN))
    ctx.lookups.set_faces(faces)
    sub_ns, ref_ns = [], []
    with open_lookups(baseline_library(), sandbox=getattr(ctx.lookups, "sandboxed", None)) as base:
        base.set_faces(faces)
        for _ in range(ROUNDS):
            ns, failure = ctx.lookups.time_fetch(dirs, REPEATS)
            if failure is not None:
                result.status, result.fraction = FAILED, 0.0
                result.output = f"fetchColor could not be timed: {failure.describe()}"
                result.diagnoses = failure_diagnoses([failure])
                return
            sub_ns.append(ns)
            ref_ns.append(base.time_fetch(dirs, REPEATS)[0])
            if len(sub_ns) >= 3 and min(sub_ns) > 3 * within * min(ref_ns):
                break   # clearly slow: more rounds would only cost the student's time budget
    sub, ref = float(min(sub_ns)), float(min(ref_ns))
    ratio = sub / ref if ref > 0 else float("inf")
    result.metrics.update(ns_per_lookup=sub, reference_ns_per_lookup=ref, speed_ratio=ratio)
    try:
        point = accuracy_point(ctx, sub)
        result.metrics["uniform_smooth_rms"] = point["uniform_smooth_rms"]
        result.artifacts["speed_accuracy_chart"] = draw_chart(ctx, point)
    except Exception as e:  # the chart is a courtesy: it never costs points
        result.output += f"(The speed-against-accuracy chart could not be drawn: {e})\n\n"
    result.output += (f"Your fetchColor: {sub:.1f} ns per lookup; the reference: {ref:.1f} ns "
                     f"(fastest of {len(sub_ns)} interleaved rounds over {len(dirs)} random directions): {ratio:.2f}x. "
                     f"Full points within {within:g}x.")
    if ratio > within:
        result.status, result.fraction = FAILED, 0.0
        result.diagnoses = [Diagnosis("slow", f"fetchColor takes {ratio:.1f}x the reference's time per lookup (limit {within:g}x).")]


STUDY_FACE_SIZE = 64     # the study's bake at this size takes ~1 s once, then is cached


def accuracy_point(ctx: CheckContext, ns: float) -> dict:
    """The submission's point on the study's chart (docs/study.md): its RMS
    error against the analytic environment, over uniform directions away from
    hard edges, on the study's bake at STUDY_FACE_SIZE; and its time."""
    from ..study import accuracy
    from ..study.bake import bake
    from ..study.ground_truth import DEFAULT_ENVIRONMENT as env
    faces = bake(env, STUDY_FACE_SIZE)
    dirs = accuracy.uniform_directions(20_000)
    ctx.lookups.set_faces(faces)
    rgb = ctx.lookups.fetch(dirs).values
    smooth = accuracy.smooth_mask(env, dirs, STUDY_FACE_SIZE)
    errors = accuracy.per_direction_error(rgb, env.radiance(dirs))
    return {"label": f"your fetchColor (face {STUDY_FACE_SIZE})", "ns_random": ns,
            "uniform_smooth_rms": accuracy.error_stats(errors[smooth])["rms"]}


def draw_chart(ctx: CheckContext, point: dict):
    from ..study import chart
    from ..study.run import read_csv
    rows = read_csv(PROJECT_ROOT / "docs" / "study" / "study.csv")
    path = ctx.artifact("speed_accuracy_chart.png")
    chart.draw(rows, [point], path, panels=chart.PANELS[:1], title="Speed against accuracy", dpi=90)
    return path
