"""The speed check's ratio for correct code, quiet and under load.

Correct submissions are about as fast as the reference (ratio near 1); the
limit is 8x. Each run grades the speed check alone (and what it needs) for
one correct submission while LOAD busy processes run, and prints the median
and the largest ratio over the runs: the margin a loaded machine leaves.

    .venv/bin/python bench/bench_speed_load.py [--runs 5] [--load 0 8]
"""
from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

BUSY = [sys.executable, "-c", "import time\nend = time.monotonic() + 900\nwhile time.monotonic() < end: pass"]


def ratios(submission: Path, runs: int, load: int) -> list[float]:
    from grader.grading.grade import GradeOptions, grade
    busy = [subprocess.Popen(BUSY) for _ in range(load)]
    found = []
    try:
        for _ in range(runs):
            with tempfile.TemporaryDirectory() as out:
                result = grade(submission, Path(out), GradeOptions(quick=True, only=("speed",)), write_reports=False)
                speed = next(c for c in result.checks if c.name == "speed")
                found.append(float(speed.metrics.get("speed_ratio", float("nan"))))
    finally:
        for p in busy:
            p.kill()
            p.wait()
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--load", type=int, nargs="+", default=[0, 8])
    parser.add_argument("--submission", type=Path, default=ROOT / "tests" / "submissions" / "correct" / "if_chain.cpp")
    args = parser.parse_args()
    for load in args.load:
        found = ratios(args.submission, args.runs, load)
        print(f"load {load}: speed ratio median {statistics.median(found):.2f}x, largest {max(found):.2f}x "
              f"over {len(found)} runs ({', '.join(f'{r:.2f}' for r in found)}); limit 8x")


if __name__ == "__main__":
    main()
