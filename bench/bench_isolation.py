"""The cost of isolation on a correct submission, all measured in one run.

    .venv/bin/python bench/bench_isolation.py [--rounds 7] [--lookups 200000]

Three parts, each a ratio against the way it was done before, medians:
  1. lookups through each isolation mode (bubblewrap, privilege-drop, plain)
     against the in-process reference, and worker start-up per mode;
  2. the speed check's timing: before, TIME_FETCH timed sub_fetch_batch inside
     the worker (REPEATS passes over one fixed batch, the worker's own clock);
     now, each pass has fresh directions and is timed by the kernel's CPU
     accounting from outside, with the colours sent back, plus a pass of the
     null library for the protocol's cost. Reported: the grader's wall time
     per round, old and new, and the ns per lookup each way gives;
  3. privilege-drop against plain (the old fallback) and bubblewrap.

Workload: a correct C++ solution (tests/submissions/correct/axis_table.cpp,
built by grader/build/__init__.py) looks up a fixed set of random directions in a
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
from grader.envmap.library import CubeMap  # noqa: E402
from grader.worker import Worker, privilege_drop_problem, sandbox_problem  # noqa: E402
from grader.worker.native import null_library  # noqa: E402

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
    drop = privilege_drop_problem()
    modes = ["plain"] + (["sandbox"] if problem is None else []) + (["privilege-drop"] if drop is None else [])
    if problem:
        print(f"bubblewrap unavailable: {problem}")
    if drop:
        print(f"privilege-drop unavailable: {drop}")

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
    timing = compare_timing(workers[modes[-1] if "sandbox" not in modes else "sandbox"], faces, args.rounds)
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
    for mode in modes[1:]:
        ratio = statistics.median(times[f"{mode} worker"]) / statistics.median(times["plain worker"])
        print(f"{mode} / plain lookup time: {ratio:.2f}; start-up {mode} / plain: "
              f"{statistics.median(starts[mode]) / statistics.median(starts['plain']):.2f}")
    if "sandbox" in modes and "privilege-drop" in modes:
        print(f"privilege-drop / bubblewrap lookup time: "
              f"{statistics.median(times['privilege-drop worker']) / statistics.median(times['sandbox worker']):.2f}; "
              f"start-up: {statistics.median(starts['privilege-drop']) / statistics.median(starts['sandbox']):.2f}")
    print()
    print(timing)
    return 0


SPEED_LOOKUPS, SPEED_REPEATS = 50_000, 2   # grader/checks/speed.py's pass size; the old REPEATS


def compare_timing(worker: Worker, faces: np.ndarray, rounds: int) -> str:
    """One speed-check round the old way and the new way, in the same mode:
    the submission (`worker`, the correct one) and the reference library,
    plus (new) the null library and freezing the submission's worker."""
    from grader.checks.speed import baseline_library
    rng = np.random.default_rng(7)
    fixed = rng.normal(size=(SPEED_LOOKUPS, 3))
    old_wall, new_wall, old_ns, new_ns, raw_ns = [], [], [], [], []
    with Worker(null_library(), sandbox=worker.mode) as null, \
            Worker(baseline_library(), sandbox=worker.mode) as ref:
        null.set_faces(faces)
        ref.set_faces(faces)
        for _ in range(rounds):
            began = time.perf_counter()
            ns = worker.time_fetch(fixed, repeats=SPEED_REPEATS)
            ref.time_fetch(fixed, repeats=SPEED_REPEATS)
            old_wall.append(time.perf_counter() - began)
            old_ns.append(ns)
            dirs = rng.normal(size=(SPEED_LOOKUPS, 3))
            began = time.perf_counter()
            _, used = worker.fetch_timed(dirs)
            worker.freeze()
            ref.fetch_timed(dirs)
            ref.fetch_timed(dirs)
            _, overhead = null.fetch_timed(dirs)
            worker.thaw()
            new_wall.append(time.perf_counter() - began)
            raw_ns.append(used / SPEED_LOOKUPS)
            new_ns.append((used - overhead) / SPEED_LOOKUPS)
    old, new = statistics.median(old_wall), statistics.median(new_wall)
    return (f"speed timing ({worker.isolation}, {SPEED_LOOKUPS} lookups per pass, median of {rounds} rounds):\n"
            f"  old round (TIME_FETCH x{SPEED_REPEATS} inside the worker, submission and reference): "
            f"{old * 1e3:.1f} ms; submission {statistics.median(old_ns):.1f} ns/lookup\n"
            f"  new round (fresh directions, kernel CPU time from outside, colours back; submission, reference "
            f"twice, null library, submission frozen meanwhile): {new * 1e3:.1f} ms; submission "
            f"{statistics.median(new_ns):.1f} ns/lookup ({statistics.median(raw_ns):.1f} before taking off the "
            f"protocol's cost)\n"
            f"  new / old wall time per round: {new / old:.2f} (the check does 5 rounds, up to 15 near the limit)")


if __name__ == "__main__":
    sys.exit(main())
