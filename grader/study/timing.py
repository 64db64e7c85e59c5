"""Nanoseconds per lookup: a batch call timed whole, median of repeats.

The median (not the minimum) because the study runs beside other work on
shared machines; the batch is large enough that per-call overhead (cffi,
allocating the output) is a small share of it.
"""
from __future__ import annotations

import time
from typing import Callable

import numpy as np


def time_batch_calls(lookup: Callable[[np.ndarray], np.ndarray], dirs: np.ndarray,
                     repeats: int) -> list[float]:
    """Seconds per call of lookup(dirs), one entry per repeat (after one warm-up)."""
    lookup(dirs[: min(len(dirs), 1024)])
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        lookup(dirs)
        times.append(time.perf_counter() - start)
    return times


def ns_per_lookup(seconds: list[float], count: int) -> float:
    return float(np.median(seconds)) / count * 1e9
