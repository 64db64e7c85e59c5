"""Where the renders check's thresholds (SSIM_MIN, FLIP_MAX, PIXEL_FLIP_MAX) come from.

    .venv/bin/python bench/measure_render_thresholds.py [--out build/thresholds]

Renders every fixture scene (grader.grading.fixtures.render_fixtures()) with the
lookup of
  - every correct solution in tests/submissions/correct/, each built four
    ways: -O0, -O2 (the grader's default), -O3 and -O3 -ffast-math (one of
    them, float_math.cpp, computes in float);
  - every wrong submission in tests/submissions/wrong/ (default build),
    except those that never produce a render (syntax-error, slow,
    timeout-loop);
  - the reference library itself (the floor: what storing the fixture as
    RGBE .hdr costs);
exactly as the renders check does (grader.checks.renders.render_with_submission
in a worker, then image_metrics.display / ssim / flip against the fixture).

For each render it records SSIM, mean FLIP, and the fraction of pixels that
differ by more than one 8-bit level from the same scene rendered with the
reference lookup ("changed": 0 means the mistake is invisible in that render).
Writes measurements.csv (one row per render) and thresholds.md (the tables
and the recommended thresholds) to --out, and prints the Markdown.

It also records the largest per-pixel FLIP error of each render and the
share of its pixels at or below PIXEL_FLIP_MAX ("matched": what a failing
render scores), and for each wrong submission the matched share of every
render.

Recommendation: per metric, the worst correct render against, for each
wrong submission that changes some render, its most telling render; the
threshold sits at the geometric middle of the gap in dissimilarity
(1 - SSIM, FLIP), so both margins are the same factor. PIXEL_FLIP_MAX has
no such gap (a wrong render has pixels of every error). It is chosen so that
a render with one face wrong scores the share of pixels that face does not
reach: on the main scene with a map of random texels (every texel unlike its
neighbours, so a wrong face changes every pixel it reaches), each face in
turn has v flipped, and the candidate (at least PIXEL_MARGIN times the
largest per-pixel error of any correct build) whose matched shares are
closest to the unreached shares is recommended. The table of matched shares
shows what the zoo's wrong submissions then keep.
"""
from __future__ import annotations

import argparse
import csv
import math
import sys
import time
import types
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from grader.grading import fixtures  # noqa: E402
from grader.envmap import library
from grader.build import build_submission  # noqa: E402
from grader.checks import renders  # noqa: E402
from grader.checks.instruments.image_metrics import display, flip, flip_pixels, ssim  # noqa: E402
from grader.worker.lookups import open_lookups  # noqa: E402

SUBMISSIONS = ROOT / "tests" / "submissions"
VARIANTS = {"-O0": ("-O0",), "-O2": (), "-O3": ("-O3",), "-O3 -ffast-math": ("-O3", "-ffast-math")}
DEFAULT_VARIANT = "-O2"
# Wrong submissions that never produce a render to compare.
NO_RENDER = ("syntax-error", "slow", "timeout-loop")
# A pixel counts as changed when it moves by more than one 8-bit display level.
CHANGED_LEVEL = 1.0 / 255.0
# PIXEL_FLIP_MAX sits at least this factor above the largest per-pixel FLIP
# error of any correct build.
PIXEL_MARGIN = 10.0
# Other per-pixel thresholds shown beside the chosen one.
PIXEL_CANDIDATES = (0.01, 0.02, 0.05, 0.1, 0.2)


@dataclass
class Measurement:
    kind: str          # correct, wrong or reference
    submission: str
    variant: str
    fixture: str
    ssim: float
    flip: float
    changed: float     # fraction of pixels unlike the reference-lookup render
    ssim_unstored: float   # against the reference-lookup render itself, before RGBE storage
    flip_unstored: float
    failures: int      # inputs the worker reported as failed (crash, out-of-bounds read, ...)
    pixel_flip_max: float = 0.0   # largest per-pixel FLIP error against the fixture
    matched: float = 1.0          # share of pixels with per-pixel FLIP <= renders.PIXEL_FLIP_MAX
    matched_at: tuple = ()        # the same share at each of PIXEL_CANDIDATES


@dataclass
class Scene:
    fixture: fixtures.RenderFixture
    expected: np.ndarray           # the fixture, display-referred
    reference_render: np.ndarray   # the reference lookup's render, display-referred, not stored


