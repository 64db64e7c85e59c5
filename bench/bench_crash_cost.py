"""What a crash costs: worker starts and wall time of grading a crash-heavy
submission against a correct one, as ratios measured in the same run.

    .venv/bin/python bench/bench_crash_cost.py [--rounds 3] [--quick]

Submissions (tests/submissions/): correct/idiomatic.cpp; wrong/out-of-bounds-x1.cpp
(x1 and y1 not clamped: it faults at the last row and column of a face, the
issue 19 case that scored 41 against 99); wrong/crash-null.cpp. Each is
graded `--rounds` times, rounds interleaved so drift hits all alike; the
report gives each one's median wall time, its worker starts (the same every
round: the search is deterministic) and its score, and the ratio of each
crash-heavy one to the correct one. Before issue 19's change every fault
cost a worker start and narrowing down; now the worker goes on past it.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from grader.grading.grade import GradeOptions, grade  # noqa: E402
from grader.worker import process  # noqa: E402

SUBMISSIONS = ROOT / "tests" / "submissions"
CASES = {"correct": SUBMISSIONS / "correct" / "idiomatic.cpp",
         "out-of-bounds-x1": SUBMISSIONS / "wrong" / "out-of-bounds-x1.cpp",
         "crash-null": SUBMISSIONS / "wrong" / "crash-null.cpp"}


def count_starts():
    """Worker.start, counted."""
    counter = [0]
    original = process.Worker.start

    def start(self):
        counter[0] += 1
        return original(self)

    process.Worker.start = start
    return counter


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="the test suite's smaller direction sets")
    args = parser.parse_args()
    starts = count_starts()
    walls = {name: [] for name in CASES}
    seen: dict[str, tuple[int, float]] = {}
    for _ in range(args.rounds):
        for name, path in CASES.items():
            with tempfile.TemporaryDirectory() as out:
                before, began = starts[0], time.perf_counter()
                result = grade(path, Path(out), GradeOptions(quick=args.quick, allow_stale=True))
                walls[name].append(time.perf_counter() - began)
                seen[name] = (starts[0] - before, result.score)
    base_wall, base_starts = statistics.median(walls["correct"]), seen["correct"][0]
    print(f"{'submission':18} {'score':>7} {'starts':>7} {'wall s':>8} {'starts/correct':>15} {'wall/correct':>13}")
    for name in CASES:
        wall, (n, score) = statistics.median(walls[name]), seen[name]
        print(f"{name:18} {score:7.2f} {n:7d} {wall:8.2f} {n / base_starts:15.2f} {wall / base_wall:13.2f}")


if __name__ == "__main__":
    main()
