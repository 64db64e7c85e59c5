"""Build cost of one student file: cold (empty cache: our objects and the
student's file), warm (our objects cached, the student's file new) and
cached (nothing to do). Median of --runs runs each.

    .venv/bin/python bench/bench_build.py [--runs 5] [--sanitize]
"""
from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from grader.build import build_submission  # noqa: E402

SOURCE = Path(__file__).resolve().parents[1] / "tests" / "submissions" / "correct" / "idiomatic.cpp"


def timed(fn) -> float:
    start = time.perf_counter()
    result = fn()
    assert result.ok, result.log
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--sanitize", action="store_true")
    args = parser.parse_args()
    text = SOURCE.read_text()
    cold, warm, cached = [], [], []
    for run in range(args.runs):
        with tempfile.TemporaryDirectory() as tmp:
            cache = Path(tmp) / "cache"
            src = Path(tmp) / "EnvironmentMap.cpp"
            src.write_text(text + f"\n// run {run} a\n")
            cold.append(timed(lambda: build_submission(src, cache_dir=cache, sanitize=args.sanitize)))
            src.write_text(text + f"\n// run {run} b\n")
            warm.append(timed(lambda: build_submission(src, cache_dir=cache, sanitize=args.sanitize)))
            cached.append(timed(lambda: build_submission(src, cache_dir=cache, sanitize=args.sanitize)))
    for name, values in (("cold", cold), ("warm", warm), ("cached", cached)):
        print(f"{name:7s} median {statistics.median(values):.3f} s  (min {min(values):.3f}, max {max(values):.3f})")


if __name__ == "__main__":
    main()