def prepare_scenes() -> list[Scene]:
    out = []
    for fixture in fixtures.render_fixtures():
        escapes = fixtures.prepared_scene(fixture).trace()
        cube = library.CubeMap.load_cross(fixture.map)
        reference_render = escapes.resolve(cube.fetch(escapes.dirs, "bilinear"))
        out.append(Scene(fixture, display(fixture.load()), display(reference_render)))
    return out


def compare(scene: Scene, image_display: np.ndarray) -> tuple[float, ...]:
    """SSIM and FLIP against the fixture (what the check sees), the fraction
    of changed pixels, SSIM and FLIP against the reference-lookup render
    (what the build alone changes, without the fixture's RGBE rounding), 0,
    and the per-pixel figures: largest FLIP error, matched share at
    PIXEL_FLIP_MAX and at each candidate."""
    changed = np.abs(image_display - scene.reference_render).max(axis=2) > CHANGED_LEVEL
    pixels = flip_pixels(scene.expected, image_display)
    return (ssim(scene.expected, image_display), flip(scene.expected, image_display)[0], float(changed.mean()),
            ssim(scene.reference_render, image_display), flip(scene.reference_render, image_display)[0],
            0, float(pixels.max()), float((pixels <= renders.PIXEL_FLIP_MAX).mean()),
            tuple(float((pixels <= t).mean()) for t in PIXEL_CANDIDATES))


def measure_library(library: Path, scenes: list[Scene], kind: str, name: str, variant: str) -> list[Measurement]:
    rows = []
    with open_lookups(library) as lookups:
        ctx = types.SimpleNamespace(lookups=lookups)
        for scene in scenes:
            image, outcome = renders.render_with_submission(ctx, scene.fixture)
            figures = list(compare(scene, display(image)))
            figures[5] = len(outcome.failures)
            rows.append(Measurement(kind, name, variant, scene.fixture.name, *figures))
    return rows


def measure_reference(scenes: list[Scene]) -> list[Measurement]:
    rows = []
    for scene in scenes:
        rows.append(Measurement("reference", "reference library", "", scene.fixture.name,
                                *compare(scene, scene.reference_render)))
    return rows


def build(path: Path, variant: str) -> Path:
    built = build_submission(path, extra_flags=VARIANTS[variant])
    if not built.ok:
        raise SystemExit(f"{path.name} {variant} did not build:\n{built.log}")
    return built.library


def fails(row: Measurement, ssim_min: float, flip_max: float) -> bool:
    """The renders check's own rule."""
    return not (row.ssim >= ssim_min and row.flip <= flip_max)


@dataclass
class Gap:
    metric: str
    correct_worst: float       # dissimilarity of the worst correct render
    correct_where: str
    wrong_least: float         # of the hardest wrong submission's most telling render
    wrong_who: str

    @property
    def exists(self) -> bool:
        return self.wrong_least > self.correct_worst

    @property
    def middle(self) -> float:
        return math.sqrt(self.correct_worst * self.wrong_least)


def gaps(rows: list[Measurement], visible: set[str], unstored: bool = False) -> list[Gap]:
    """unstored: against the reference lookup's render instead of the fixture
    (what the gaps would be with fixtures stored without RGBE rounding)."""
    correct = [r for r in rows if r.kind == "correct"]
    out = []
    if unstored:
        metrics = (("SSIM", lambda r: 1.0 - r.ssim_unstored), ("FLIP", lambda r: r.flip_unstored))
    else:
        metrics = (("SSIM", lambda r: 1.0 - r.ssim), ("FLIP", lambda r: r.flip))
    for metric, dissimilarity in metrics:
        worst = max(correct, key=dissimilarity)
        telling = {}
        for name in visible:
            telling[name] = max((r for r in rows if r.kind == "wrong" and r.submission == name), key=dissimilarity)
        hardest = min(telling.values(), key=dissimilarity)
        out.append(Gap(metric, dissimilarity(worst), f"{worst.submission} {worst.variant} on {worst.fixture}",
                       dissimilarity(hardest), f"{hardest.submission} on {hardest.fixture}"))
    return out


def nice(value: float) -> float:
    """Two significant digits: a threshold a person can read."""
    return float(f"{value:.2g}")


