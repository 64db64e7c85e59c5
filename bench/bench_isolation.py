"""The cost of isolation on a correct submission, all measured in one run.

    .venv/bin/python bench/bench_isolation.py [--rounds 7] [--lookups 200000]

Workload: a correct C++ solution (tests/submissions/correct/axis_table.cpp,
built by grader/build.py) looks up a fixed set of random directions in a
64x64-per-face cube map, in batches of 10000, through
  - a worker in the bubblewrap sandbox (seccomp filter, limits, guard pages),
  - a plain worker (the same, without bubblewrap),
  - the reference library in-process (no isolation at all: the baseline).
Rounds interleave the three so drift hits all alike; the report gives the
median wall time of each and its ratio to the baseline, the median time to
start a worker (spawn, load the submission, set the faces) in each mode, and
the ns per lookup measured inside the worker (TIME_FETCH).
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
from grader.reference import CubeMap  # noqa: E402
from grader.worker import Worker, sandbox_problem  # noqa: E402

BATCH = 10_000


def timed(fn) -> float:
    began = time.perf_counter()
    fn()
    return time.perf_counter() - began


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--lookups", type=int, default=200_000)
    parser.add_argument("--starts", type=int, default=10)
    args = parser.parse_args()

    built = build_submission(ROOT / "tests" / "submissions" / "correct" / "axis_table.cpp")
    if not built.ok:
        print(built.log)
        return 1
    rng = np.random.default_rng(2024)
    faces = rng.random((6, 64, 64, 3), dtype=np.float32)
    dirs = rng.normal(size=(args.lookups, 3))
    batches = [dirs[i:i + BATCH] for i in range(0, len(dirs), BATCH)]
    cube = CubeMap(faces)
    expected = cube.fetch(dirs)

    problem = sandbox_problem()
    modes = ["plain"] + (["sandbox"] if problem is None else [])
    if problem:
        print(f"sandbox unavailable: {problem}; measuring the plain worker only")

    workers = {}
    for mode in modes:
        workers[mode] = Worker(built.library, sandbox=mode)
        workers[mode].start()
        workers[mode].set_faces(faces)
        got = np.concatenate([workers[mode].fetch(b, timeout_s=60) for b in batches])
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)

    times: dict[str, list[float]] = {"in-process reference": [], **{f"{m} worker": [] for m in modes}}
    for _ in range(args.rounds):
        times["in-process reference"].append(timed(lambda: [cube.fetch(b) for b in batches]))
        for mode in modes:
            times[f"{mode} worker"].append(timed(lambda: [workers[mode].fetch(b, timeout_s=60) for b in batches]))
    inside = {m: workers[m].time_fetch(dirs[:BATCH], repeats=args.rounds) for m in modes}
    for worker in workers.values():
        worker.close()

    starts: dict[str, list[float]] = {m: [] for m in modes}
    for _ in range(args.starts):
        for mode in modes:
            def start_and_stop():
                with Worker(built.library, sandbox=mode) as w:
                    w.set_faces(faces)
            starts[mode].append(timed(start_and_stop))

    base = statistics.median(times["in-process reference"])
    print(f"{args.lookups} lookups in batches of {BATCH}, 64x64 faces, median of {args.rounds} rounds")
    print(f"{'':24s} {'median s':>10s} {'ns/lookup':>10s} {'x reference':>12s}")
    for name, values in times.items():
        med = statistics.median(values)
        print(f"{name:24s} {med:10.4f} {med / args.lookups * 1e9:10.1f} {med / base:12.2f}")
    print()
    for mode in modes:
        print(f"{mode} worker: start + load + set faces, median of {args.starts}: "
              f"{statistics.median(starts[mode]) * 1e3:.1f} ms; "
              f"inside the worker {inside[mode]:.1f} ns/lookup (TIME_FETCH)")
    if "sandbox" in modes:
        ratio = statistics.median(times["sandbox worker"]) / statistics.median(times["plain worker"])
        print(f"sandbox / plain lookup time: {ratio:.2f}; start-up sandbox / plain: "
              f"{statistics.median(starts['sandbox']) / statistics.median(starts['plain']):.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
