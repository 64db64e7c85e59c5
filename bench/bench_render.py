"""Speed of the reference renderer on envmap_test.cfg (512 x 512, 16 spp).

    .venv/bin/python bench/bench_render.py [--scene FILE.cfg] [--map FILE_cross.hdr] [--repeats 5]

Times, on one core, the median of the repeats of:
  - render: em_render (trace, look up in batches, resolve; all in C);
  - the same split in the two steps the grader uses for a submission:
    trace (em_trace and the copy into numpy), lookup (em_fetch_batch over
    every escape) and resolve (em_resolve);
  - the baseline, measured in the same run: the same camera with the
    spheres removed (one escape per sample, no bounces).
Prints the times, the escapes per sample, and the ratios render / baseline
and render / (trace + lookup + resolve).
"""
from __future__ import annotations

import argparse
import re
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from grader.envmap.library import CubeMap, Scene  # noqa: E402


def median_seconds(fn, repeats: int):
    """(median seconds, last result) of fn() over repeats runs."""
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def without_spheres(text: str) -> str:
    return re.sub(r"\bsphere\s*\{[^}]*\}", "", text)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", type=Path, default=ROOT / "envmap_test.cfg")
    parser.add_argument("--map", type=Path, help="vertical cross (default: the scene's)")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()

    scene = Scene.load(args.scene)
    text = args.scene.read_text()
    baseline = Scene.parse(without_spheres(text), str(args.scene), str(args.scene.parent))
    cube = CubeMap.load_cross(args.map or scene.environment_path)
    spp = samples_per_pixel(text)
    samples = scene.width * scene.height * spp
    print(f"{args.scene.name}: {scene.width} x {scene.height}, {spp} spp, "
          f"map {args.map or scene.environment_path}, median of {args.repeats}")

    t_render, image = median_seconds(lambda: scene.render(cube), args.repeats)
    t_base, _ = median_seconds(lambda: baseline.render(cube), args.repeats)
    t_trace, escapes = median_seconds(scene.trace, args.repeats)
    t_lookup, rgb = median_seconds(lambda: cube.fetch(escapes.dirs), args.repeats)
    t_resolve, split = median_seconds(lambda: escapes.resolve(rgb), args.repeats)
    assert split.tobytes() == image.tobytes(), "trace + resolve differs from render"

    n = len(escapes.dirs)
    print(f"  render (em_render)        {t_render:8.3f} s")
    print(f"  baseline (no spheres)     {t_base:8.3f} s")
    print(f"  trace (em_trace + copy)   {t_trace:8.3f} s   {n} escapes, {n / samples:.2f} per sample")
    print(f"  lookup (em_fetch_batch)   {t_lookup:8.3f} s   {1e9 * t_lookup / n:.0f} ns per escape")
    print(f"  resolve (em_resolve)      {t_resolve:8.3f} s")
    print(f"  render / baseline                 {t_render / t_base:.2f}")
    print(f"  render / (trace+lookup+resolve)   {t_render / (t_trace + t_lookup + t_resolve):.2f}")
    return 0


def samples_per_pixel(text: str) -> int:
    """The scene's samples per pixel, as the API shows it: a one-pixel image
    with the spheres removed has one escape per sample."""
    probe = Scene.parse(without_spheres(text), "probe")
    probe.set_resolution(1, 1)
    return len(probe.trace().dirs)


if __name__ == "__main__":
    raise SystemExit(main())
