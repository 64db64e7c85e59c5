"""The study: every method at every face size, accuracy and speed in one run.

One row per (method, face size), written as CSV with a `method` column.
Accuracy columns are <set>_<subset>_<stat>: set uniform | edge | corner,
subset all | smooth (accuracy.py), stat rms | p99 | max. Speed columns are
ns_random and ns_coherent: the same panorama directions timed in scanline
order and shuffled.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import accuracy
from .bake import bake
from .ground_truth import DEFAULT_ENVIRONMENT, AnalyticEnvironment
from .methods import Method
from .timing import ns_per_lookup, time_batch_calls

SIZES = (8, 16, 32, 64, 128, 256, 512)
QUICK_SIZES = (8, 32)
SETS = ("uniform", "edge", "corner")
SUBSETS = ("all", "smooth")
STATS = ("rms", "p99", "max")
ERROR_COLUMNS = [f"{s}_{sub}_{st}" for s in SETS for sub in SUBSETS for st in STATS]
COLUMNS = ["method", "label", "kind", "face_size", "ns_random", "ns_coherent",
           "timing_count", *ERROR_COLUMNS]


@dataclass
class StudyConfig:
    sizes: tuple[int, ...] = SIZES
    n_uniform: int = 200_000
    n_edge: int = 50_000
    n_corner: int = 20_000
    n_timing: int = 1 << 17
    repeats: int = 7
    environment: AnalyticEnvironment = field(default=DEFAULT_ENVIRONMENT)
    cache_dir: Path | None = None      # None: bake.CACHE_DIR

    @classmethod
    def quick(cls, **overrides) -> "StudyConfig":
        values = dict(sizes=QUICK_SIZES, n_uniform=20_000, n_edge=5_000, n_corner=2_000,
                      n_timing=1 << 13, repeats=3)
        values.update(overrides)
        return cls(**values)


def _bake(config: StudyConfig, size: int) -> np.ndarray:
    if config.cache_dir is None:
        return bake(config.environment, size)
    return bake(config.environment, size, cache_dir=config.cache_dir)


def measure_method(method: Method, faces: np.ndarray, sets: dict, timing_dirs: np.ndarray,
                   config: StudyConfig, size: int) -> dict:
    """One CSV row: the method bound to `faces`, its errors on each set and its speed."""
    lookup = method.bind(faces)
    row = {"method": method.name, "label": method.label, "kind": method.kind, "face_size": size}
    for set_name, (dirs, truth, smooth) in sets.items():
        errors = accuracy.per_direction_error(lookup(dirs), truth)
        for subset, mask in (("all", slice(None)), ("smooth", smooth)):
            for stat, value in accuracy.error_stats(errors[mask]).items():
                row[f"{set_name}_{subset}_{stat}"] = value
    count = min(len(timing_dirs), method.max_timing_batch or len(timing_dirs))
    coherent = timing_dirs[:count]
    shuffled = coherent[np.random.default_rng(7).permutation(count)]
    timer = method.timer or time_batch_calls
    row["ns_coherent"] = ns_per_lookup(timer(lookup, coherent, config.repeats), count)
    row["ns_random"] = ns_per_lookup(timer(lookup, shuffled, config.repeats), count)
    row["timing_count"] = count
    return row


def run_study(config: StudyConfig, methods: list[Method], progress=None) -> list[dict]:
    """Rows (dicts with COLUMNS) for every method at every size in config.sizes."""
    env = config.environment
    rows = []
    uniform = accuracy.uniform_directions(config.n_uniform)
    # Coherent timing: a panorama at a fixed count, so sizes compare alike.
    timing_dirs = accuracy.panorama_directions(config.n_timing)
    for size in config.sizes:
        faces = _bake(config, size)
        sets = {}
        for name, dirs in (("uniform", uniform),
                           ("edge", accuracy.edge_directions(config.n_edge, size)),
                           ("corner", accuracy.corner_directions(config.n_corner, size))):
            sets[name] = (dirs, env.radiance(dirs), accuracy.smooth_mask(env, dirs, size))
        for method in methods:
            if progress:
                progress(f"face size {size}: {method.name}")
            rows.append(measure_method(method, faces, sets, timing_dirs, config, size))
    return rows


def write_csv(rows: list[dict], path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})


def read_csv(path: Path) -> list[dict]:
    """Rows as run_study returns them (numbers parsed)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    for row in rows:
        for key in COLUMNS:
            if key in ("method", "label", "kind") or key not in row:
                continue
            row[key] = int(row[key]) if key in ("face_size", "timing_count") else float(row[key])
    return rows