def markdown(rows: list[Measurement], ssim_min: float, flip_max: float, elapsed: dict[str, float]) -> str:
    scenes = list(dict.fromkeys(r.fixture for r in rows))
    lines = [f"Current thresholds (grader/checks/renders.py): SSIM_MIN = {ssim_min}, FLIP_MAX = {flip_max}.", ""]

    lines += ["### Correct solutions and the reference (min SSIM, max mean FLIP over the "
              f"{len(scenes)} renders)", "",
              "Against the fixture, as the check compares; changed pixels and the unstored columns are against "
              "the reference lookup's own render before it is stored as RGBE .hdr, so they show what the build "
              "alone changes.", "",
              "| submission | build | min SSIM | max FLIP | max changed pixels | min SSIM, unstored | max FLIP, unstored "
              "| failed inputs | verdict now |", "|---|---|---:|---:|---:|---:|---:|---:|---|"]
    groups = {}
    for r in rows:
        if r.kind != "wrong":
            groups.setdefault((r.submission, r.variant), []).append(r)
    for (name, variant), group in groups.items():
        verdict = "FAIL" if any(fails(r, ssim_min, flip_max) for r in group) else "pass"
        lines.append(f"| {name} | {variant} | {min(r.ssim for r in group):.5f} | {max(r.flip for r in group):.4f} "
                     f"| {100 * max(r.changed for r in group):.2f}% | {min(r.ssim_unstored for r in group):.7f} "
                     f"| {max(r.flip_unstored for r in group):.6f} | {sum(r.failures for r in group)} | {verdict} |")

    wrong = [r for r in rows if r.kind == "wrong"]
    names = list(dict.fromkeys(r.submission for r in wrong))
    short = {name: f"R{i + 1}" for i, name in enumerate(scenes)}
    lines += ["", "### Wrong submissions, per render: SSIM / FLIP (changed pixels); * = fails now", "",
              "Renders: " + "; ".join(f"{short[n]} = {n}" for n in scenes), "",
              "| submission | min SSIM | max FLIP | " + " | ".join(short[n] for n in scenes) + " | verdict now |",
              "|---|---:|---:|" + "---|" * len(scenes) + "---|"]
    for name in names:
        group = {r.fixture: r for r in wrong if r.submission == name}
        cells = []
        for scene in scenes:
            r = group[scene]
            mark = "*" if fails(r, ssim_min, flip_max) else ""
            cells.append(f"{r.ssim:.3f} / {r.flip:.3f} ({100 * r.changed:.0f}%){mark}")
        verdict = "FAIL" if any(fails(r, ssim_min, flip_max) for r in group.values()) else "**passes all**"
        lines.append(f"| {name} | {min(r.ssim for r in group.values()):.4f} | {max(r.flip for r in group.values()):.4f} | "
                     + " | ".join(cells) + f" | {verdict} |")

    visible = {n for n in names if any(r.changed > 0 for r in wrong if r.submission == n)}
    invisible = [n for n in names if n not in visible]
    partial = {n: [r.fixture for r in wrong if r.submission == n and r.changed == 0] for n in sorted(visible)}
    lines += ["", "### Visibility", ""]
    lines.append("- Change no render at all (left to the other checks): "
                 + (", ".join(invisible) if invisible else "none") + ".")
    for name, unseen in partial.items():
        if unseen:
            lines.append(f"- {name}: invisible in {', '.join(unseen)}.")
    passing = [n for n in visible if not any(fails(r, ssim_min, flip_max) for r in wrong if r.submission == n)]
    lines.append("- Change some render yet pass every render with the current thresholds: "
                 + (", ".join(sorted(passing)) if passing else "none") + ".")

    lines += ["", "### Gaps and recommended thresholds", "",
              "| metric | worst correct (1-SSIM or FLIP) | where | least telling wrong | who | gap | geometric middle | margin factor |",
              "|---|---:|---|---:|---|---|---:|---:|"]
    recommended = {}
    for gap in gaps(rows, visible):
        if gap.exists:
            margin = math.sqrt(gap.wrong_least / gap.correct_worst)
            recommended[gap.metric] = nice(gap.middle)
            lines.append(f"| {gap.metric} | {gap.correct_worst:.3g} | {gap.correct_where} | {gap.wrong_least:.3g} | "
                         f"{gap.wrong_who} | yes | {gap.middle:.3g} | {margin:.2f}x |")
        else:
            lines.append(f"| {gap.metric} | {gap.correct_worst:.3g} | {gap.correct_where} | {gap.wrong_least:.3g} | "
                         f"{gap.wrong_who} | **none** (closed by {gap.wrong_who}) | | |")
    lines.append("")
    for metric, middle in recommended.items():
        gap = next(g for g in gaps(rows, visible) if g.metric == metric)
        value = 1.0 - middle if metric == "SSIM" else middle
        name = "SSIM_MIN" if metric == "SSIM" else "FLIP_MAX"
        lines.append(f"- {name} = {value:.6g}: the worst correct render is {middle / gap.correct_worst:.2f}x "
                     f"inside it, the least telling wrong one {gap.wrong_least / middle:.2f}x outside "
                     f"(in {'1 - SSIM' if metric == 'SSIM' else 'mean FLIP'}).")
    if {"SSIM", "FLIP"} <= set(recommended):
        rec_ssim, rec_flip = 1.0 - recommended["SSIM"], recommended["FLIP"]
        correct_fail = [r for r in rows if r.kind == "correct" and fails(r, rec_ssim, rec_flip)]
        wrong_pass = [n for n in visible if not any(fails(r, rec_ssim, rec_flip) for r in wrong if r.submission == n)]
        lines.append(f"- With these, correct renders failing: {len(correct_fail)}; visible wrong submissions "
                     f"passing every render: {len(wrong_pass)}.")
    lines += ["", "If the fixtures kept the reference render's floats (no RGBE rounding), the gaps would be:", "",
              "| metric | worst correct | where | least telling wrong | who | margin factor at the middle |",
              "|---|---:|---|---:|---|---:|"]
    for gap in gaps(rows, visible, unstored=True):
        margin = f"{math.sqrt(gap.wrong_least / gap.correct_worst):.0f}x" if gap.exists and gap.correct_worst > 0 else "-"
        lines.append(f"| {gap.metric} | {gap.correct_worst:.2g} | {gap.correct_where} | {gap.wrong_least:.3g} | "
                     f"{gap.wrong_who} | {margin} |")
    lines += pixel_tables(rows, scenes, short, one_face_wrong(fixtures.render_fixtures()[0]),
                          fixtures.render_fixtures()[0].name)
    lines += ["", "Time: " + ", ".join(f"{k} {v:.1f} s" for k, v in elapsed.items()) + "."]
    return "\n".join(lines) + "\n"


