"""fetchColor where methods fail: degenerate directions, ties moved by one ulp,
and continuity across the cube's edges."""
from __future__ import annotations

import numpy as np

from ..i18n import N_, _
from ..grading.results import FAILED, CheckResult, Diagnosis
from . import Needs, check, shown
from .instruments.compare import describe_direction, format_vector, tolerance, worst_cases
from .context import CheckContext, failure_diagnoses, set_end_to_end_faces, unique_diagnoses
from .instruments.directions import corners, edges, fibonacci_sphere
from .instruments import fetch_record
from .read_texture import ReadTextureFinding, read_texture
from .fetch_sweep import WORKING_CREDIT, SweepFinding, fetch_sweep
from ..cubemap.directions import texel_directions
from ..envmap import library as reference
from ..envmap.geometry import face_uv_to_direction
from .instruments.textures import coordinate_faces

FACE_SIZE = 16
TINY = 5e-324          # the smallest denormal
HUGE = 1e308


def degenerate_directions() -> np.ndarray:
    """Zero, NaN and infinite components: any answer is fine, crashing is not."""
    nan, inf = np.nan, np.inf
    return np.array([
        [0, 0, 0], [-0.0, -0.0, -0.0], [nan, 0, 0], [0, nan, 0], [0, 0, nan], [nan, nan, nan],
        [inf, 0, 0], [0, -inf, 0], [0, 0, inf], [inf, inf, inf], [-inf, inf, -inf], [inf, nan, 1],
    ], np.float64)


def extreme_directions() -> np.ndarray:
    """Finite, non-zero directions of extreme length: the answer must be finite."""
    return np.array([
        [TINY, 0, 0], [0, TINY, 0], [0, 0, -TINY], [TINY, TINY, TINY], [1e-310, -2e-310, 3e-310],
        [HUGE, 0, 0], [0, -HUGE, 0], [HUGE, HUGE, HUGE], [HUGE, 1, 1], [1, HUGE, -HUGE],
        [1e-300, 1e-300, 1], [1, 1e-300, 1e-300], [1e300, 1e-300, 0],
    ], np.float64)


# Lengths as exact powers of two: a direction scaled by 2^k is the same
# direction to the last bit where the scaled components are exact (kept only
# there), so an answer that changes between two of them is the length's doing.
LENGTH_EXPONENTS = (-1000, -600, -140, -30, 0, 10, 30, 140, 600, 1000)
LENGTH_BASES = 24   # directions of the sphere asked at every length, beside the extreme ones


