"""Grading speed now against a baseline commit, in the same run.

    .venv/bin/python bench/bench_compare.py [--baseline c56cd4e] [--now HEAD] [--repeats 5] [--class-size 0]

"Now" is this checkout as it is, or with --now COMMIT that commit (exported
too: a shared checkout with work in progress does not disturb it). The
baseline is exported (`git archive`, nothing in this checkout changes)
into a temporary folder that shares this project's .venv/, and gets its own
`make reference` and build cache. Then the same commands run in both trees,
alternately, so that whatever else loads the machine loads both alike:

  start-up    `python -m grader grade --help`: interpreter, CLI and the grade command's imports
  warm        `python -m grader grade` of a correct submission, everything cached
  crash       a submission that dereferences NULL in fetchColor, to its verdict
  hang        a submission that loops forever in fetchColor, to its verdict
  class       (--class-size N) `grade-all --jobs J` on N copies of the bench's class mix

Each figure is the median wall time, with the CPU time (user + system of
the command and its children), which other load inflates much less, and the
ratio now / baseline. The load average is printed: on a busy machine the
ratios are the figures to quote.
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SUBMISSIONS = ROOT / "tests" / "submissions"
CASES = {
    "start-up": ["grade", "--help"],
    "warm": ["grade", str(SUBMISSIONS / "correct" / "if_chain.cpp")],
    "crash": ["grade", str(SUBMISSIONS / "wrong" / "crash-null.cpp")],
    "hang": ["grade", str(SUBMISSIONS / "wrong" / "timeout-loop.cpp")],
}


def export(commit: str, into: Path) -> Path:
    tree = into / f"tree-{commit}"
    tree.mkdir(parents=True)
    archive = subprocess.run(["git", "archive", "--format=tar", commit], cwd=ROOT, check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(tree)], input=archive, check=True)
    (tree / ".venv").symlink_to(ROOT / ".venv")
    subprocess.run(["make", "-s", "reference"], cwd=tree, check=True, capture_output=True)
    return tree


def timed(tree: Path, args: list[str], out: Path) -> tuple[float, float]:
    """(wall, cpu) seconds of one `python -m grader ...` in `tree`."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    extra = ["--out", str(out)] if args[0] == "grade" and "--help" not in args else []
    subprocess.run([str(ROOT / ".venv" / "bin" / "python"), "-m", "grader", *args, *extra], cwd=tree,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def class_folder(folder: Path, size: int) -> None:
    sys.path.insert(0, str(ROOT / "bench"))
    from bench_grading import make_class
    make_class(folder, size, with_hang=False)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--baseline", default="c56cd4e", help="commit to compare with (default: c56cd4e)")
    parser.add_argument("--now", default=None, help="a commit to measure instead of this checkout")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--cases", default="start-up,warm,crash,hang")
    parser.add_argument("--class-size", type=int, default=0, help="also grade a class of N (0: no)")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="bench-compare-"))
    try:
        subprocess.run(["make", "-s", "reference"], cwd=ROOT, check=True, capture_output=True)
        trees = {"now": export(args.now, work) if args.now else ROOT, "baseline": export(args.baseline, work)}
        print(f"baseline {args.baseline} in {trees['baseline']}; load average {os.getloadavg()[0]:.1f} "
              f"on {os.cpu_count()} cores")
        cases = [c for c in args.cases.split(",") if c]
        for name, tree in trees.items():       # warm the build caches
            timed(tree, CASES["warm"], work / f"warmup-{name}")
        figures = {(c, t): [] for c in cases for t in trees}
        for i in range(args.repeats):
            for case in cases:
                for name, tree in trees.items():
                    figures[case, name].append(timed(tree, CASES[case], work / f"{case}-{name}-{i}"))
        print(f"{'':10s} {'now wall':>9s} {'cpu':>7s}   {'baseline':>9s} {'cpu':>7s}   now/baseline wall, cpu")
        for case in cases:
            now = [statistics.median(x) for x in zip(*figures[case, "now"])]
            base = [statistics.median(x) for x in zip(*figures[case, "baseline"])]
            print(f"{case:10s} {now[0]:8.2f}s {now[1]:6.2f}s   {base[0]:8.2f}s {base[1]:6.2f}s   "
                  f"{now[0] / base[0]:.2f}, {now[1] / base[1]:.2f}")
        if args.class_size:
            for name, tree in trees.items():
                folder = work / f"class-{name}"
                class_folder(folder, args.class_size)
                t0 = time.perf_counter()
                subprocess.run([str(ROOT / ".venv" / "bin" / "python"), "-m", "grader", "grade-all", str(folder),
                                "--out", str(work / f"class-out-{name}"), "--jobs", str(args.jobs), "--no-progress"],
                               cwd=tree, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
                print(f"class of {args.class_size}, --jobs {args.jobs}, {name}: {time.perf_counter() - t0:.1f} s")
        print(f"load average after: {os.getloadavg()[0]:.1f}")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
