"""Full renders with the submission's lookup, against the fixture renders."""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..grading import fixtures
from ..envmap import oracle
from ..i18n import _
from ..grading.results import FAILED, CheckResult, Diagnosis
from . import check, shown
from .context import CheckContext, failure_diagnoses, look_up_public_map, unique_diagnoses
from .instruments import map_probe
from .instruments.map_probe import load_map, stamp
from .instruments.image_metrics import difference_picture, display, flip, flip_pixels, ssim

# Measured on the correct solutions (-O0, -O3, -ffast-math, float and double)
# and on the zoo of wrong ones; docs/thresholds.md has the numbers.
SSIM_MIN = 0.99995
FLIP_MAX = 0.0006
# A render that fails the rule above scores the share of its pixels whose
# own FLIP error is at most this: so one wrong face costs about the share of
# the picture it covers, and a black render about everything. Set well above
# the largest per-pixel error of any correct build (docs/thresholds.md).
PIXEL_FLIP_MAX = 0.02


@dataclass(frozen=True)
class RenderScore:
    ssim: float
    flip_mean: float
    flip_map: np.ndarray | None    # magma-coloured, for the report (None: identical images, made when pictured)
    passed: bool            # the whole-image rule: full marks
    matched: float          # share of pixels with FLIP <= PIXEL_FLIP_MAX (1.0 when passed)

    @property
    def score(self) -> float:
        return 1.0 if self.passed else self.matched


def score_render(expected_display: np.ndarray, got_display: np.ndarray) -> RenderScore:
    """The renders check's rule for one render, on display images.

    Two identical images (a correct lookup's render, bit for bit, most of a
    class) score SSIM 1 and FLIP 0 exactly, as computed: every term of both
    is a difference of the two images or a ratio of equal products
    (tests/unit/checks/test_renders.py holds the shortcut to the full
    computation); their FLIP map is made only for the render pictured."""
    if np.array_equal(expected_display, got_display):
        return RenderScore(1.0, 0.0, None, True, 1.0)
    s = ssim(expected_display, got_display)
    f_mean, f_map = flip(expected_display, got_display)
    passed = s >= SSIM_MIN and f_mean <= FLIP_MAX
    matched = 1.0 if passed else matched_share(expected_display, got_display)
    return RenderScore(s, f_mean, f_map, passed, matched)


def matched_share(expected_display: np.ndarray, got_display: np.ndarray) -> float:
    """Share of pixels a person could not tell from the reference's."""
    return float((flip_pixels(expected_display, got_display) <= PIXEL_FLIP_MAX).mean())


@functools.lru_cache(maxsize=16)
def _traced(scene: tuple, size: tuple[int, int], spp: int):
    """The reference's camera paths of a scene (the same for every
    submission: traced once per process, not once per grading; four renders
    share the main scene). Read-only, so no caller can change them for the next."""
    escapes = oracle.current().trace(scene[0], size, spp)
    for a in (escapes.dirs, escapes.weights, escapes.pixels):
        a.setflags(write=False)
    return escapes


@functools.lru_cache(maxsize=16)
def _expected(render: tuple) -> np.ndarray:
    expected = display(np.load(render[0], allow_pickle=False))
    expected.setflags(write=False)
    return expected


def render_with_submission(ctx: CheckContext, fixture: fixtures.RenderFixture, largest: tuple[int, int] | None = None,
                           first: bool = True, sample=None):
    """(image, outcome): the fixture's scene traced by the reference, the
    environment looked up by the submission in its worker. The first render
    of a check starts a worker whose first lookup was on faces larger than
    `largest` (the largest map the check uses); the others follow in that
    worker, as a student's program would look up one map after another."""
    escapes = _traced(stamp(fixture.scene), fixtures.RENDER_SIZE, fixtures.RENDER_SPP)
    faces = load_map(fixture.map)
    outcome = look_up_public_map(ctx, faces, escapes.dirs, largest, first, sample)
    rgb = np.nan_to_num(outcome.values, nan=0.0, posinf=0.0, neginf=0.0)
    return oracle.current().resolve(escapes, rgb), outcome