def same_direction_lengths(extreme: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(dirs (n, 3), base (n,)): each base direction at every length of
    LENGTH_EXPONENTS where the scaling is exact, and each finite, non-zero
    extreme direction as it is beside its own base (itself brought, exactly,
    to a largest component in [0.5, 1))."""
    finite = extreme[np.isfinite(extreme).all(axis=1) & (np.abs(extreme).max(axis=1) > 0)]
    _mantissa, e = np.frexp(np.abs(finite).max(axis=1))
    bases = np.concatenate([np.ldexp(finite, -e[:, None]), fibonacci_sphere(LENGTH_BASES)])
    dirs, base = [finite], [np.arange(len(finite))]
    with np.errstate(over="ignore", under="ignore"):
        for k in LENGTH_EXPONENTS:
            scaled = np.ldexp(bases, k)
            exact = np.isfinite(scaled).all(axis=1) & (np.ldexp(scaled, -k) == bases).all(axis=1)
            dirs.append(scaled[exact])
            base.append(np.flatnonzero(exact))
    return np.concatenate(dirs), np.concatenate(base)


def _asked(rec, i: int) -> str:
    """What fetchColor did for direction i, as the record shows it."""
    faces, uv = rec.request()
    if rec.calls[i] == 0:
        return _("makes no readTexture call and returns %(rgb)s") % {"rgb": format_vector(rec.values[i])}
    if faces[i] >= 0:
        return _("asks readTexture for face %(face)s at (u, v) = (%(u)s, %(v)s)") % {
            "face": reference.FACE_NAMES[int(faces[i])], "u": f"{uv[i, 0]:.6g}", "v": f"{uv[i, 1]:.6g}"}
    return _("returns %(rgb)s") % {"rgb": format_vector(rec.values[i])}


def length_dependence(lookups, extreme: np.ndarray, texels: np.ndarray, tol) -> Diagnosis | None:
    """The same direction at two lengths, right at one and wrong at the
    other (both recorded): length-dependent, with the pair, or None."""
    dirs, base = same_direction_lengths(extreme)
    rec, verdict = fetch_record.observe(lookups, dirs, texels, tol)
    answered = rec.calls >= 0
    changing = [b for b in np.unique(base)
                if verdict.ok[(base == b) & answered].any() and (~verdict.ok[(base == b) & answered]).any()]
    if not changing:
        return None
    # The pair at the most ordinary lengths (nearest 1): the easiest two calls to try.
    scale = np.abs(np.log2(np.abs(dirs).max(axis=1)))
    pairs = []
    for b in changing:
        rows = np.flatnonzero((base == b) & answered)
        wrong = min(rows[~verdict.ok[rows]], key=lambda i: scale[i])
        right = min(rows[verdict.ok[rows]], key=lambda i: scale[i])
        pairs.append((scale[wrong] + scale[right], wrong, right))
    _cost, wrong, right = min(pairs)
    return Diagnosis("length-dependent", _(
        "%(wrong)s %(wrong_asked)s; the same direction at another length, %(right)s, %(right_asked)s, as the "
        "table gives. The two differ by a power of two only (no digit of the ratios changes), so the length "
        "alone changes your answer: %(count)d of %(bases)d directions asked at several lengths, from the "
        "smallest denormals to 1e308, do this.") % {
        "wrong": describe_direction(dirs[wrong]), "wrong_asked": _asked(rec, wrong),
        "right": describe_direction(dirs[right]), "right_asked": _asked(rec, right),
        "count": len(changing), "bases": len(np.unique(base))})


def ulp_moved(dirs: np.ndarray) -> np.ndarray:
    """Each direction with every component moved one ulp up and one ulp down."""
    return np.concatenate([np.nextafter(dirs, np.inf), np.nextafter(dirs, -np.inf)])


def border_and_interior(size: int = FACE_SIZE, per_face: int = 64, seed: int = 7):
    """Directions whose (u, v) lie within one texel of a face's border, and
    directions at least two texels inside it: (border, interior), each (n, 3)."""
    rng = np.random.default_rng(seed)
    texel = 1.0 / size
    faces = np.repeat(np.arange(6), per_face)
    n = len(faces)
    # Border: one coordinate in the outer texel (either side), the other anywhere.
    across = rng.uniform(0.0, 1.0, n)
    band = rng.uniform(0.0, texel, n)
    band = np.where(rng.random(n) < 0.5, band, 1.0 - band)
    u_first = rng.random(n) < 0.5
    u, v = np.where(u_first, band, across), np.where(u_first, across, band)
    border = face_uv_to_direction(faces, u, v)
    inner = rng.uniform(2 * texel, 1.0 - 2 * texel, (n, 2))
    interior = face_uv_to_direction(faces, inner[:, 0], inner[:, 1])
    return border, interior


def seam_only(lookups, texels: np.ndarray, tol) -> tuple[bool, int, int]:
    """(wrong only near the edges, border directions wrong, border directions
    judged): every direction two texels or more inside a face matches what
    fetchColor asks readTexture for is right (instruments.fetch_record), and
    some within a texel of the border are not. A crash says nothing about
    where the mistake is (other checks report it)."""
    border, interior = border_and_interior()
    results = []
    for dirs in (border, interior):
        rec, verdict = fetch_record.observe(lookups, dirs, texels, tol)
        if rec.outcome.failures or (rec.calls < 0).any():
            return False, 0, 0
        results.append((int((~verdict.ok).sum()), len(dirs)))
    (border_bad, border_judged), (interior_bad, _) = results
    return interior_bad == 0 and border_bad > 0, border_bad, border_judged


def edge_pairs(k: int = 8, offset: float = 1e-7):
    """Directions just either side of each of the 12 edges: (a, b, edge index)."""
    on = edges(k)
    a, b = on.copy(), on.copy()
    for i, d in enumerate(on):
        tied = np.flatnonzero(np.abs(d) == np.abs(d).max())
        a[i, tied[0]] *= 1 + offset
        b[i, tied[1]] *= 1 + offset
    return a, b, np.repeat(np.arange(12), k)


# A lookup that returns black never crashes: robustness, like speed, counts
# in proportion to how much of the sweep works (sweeps.WORKING). It always
# runs, so the crashes and NaNs it finds are named.
@check(requires=(read_texture, Needs(fetch_sweep, credit=WORKING_CREDIT)), end_to_end=True)
def stability(ctx: CheckContext, result: CheckResult, texture: ReadTextureFinding, sweep: SweepFinding) -> None:
    """fetchColor survives zero, NaN, infinite, tiny and huge directions, and agrees with the reference at ties and across edges."""
    # Texels that encode their position; every answer judged on the record
    # of what fetchColor asks readTexture (instruments.fetch_record), as if
    # its readTexture were the handout's: the student's readTexture plays no part.
    size = (FACE_SIZE, FACE_SIZE)
    texels = coordinate_faces(FACE_SIZE, FACE_SIZE)
    set_end_to_end_faces(ctx, texels)
    tol = tolerance(FACE_SIZE, FACE_SIZE, FACE_SIZE + 1.0)
    parts, diagnoses = [], []

    # 1. Degenerate directions: only crashing is wrong (fetchColor's own:
    # its readTexture calls are answered by the recording).
    degenerate = degenerate_directions()
    rec = fetch_record.record(ctx.lookups, degenerate)
    parts.append((N_("zero, NaN and infinite directions do not crash"), len(degenerate), int((rec.calls >= 0).sum())))
    diagnoses += failure_diagnoses(rec.outcome.failures)

    # 2. Extreme but valid directions: finite and what a correct fetchColor gives.
    extreme = extreme_directions()
    rec, verdict = fetch_record.observe(ctx.lookups, extreme, texels, tol)
    diagnoses += failure_diagnoses(rec.outcome.failures)
    nan_rows, seen = fetch_record.not_finite(rec)
    if len(nan_rows):
        # The cause (float conversion, a squared length, a division by the
        # length) is named by its own diagnosis beside this one; here only what happened.
        diagnoses.append(Diagnosis("nan-output", _("%(call)s %(seen)s: NaN or infinity, for a direction that is finite "
                                                   "and not zero.")
                                   % {"call": describe_direction(extreme[nan_rows[0]]), "seen": seen[0]}))
    parts.append((N_("tiny and huge directions give the reference colour"), len(extreme), int(verdict.ok.sum())))
    group = N_("tiny and huge directions")   # a key; reports read it out with _()
    result.mismatches += worst_cases(verdict, lambda i: describe_direction(extreme[i]), verdict.actual, verdict.expected,
                                     group=group, hits=lambda i: fetch_record.hits(verdict, i, size))
    result.mismatch_counts[group] = len(verdict.failures)
    # The same directions at other lengths (not scored): says, with a pair of
    # calls, when only the length changes the answer (issue 29, patterns 6, 8, 11).
    found = length_dependence(ctx.lookups, extreme, texels, tol)
    if found is not None:
        diagnoses.append(found)

    # 3. Ties moved by one ulp: either touching face is right.
    ties = ulp_moved(np.concatenate([corners(), edges(4)]))
    rec, verdict = fetch_record.observe(ctx.lookups, ties, texels, tol)
    diagnoses += failure_diagnoses(rec.outcome.failures)
    parts.append((N_("edges and corners moved by one ulp"), len(ties), int(verdict.ok.sum())))

    # Where the answers are wrong: only within a texel of the cube's edges?
    near_edges_only, border_bad, border_judged = seam_only(ctx.lookups, texels, tol)
    seam_hint = (" " + _("Away from the edges your colours match the reference: only directions within one texel of a "
                         "face's border are wrong (%(bad)d of %(judged)d tried there). Look at what happens to "
                         "(u, v) at the face's border: the clamp, the rounding, or which face an edge direction goes to.")
                 % {"bad": border_bad, "judged": border_judged} if near_edges_only else "")

    # 4. Continuity: on a continuous environment (each texel holds the
    # direction through it), the jump across each edge is no larger than a
    # correct fetchColor's: the handout's readTexture at the recorded (face,
    # u, v) either side of the edge.
    smooth = (0.5 + 0.5 * texel_directions(FACE_SIZE)).astype(np.float32)
    ctx.lookups.set_faces(smooth)
    smooth_tol = tolerance(FACE_SIZE, FACE_SIZE, 1.0)
    a, b, edge = edge_pairs()
    _rec_a, judged_a = fetch_record.observe(ctx.lookups, a, smooth, smooth_tol)
    _rec_b, judged_b = fetch_record.observe(ctx.lookups, b, smooth, smooth_tol)
    with np.errstate(invalid="ignore"):
        ref_jump = np.abs(judged_a.expected - judged_b.expected).max(axis=1)
        sub_jump = np.abs(judged_a.actual - judged_b.actual).max(axis=1)
    # Both sides what the table gives, or a jump no larger than a correct
    # fetchColor's; a side where nothing was recorded (a crash) fails (NaN).
    bad = ~(judged_a.ok & judged_b.ok) & ~(sub_jump <= ref_jump + 2 * smooth_tol)
    bad_edges = sorted({int(e) for e in edge[bad]})
    parts.append((N_("no seam larger than the reference's at the 12 edges"), 12, 12 - len(bad_edges)))
    if bad_edges:
        diagnoses.append(Diagnosis("discontinuous-seam", _("The colour jumps across %(count)d of the 12 cube edges where the "
                                                           "reference is continuous: neighbouring faces disagree about (u, v) "
                                                           "along their shared edge.") % {"count": len(bad_edges)} + seam_hint))
    elif near_edges_only:
        diagnoses.append(Diagnosis("discontinuous-seam", _("The colours differ from the reference next to the cube's edges.") + seam_hint))

    total = sum(n for _, n, _ in parts)
    ok = sum(k for _, _, k in parts)
    result.fraction = ok / total
    result.diagnoses = unique_diagnoses(diagnoses)
    table = ([f"| {_('case')} | {_('tried')} | {_('passed')} |", "|---|---:|---:|"]
             + [f"| {_(name)} | {n} | {k} |" for name, n, k in parts])
    result.output = "\n".join(table) + "\n\n" + _("Passed: %(ok)d of %(total)d, %(share)s.") % {
        "ok": ok, "total": total, "share": f"{shown(result.fraction):.2%}"}
    if ok < total:
        result.status = FAILED
