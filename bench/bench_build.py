"""Build cost of one student file: cold (empty cache: our objects and the
student's file), warm (our objects cached, the student's file new) and
cached (nothing to do). Median of --runs runs each, as wall time and as CPU
time (ours and the compilers', user + system: steady on a loaded machine).

    .venv/bin/python bench/bench_build.py [--runs 5] [--sanitize] [--unsandboxed]
"""
from __future__ import annotations

import argparse
import resource
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from grader.build import build_submission  # noqa: E402

SOURCE = Path(__file__).resolve().parents[1] / "tests" / "submissions" / "correct" / "idiomatic.cpp"


def _cpu() -> float:
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def timed(fn) -> tuple[float, float]:
    start, cpu = time.perf_counter(), _cpu()
    result = fn()
    assert result.ok, result.log
    return time.perf_counter() - start, _cpu() - cpu


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--sanitize", action="store_true")
    parser.add_argument("--unsandboxed", action="store_true",
                        help="compilers run as plain children (no bubblewrap, no uid change), so the CPU "
                             "column counts all of their work (bubblewrap's children are not counted)")
    args = parser.parse_args()
    if args.unsandboxed:
        from grader import build
        from grader.worker import sandbox
        sandbox.sandbox_problem = lambda: "off for the benchmark"
        if hasattr(build, "build_isolation"):
            build.build_isolation = lambda: "none"
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
    for name, runs in (("cold", cold), ("warm", warm), ("cached", cached)):
        wall, cpu = [w for w, _ in runs], [c for _, c in runs]
        print(f"{name:7s} wall median {statistics.median(wall):.3f} s (min {min(wall):.3f})   "
              f"cpu median {statistics.median(cpu):.3f} s (min {min(cpu):.3f})")


if __name__ == "__main__":
    main()
