"""Build cost of one student file: cold (empty cache: our objects and the
student's file), warm (our objects cached, the student's file new) and
cached (nothing to do). Median of --runs runs each, as wall time and as CPU
time (ours and the compilers', user + system: steady on a loaded machine).

    .venv/bin/python bench/bench_build.py [--runs 5] [--sanitize] [--unsandboxed] [--against REV]

--against REV (e.g. main) also times the build of that commit (its tree
from `git archive`), run by run in turn with this one in the same run, and
prints the ratios this / REV: the cost of the steps added since (the -E
pass and the token policy, the privilege-drop probe).
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import statistics
import sys
import tempfile
import time
from pathlib import Path

_TREE = Path(os.environ.get("BENCH_BUILD_TREE") or Path(__file__).resolve().parents[1])
sys.path.insert(0, str(_TREE))
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


def measure(runs: int, sanitize: bool, unsandboxed: bool) -> dict[str, list[tuple[float, float]]]:
    if unsandboxed:
        from grader import build
        from grader.worker import sandbox
        sandbox.sandbox_problem = lambda: "off for the benchmark"
        if hasattr(build, "build_isolation"):
            build.build_isolation = lambda: "none"
    text = SOURCE.read_text()
    cold, warm, cached = [], [], []
    for run in range(runs):
        with tempfile.TemporaryDirectory() as tmp:
            cache = Path(tmp) / "cache"
            src = Path(tmp) / "EnvironmentMap.cpp"
            src.write_text(text + f"\n// run {run} a {time.time_ns()}\n")
            cold.append(timed(lambda: build_submission(src, cache_dir=cache, sanitize=sanitize)))
            src.write_text(text + f"\n// run {run} b {time.time_ns()}\n")
            warm.append(timed(lambda: build_submission(src, cache_dir=cache, sanitize=sanitize)))
            cached.append(timed(lambda: build_submission(src, cache_dir=cache, sanitize=sanitize)))
    return {"cold": cold, "warm": warm, "cached": cached}


def _one_run(tree: Path, args) -> dict:
    cmd = [sys.executable, __file__, "--runs", "1", "--json"] + (["--sanitize"] if args.sanitize else []) \
        + (["--unsandboxed"] if args.unsandboxed else [])
    done = subprocess.run(cmd, env={**os.environ, "BENCH_BUILD_TREE": str(tree)}, capture_output=True,
                          text=True, check=True)
    return json.loads(done.stdout)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--sanitize", action="store_true")
    parser.add_argument("--unsandboxed", action="store_true",
                        help="compilers run as plain children (no bubblewrap, no uid change), so the CPU "
                             "column counts all of their work (bubblewrap's children are not counted)")
    parser.add_argument("--against", metavar="REV", help="also time commit REV, in turn, and print ratios")
    parser.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.json:
        print(json.dumps(measure(args.runs, args.sanitize, args.unsandboxed)))
        return
    if not args.against:
        results = measure(args.runs, args.sanitize, args.unsandboxed)
        for name, runs in results.items():
            wall, cpu = [w for w, _ in runs], [c for _, c in runs]
            print(f"{name:7s} wall median {statistics.median(wall):.3f} s (min {min(wall):.3f})   "
                  f"cpu median {statistics.median(cpu):.3f} s (min {min(cpu):.3f})")
        return
    here = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as tmp:
        other = Path(tmp) / "tree"
        other.mkdir()
        archive = subprocess.run(["git", "-C", str(here), "archive", args.against], capture_output=True, check=True)
        subprocess.run(["tar", "-x", "-C", str(other)], input=archive.stdout, check=True)
        mine: dict[str, list] = {}
        theirs: dict[str, list] = {}
        for _ in range(args.runs):   # in turn, so both see the same machine
            for tree, into in ((here, mine), (other, theirs)):
                for name, runs in _one_run(tree, args).items():
                    into.setdefault(name, []).extend(runs)
    print(f"this tree / {args.against}, medians of {args.runs} runs each, taken in turn:")
    for name in mine:
        for column, i in (("wall", 0), ("cpu", 1)):
            a = statistics.median(r[i] for r in mine[name])
            b = statistics.median(r[i] for r in theirs[name])
            print(f"{name:7s} {column}: {a:.3f} s / {b:.3f} s = {a / b:.2f}x")


if __name__ == "__main__":
    main()
