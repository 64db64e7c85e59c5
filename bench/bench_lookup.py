"""Speed of the reference batch lookup (em_fetch_batch) against the numpy model.

    .venv/bin/python bench/bench_lookup.py [--map FILE_cross.hdr] [--repeats 5]

Looks up 1e6 random directions and the 1e6 directions of a 1024x1024 camera
image (image order, so neighbouring lookups hit neighbouring texels) with the
nearest, bilinear and seamless filters, and the same directions with the
vectorised numpy model of tests/helpers/assignment_model.py (nearest and bilinear;
it has no seamless), all in this run on one core. Prints the median lookups
per second of the repeats and the ratio C / numpy. The C figure is
em_fetch_batch itself, into an output buffer allocated once.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

import assignment_model as model  # noqa: E402
from grader.envmap.library import FILTERS as FILTER_CODES, CubeMap, library  # noqa: E402

# A real probe when ../shared/probes is beside the checkout (it is not in the
# repository), else the project's own sky.
DEFAULT_MAP = next((p for p in (ROOT.parent / "shared" / "probes" / "stpeters_cross.hdr",
                                ROOT / "Cubemap" / "sky_cross.hdr") if p.exists()), ROOT / "Cubemap" / "sky_cross.hdr")
FILTERS = ("nearest", "bilinear", "seamless")


def random_directions(n: int, seed: int = 1) -> np.ndarray:
    """Uniform on the sphere: normalised Gaussian vectors."""
    dirs = np.random.default_rng(seed).normal(size=(n, 3))
    return dirs / np.linalg.norm(dirs, axis=1, keepdims=True)


def camera_directions(side: int = 1024, fov_degrees: float = 100.0) -> np.ndarray:
    """The primary rays of a pinhole camera, top row first, looking between
    the -Z, +X and +Y faces so that the image crosses face edges."""
    forward = np.array([0.6, 0.3, -1.0])
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    half = np.tan(np.radians(fov_degrees) / 2)
    t = (np.arange(side) + 0.5) / side * 2 - 1
    x, y = np.meshgrid(t * half, -t * half)
    return (forward + x[..., None] * right + y[..., None] * up).reshape(-1, 3)


def batch_lookup(cube: CubeMap, dirs: np.ndarray, filter: str):
    """em_fetch_batch over dirs into a buffer allocated once, as a renderer
    calls it: the batch API alone, without the binding's allocations."""
    ffi, lib = library()
    rgb = np.empty_like(dirs)
    dirs_buffer, rgb_buffer = ffi.from_buffer(dirs), ffi.from_buffer(rgb)  # kept alive by the closure
    code = FILTER_CODES[filter]

    def run():
        lib.em_fetch_batch(cube.c, code, ffi.cast("double *", dirs_buffer), len(dirs),
                           ffi.cast("double *", rgb_buffer), ffi.NULL)
    return run


def median_seconds(runs: dict, repeats: int) -> dict:
    """Median wall time of each callable; the callables take turns, repeat
    after repeat, so that a load that comes and goes hits them alike."""
    times = {name: [] for name in runs}
    for _ in range(repeats):
        for name, run in runs.items():
            start = time.perf_counter()
            run()
            times[name].append(time.perf_counter() - start)
    return {name: statistics.median(t) for name, t in times.items()}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", type=Path, default=DEFAULT_MAP, help="a vertical-cross .hdr")
    parser.add_argument("--repeats", type=int, default=5, help="repeats of each measurement")
    args = parser.parse_args()

    cube = CubeMap.load_cross(args.map)
    sets = {"random": random_directions(1_000_000), "coherent": np.ascontiguousarray(camera_directions())}
    print(f"map {args.map.name}: faces {cube.face_width}x{cube.face_height}; "
          f"median of {args.repeats} repeats, C and numpy taking turns; one core")
    print(f"{'directions':<10} {'filter':<9} {'C Mlookup/s':>12} {'numpy Mlookup/s':>16} {'C / numpy':>10}")
    for set_name, dirs in sets.items():
        for filter in FILTERS:
            runs = {"C": batch_lookup(cube, dirs, filter)}
            if filter in model.FILTERS:
                runs["numpy"] = lambda: model.fetch(cube.faces, dirs, filter)
            seconds = median_seconds(runs, args.repeats)
            line = f"{set_name:<10} {filter:<9} {len(dirs) / seconds['C'] / 1e6:>12.1f}"
            if "numpy" in seconds:
                line += f" {len(dirs) / seconds['numpy'] / 1e6:>16.2f} {seconds['numpy'] / seconds['C']:>10.1f}"
            else:
                line += f" {'(no model)':>16} {'':>10}"
            print(line, flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