@check(end_to_end=True, public_maps=True)
def renders(ctx: CheckContext, result: CheckResult) -> None:
    """Full renders of the mirror and glass spheres with your lookup look like the reference renders."""
    from ..envmap.imaging import write_image
    rows, diagnoses, passed, earned = [], [], 0, 0.0
    items = fixtures.render_fixtures()
    if ctx.quick:
        items = items[:1]
    worst = None
    crashed_in = None
    sizes = [load_map(fixture.map).shape[1:3] for fixture in items]
    largest = (max(h for h, _ in sizes), max(w for _, w in sizes)) if sizes else None
    samples = map_probe.sample_runs(ctx, "renders", [
        (fixture.name, _("the render of %(render)s") % {"render": render_name(fixture)},
         _traced(stamp(fixture.scene), fixtures.RENDER_SIZE, fixtures.RENDER_SPP).dirs, load_map(fixture.map).shape[1:3])
        for fixture in items])
    for number, fixture in enumerate(items):
        if crashed_in is not None:
            # Each crash costs a search for its input; one crashed render says enough.
            rows.append(f"| {render_name(fixture)} | | | | "
                        + _("not run: crashed in %(render)s") % {"render": crashed_in} + " |")
            continue
        image, outcome = render_with_submission(ctx, fixture, largest, first=number == 0, sample=samples.get(fixture.name))
        diagnoses += failure_diagnoses(outcome.failures)
        if outcome.failures:
            crashed_in = fixture.name
        expected = _expected(stamp(fixture.path)).copy()   # fixture.load(), once per process; FLIP wants it writable
        got = display(image)
        scored = score_render(expected, got)
        s, f_mean, f_map, ok = scored.ssim, scored.flip_mean, scored.flip_map, scored.passed
        passed += ok
        earned += shown(scored.score)       # as the table prints it: the numbers shown are the numbers used
        rows.append(f"| {render_name(fixture)} | {s:.5f} | {f_mean:.5f} | {shown(scored.matched):.2%} "
                    f"| {_('pass') if ok else _('FAIL')} |")
        result.metrics[f"ssim_{fixture.name}"] = s
        result.metrics[f"flip_mean_{fixture.name}"] = f_mean
        if worst is None or s < worst[0]:
            worst = (s, f_mean, fixture, expected, got, f_map)
    if worst is not None:
        # The pictures show the render that differs most: the one a student learns most from.
        s, f_mean, fixture, expected, got, f_map = worst
        if f_map is None:
            f_map = flip(expected, got)[1]
        result.metrics["ssim"], result.metrics["flip_mean"] = s, f_mean
        for name, picture in (("render_reference", expected), ("render_submission", got),
                              ("render_difference", difference_picture(expected, got)), ("render_flip", f_map)):
            path = ctx.artifact(f"{name}.png")
            write_image(path, picture, display_referred=True)
            result.artifacts[name] = path
    # A render not run (after a crash) earns nothing.
    result.fraction = earned / len(items) if items else 1.0
    if passed < len(items):
        result.status = FAILED
        diagnoses.append(Diagnosis("render-mismatch", _("%(wrong)d of %(total)d renders differ visibly from the reference "
                                                        "(SSIM below %(ssim)s or FLIP above %(flip)s).")
                                   % {"wrong": len(items) - passed, "total": len(items), "ssim": SSIM_MIN, "flip": FLIP_MAX}))
    result.diagnoses = unique_diagnoses(diagnoses)
    if passed < len(items):
        rows.append("\n" + _("The check's share: %(share)s, the mean of the %(count)d renders' shares above "
                              "(one not run counts 0%%).") % {"share": f"{shown(result.fraction):.2%}", "count": len(items)})
    header = [f"| {_('render')} | SSIM | FLIP | {_('pixels that match')} | |", "|---|---:|---:|---:|---|"]
    pictured = ("\n\n" + _("The pictures show %(render)s, the render that differs most.") % {"render": render_name(worst[2])}
             if worst else "")
    result.output = (_("Pass: SSIM >= %(ssim)s and mean FLIP <= %(flip)s on tone-mapped images. "
                       "A render that fails earns the share of its pixels that match (per-pixel FLIP <= %(pixel)s).")
                     % {"ssim": SSIM_MIN, "flip": FLIP_MAX, "pixel": PIXEL_FLIP_MAX}
                     + "\n\n" + "\n".join(header + rows) + pictured)


def render_name(fixture) -> str:
    """A render as "scene with map" (file names stay as they are)."""
    return _("%(scene)s with %(map)s") % {"scene": fixture.scene.stem, "map": fixture.map.name}
