"""What issue 18's confinement costs a worker start, as ratios in one run.

    .venv/bin/python bench/bench_worker_start.py [--rounds 30]

A worker is started, given 64 x 64 faces and asked one lookup, then closed,
`--rounds` times per variant, variants interleaved so drift hits all alike:
  - privilege-drop with its own pid namespace and uid (the default as root),
  - privilege-drop with its uid only (Worker.try_pid_namespace = False),
  - bubblewrap (as root: a uid of its own, bwrap without a user namespace),
  - plain (no isolation: the floor).
Reported: the median milliseconds of each and its ratio to plain.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from grader.build import build_submission  # noqa: E402
from grader.worker import Worker, privilege_drop_problem, sandbox_problem  # noqa: E402

FACES = np.random.default_rng(0).random((6, 64, 64, 3), dtype=np.float32)


def one_start(library: Path, mode: str, namespace: bool) -> float:
    Worker.try_pid_namespace = namespace
    began = time.perf_counter()
    with Worker(library, sandbox=mode, texture_shape=(64, 64)) as worker:
        worker.set_faces(FACES)
        worker.fetch([[0.3, 0.2, -1.0]])
    return time.perf_counter() - began


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=30)
    args = parser.parse_args()
    library = build_submission(ROOT / "tests" / "submissions" / "correct" / "axis_table.cpp").library
    variants = {"plain": ("plain", True)}
    if privilege_drop_problem() is None:
        variants["privilege-drop, own pid namespace"] = ("privilege-drop", True)
        variants["privilege-drop, uid only"] = ("privilege-drop", False)
    if sandbox_problem() is None:
        variants["bubblewrap"] = ("sandbox", True)
    times = {name: [] for name in variants}
    for _ in range(args.rounds):
        for name, (mode, namespace) in variants.items():
            times[name].append(one_start(library, mode, namespace))
    floor = statistics.median(times["plain"])
    for name, got in times.items():
        median = statistics.median(got)
        print(f"{name:34} {1e3 * median:7.1f} ms  {median / floor:5.2f} x plain")


if __name__ == "__main__":
    main()