@dataclass
class OneFace:
    face: str
    unreached: float             # share of pixels none of whose light comes from the face
    matched: tuple               # share of pixels matched at each of PIXEL_CANDIDATES


def one_face_wrong(fixture: fixtures.RenderFixture, seed: int = 3) -> list[OneFace]:
    """For each face: v flipped on that face only (the rest the reference),
    on `fixture`'s scene with a map of random texels; the share of pixels
    the face does not reach (a render with that face white, the rest black,
    is black there) and the matched share at each candidate threshold."""
    escapes = fixtures.prepared_scene(fixture).trace()
    noise = np.random.default_rng(seed).uniform(0.0, 2.0, (6, 32, 32, 3)).astype(np.float32)
    cube = library.CubeMap(noise)
    expected = display(escapes.resolve(cube.fetch(escapes.dirs, "bilinear")))
    faces, uv = library.direction_to_face(escapes.dirs)
    out = []
    for k, name in enumerate(library.FACE_NAMES):
        only = np.zeros_like(noise)
        only[k] = 1.0
        reach = escapes.resolve(library.CubeMap(only).fetch(escapes.dirs, "bilinear")).max(axis=2)
        flipped = uv.copy()
        flipped[faces == k, 1] = 1.0 - flipped[faces == k, 1]
        values = cube.read_texture(np.maximum(faces, 0), flipped, "bilinear")
        values[faces < 0] = 0.0
        pixels = flip_pixels(expected, display(escapes.resolve(values)))
        out.append(OneFace(name, float((reach <= 0).mean()),
                           tuple(float((pixels <= t).mean()) for t in PIXEL_CANDIDATES)))
    return out


