"""The handout's own debugging check, automated: on test_environment_map.hdr
the red, green and blue arrows must point along +x, +y and +z.

Each arrow ends in a filled disc at its + pole (grader/cubemap/test_map.py).
The check looks where the submission shows each arrow's disc (small caps
around the six axis directions) and whether the arrow's whole shape lands
where the reference puts it; then it draws the mirror sphere rendered with
the submission's lookup, labelled with what it found.
"""
from __future__ import annotations

import numpy as np

from .. import PROJECT_ROOT
from ..envmap import oracle
from ..i18n import N_, _, and_list, language, languages
from ..grading.results import FAILED, CheckResult, Diagnosis
from . import check, shown
from .context import CheckContext, failure_diagnoses, look_up_public_map, unique_diagnoses
from .instruments.directions import axes, fibonacci_sphere
from .instruments import map_probe
from .instruments.map_probe import load_map

TEST_MAP = PROJECT_ROOT / "Cubemap" / "test_environment_map.hdr"
ARROW_SCENE = PROJECT_ROOT / "scenes" / "mirror_ball_test_map.cfg"
ARROWS = ((N_("red"), "+x"), (N_("green"), "+y"), (N_("blue"), "+z"))   # colour names: catalogue ids
AXIS_NAMES = ("+x", "+y", "+z", "-x", "-y", "-z")   # the order of directions.axes()
SHAPE_AGREEMENT = 0.9   # share of the reference's arrow pixels the submission must reproduce


def colour_class(rgb: np.ndarray) -> np.ndarray:
    """0, 1, 2 for clearly red, green, blue; -1 for grey or anything else."""
    rgb = np.nan_to_num(np.asarray(rgb, np.float64), nan=0.0, posinf=0.0, neginf=0.0)
    top = rgb.argmax(axis=1)
    peak = rgb.max(axis=1)
    rest = np.sort(rgb, axis=1)[:, 1]
    return np.where((peak > 0.2) & (rest < 0.5 * peak), top, -1)