def pixel_tables(rows: list[Measurement], scenes: list[str], short: dict[str, str],
                 one_face: list[OneFace], one_face_fixture: str) -> list[str]:
    """Per-pixel FLIP: the correct builds' largest error, the recommended
    PIXEL_FLIP_MAX, and the share of pixels each wrong render keeps."""
    correct = [r for r in rows if r.kind == "correct"]
    worst = max(correct, key=lambda r: r.pixel_flip_max)
    allowed = [i for i, t in enumerate(PIXEL_CANDIDATES) if t >= PIXEL_MARGIN * worst.pixel_flip_max]
    error = {i: float(np.mean([abs(f.matched[i] - f.unreached) for f in one_face])) for i in allowed}
    recommended = PIXEL_CANDIDATES[min(error, key=error.get)] if error else float("nan")
    lines = ["", "### Per-pixel FLIP: partial credit for a failing render", "",
             f"One face wrong (v flipped), {one_face_fixture} with a map of random 32 x 32 texels: share of pixels "
             "the face does not reach, and the share matched at each candidate PIXEL_FLIP_MAX:", "",
             "| face wrong | not reached | " + " | ".join(f"matched at {t:g}" for t in PIXEL_CANDIDATES) + " |",
             "|---|---:|" + "---:|" * len(PIXEL_CANDIDATES)]
    for f in one_face:
        lines.append(f"| {f.face} | {f.unreached:.3f} | " + " | ".join(f"{m:.3f}" for m in f.matched) + " |")
    lines.append("| mean absolute difference | | " + " | ".join(
        f"{error[i]:.3f}" if i in error else "(margin too small)" for i in range(len(PIXEL_CANDIDATES))) + " |")
    lines += ["",
             f"Largest per-pixel FLIP error of any correct build: {worst.pixel_flip_max:.4g} "
             f"({worst.submission} {worst.variant} on {worst.fixture}); per build:", "",
             "| build | largest per-pixel FLIP over all correct solutions and renders |", "|---|---:|"]
    for variant in VARIANTS:
        group = [r for r in correct if r.variant == variant]
        lines.append(f"| {variant} | {max(r.pixel_flip_max for r in group):.4g} |")
    lines += ["", f"Recommended PIXEL_FLIP_MAX = {recommended:g} (of the candidates at least {PIXEL_MARGIN:g}x the "
              f"largest correct error, the one whose one-face scores are closest to the unreached shares); "
              f"in use: {renders.PIXEL_FLIP_MAX:g} ({renders.PIXEL_FLIP_MAX / worst.pixel_flip_max:.0f}x the largest "
              f"correct error). "
              f"Correct renders with a pixel above the one in use: "
              f"{sum(r.pixel_flip_max > renders.PIXEL_FLIP_MAX for r in correct)}.", "",
              f"Share of pixels matched (per-pixel FLIP <= {renders.PIXEL_FLIP_MAX:g}) per wrong render, "
              "and the renders score the check would give (a passing render scores 1):", "",
              "| submission | " + " | ".join(short[n] for n in scenes) + " | renders score (all 7) | "
              + " | ".join(f"score at {t:g}" for t in PIXEL_CANDIDATES) + " |",
              "|---|" + "---:|" * (len(scenes) + 1 + len(PIXEL_CANDIDATES))]
    wrong = [r for r in rows if r.kind == "wrong"]
    ssim_min, flip_max = renders.SSIM_MIN, renders.FLIP_MAX
    for name in dict.fromkeys(r.submission for r in wrong):
        group = {r.fixture: r for r in wrong if r.submission == name}
        per = [group[n] for n in scenes]

        def score(r: Measurement, share: float) -> float:
            return share if fails(r, ssim_min, flip_max) else 1.0
        at = [np.mean([score(r, r.matched_at[i]) for r in per]) for i in range(len(PIXEL_CANDIDATES))]
        lines.append(f"| {name} | " + " | ".join(f"{100 * score(r, r.matched):.1f}%" for r in per)
                     + f" | {np.mean([score(r, r.matched) for r in per]):.3f} | " + " | ".join(f"{a:.3f}" for a in at) + " |")
    return lines


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=ROOT / "build" / "thresholds")
    args = parser.parse_args()

    began = time.perf_counter()
    scenes = prepare_scenes()
    elapsed = {"fixtures": time.perf_counter() - began}

    correct = sorted((SUBMISSIONS / "correct").glob("*.cpp"))
    wrong = [p for p in sorted((SUBMISSIONS / "wrong").glob("*.cpp")) if p.stem not in NO_RENDER]
    jobs = [("correct", p, v) for p in correct for v in VARIANTS] + [("wrong", p, DEFAULT_VARIANT) for p in wrong]

    began = time.perf_counter()
    libraries = [build(path, variant) for _, path, variant in jobs]
    elapsed["builds"] = time.perf_counter() - began

    began = time.perf_counter()
    rows = measure_reference(scenes)
    for (kind, path, variant), library in zip(jobs, libraries):
        rows += measure_library(library, scenes, kind, path.stem, variant)
        print(f"  {kind:7} {path.stem:28} {variant}", file=sys.stderr)
    elapsed["renders and metrics"] = time.perf_counter() - began

    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "measurements.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(asdict(rows[0])))
        writer.writeheader()
        writer.writerows(asdict(r) for r in rows)
    text = markdown(rows, renders.SSIM_MIN, renders.FLIP_MAX, elapsed)
    (args.out / "thresholds.md").write_text(text)
    print(text)
    print(f"Wrote {args.out / 'measurements.csv'} and {args.out / 'thresholds.md'}.", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