def axis_caps(radius_deg: float = 2.0, per_cap: int = 24) -> np.ndarray:
    """(6, per_cap, 3): directions within radius of each axis direction."""
    rng = np.random.default_rng(7)
    out = []
    for a in axes()[[0, 1, 2, 3, 4, 5]]:
        t = np.deg2rad(radius_deg) * np.sqrt(rng.random(per_cap))
        phi = 2 * np.pi * rng.random(per_cap)
        helper = np.array([0.0, 0.0, 1.0]) if abs(a[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        e1 = np.cross(a, helper); e1 /= np.linalg.norm(e1)
        e2 = np.cross(a, e1)
        out.append(np.cos(t)[:, None] * a + np.sin(t)[:, None] * (np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2))
    return np.stack(out)


def disc_axes(classes: np.ndarray) -> list[list[int]]:
    """For each arrow, the axes whose cap shows its colour (majority)."""
    return [[i for i in range(6) if np.mean(classes[i] == k) > 0.5] for k in range(3)]


@check(end_to_end=True, public_maps=True)
def arrows(ctx: CheckContext, result: CheckResult) -> None:
    """On test_environment_map.hdr the red, green and blue arrows point along +x, +y and +z."""
    texels = load_map(TEST_MAP)
    caps = axis_caps()
    sphere = fibonacci_sphere(6000 if ctx.quick else 20_000)
    both = np.concatenate([caps.reshape(-1, 3), sphere])
    samples = map_probe.sample_runs(ctx, "arrows", [
        ("arrows", _("the arrows check on %(map)s") % {"map": TEST_MAP.name}, both, texels.shape[1:3])])
    outcome = look_up_public_map(ctx, texels, both, sample=samples.get("arrows"))
    diagnoses = failure_diagnoses(outcome.failures)
    n_caps = caps.shape[0] * caps.shape[1]
    sub_caps = colour_class(outcome.values[:n_caps]).reshape(caps.shape[:2])
    sub_sphere = colour_class(outcome.values[n_caps:])
    ref_sphere = colour_class(oracle.current().fetch(texels, sphere))

    found = disc_axes(sub_caps)
    verdicts, passed = [], 0
    for k, (colour, axis) in enumerate(ARROWS):
        where = [AXIS_NAMES[i] for i in found[k]]
        shape = shown(float(np.mean(sub_sphere[ref_sphere == k] == k)))   # decided as printed
        pole_ok = where == [axis]
        shape_ok = shape >= SHAPE_AGREEMENT
        passed += pole_ok + shape_ok
        words = {"colour": _(colour), "axis": axis, "where": and_list(where), "shape": f"{shape:.2%}"}
        if not where:
            verdicts.append(_("%(colour)s arrow: missing (no %(colour)s disc at any axis)") % words)
            diagnoses.append(Diagnosis("arrow-missing", _("The %(colour)s arrow's head (%(colour)s disc at %(axis)s) "
                                                          "appears nowhere along the axes.") % words))
        elif not pole_ok:
            verdicts.append(_("%(colour)s arrow: points toward %(where)s, should be %(axis)s") % words)
            diagnoses.append(Diagnosis("arrow-wrong", _("The %(colour)s arrow points toward %(where)s instead of %(axis)s.") % words))
        elif not shape_ok:
            verdicts.append(_("%(colour)s arrow: points to %(axis)s but is drawn wrongly (%(shape)s of it in place)") % words)
            diagnoses.append(Diagnosis("arrow-wrong", _("The %(colour)s arrow points toward %(axis)s, but only %(shape)s of it "
                                                        "is where it should be: part of it is flipped or on the wrong face.") % words))
        else:
            verdicts.append(_("%(colour)s arrow: points along %(axis)s") % words)
        result.metrics[f"{colour}_shape"] = shape
    result.fraction = passed / 6
    result.diagnoses = unique_diagnoses(diagnoses)
    result.output = "\n".join(f"- {v}" for v in verdicts)
    if passed < 6:
        result.output += "\n\n" + _("%(passed)d of 6 halves (%(share)s): each arrow earns half for pointing along its "
                                    "axis and half for %(shape)s or more of it in place.") % {
            "passed": passed, "share": f"{shown(passed / 6):.2%}", "shape": f"{SHAPE_AGREEMENT:.0%}"}
    if passed < 6:
        result.status = FAILED
    try:
        result.artifacts["arrows"] = draw(ctx, texels, verdicts)
    except Exception as e:  # a picture is a courtesy; its failure must not cost points
        result.output += "\n\n" + _("(The arrow picture could not be drawn: %(error)s)") % {"error": e}


# Latin fonts, first found: DejaVu (Debian's fonts-dejavu-core, or matplotlib's
# copy where it is installed), else the Droid fonts OpenImageIO ships.
LATIN_FONTS = ("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", "DejaVuSans.ttf", "DroidSans")
LATIN_MONO_FONTS = ("/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf", "DejaVuSansMono.ttf", "DroidSansMono")


def _font(candidates) -> str:
    """A font OpenImageIO can render: a path that exists, a DejaVu file in
    matplotlib's data folder (found without importing matplotlib), or a name
    of one of OpenImageIO's own fonts."""
    import importlib.util
    from pathlib import Path
    spec = importlib.util.find_spec("matplotlib")
    mpl = Path(spec.origin).parent / "mpl-data" / "fonts" / "ttf" if spec and spec.origin else None
    for name in candidates:
        if name.startswith("/"):
            if Path(name).is_file():
                return name
        elif name.endswith(".ttf"):
            if mpl is not None and (mpl / name).is_file():
                return str(mpl / name)
        else:
            return name
    return ""


def _fonts() -> tuple[str, str]:
    """(titles, captions); a language whose glyphs the Latin fonts lack uses its own font for both."""
    own = languages.glyph_font(language())
    if own is not None:
        return own, own
    return _font(LATIN_FONTS), _font(LATIN_MONO_FONTS)


def draw(ctx: CheckContext, texels: np.ndarray, verdicts: list[str]):
    """The large mirror ball of scenes/mirror_ball_test_map.cfg (every face in
    view) with the reference's and the submission's lookup, side by side,
    captioned with the verdicts."""
    from ..envmap.imaging import tone_map, write_image
    ref = oracle.current()
    escapes = ref.trace(ARROW_SCENE, (200, 200), 2)
    sub = ctx.lookups.fetch(escapes.dirs)
    images = [ref.resolve(escapes, ref.fetch(texels, escapes.dirs)),
              ref.resolve(escapes, np.nan_to_num(sub.values, nan=0.0, posinf=0.0, neginf=0.0))]
    # OpenImageIO, which the grader reads and writes images with, also
    # resizes and sets text: no plotting or imaging library besides (the
    # student kit's environment stays small; matplotlib's import was ~0.3 s).
    import OpenImageIO as oiio
    side, pad, line = 300, 12, 17
    fonts = _fonts()
    canvas = np.ones((28 + side + pad + line * len(verdicts) + pad, 2 * side + 3 * pad, 3), np.float32)
    for k, image in enumerate(images):
        picture = oiio.ImageBufAlgo.resize(oiio.ImageBuf(np.ascontiguousarray(np.clip(tone_map(image), 0, 1))),
                                           filtername="triangle", roi=oiio.ROI(0, side, 0, side, 0, 1, 0, 3))
        left = pad + k * (side + pad)
        canvas[28:28 + side, left:left + side] = picture.get_pixels(oiio.FLOAT)
    page = oiio.ImageBuf(canvas)
    black = (0.0, 0.0, 0.0)
    for k, title in enumerate((_("reference"), _("your fetchColor"))):
        oiio.ImageBufAlgo.render_text(page, pad + k * (side + pad) + side // 2, 6, title, 15, fonts[0], black,
                                      "center", "top")
    for i, text in enumerate(verdicts):
        oiio.ImageBufAlgo.render_text(page, canvas.shape[1] // 2, 28 + side + pad + i * line, text, 13, fonts[1],
                                      black, "center", "top")
    path = ctx.artifact("arrows.png")
    write_image(path, page.get_pixels(oiio.FLOAT), display_referred=True)
    return path
