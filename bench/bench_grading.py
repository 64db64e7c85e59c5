"""How long grading takes, and where the time goes.

    .venv/bin/python bench/bench_grading.py [--repeats 5] [--class-size 100] [--jobs 2] [--no-class]

1. One correct submission (tests/submissions/correct/if_chain.cpp) graded
   with `python -m grader grade`, wall time of the whole command (Python
   start-up and imports included), median of the repeats:
     cold    a fresh build cache: our objects and the student's file compiled
     new     our objects cached, the student's file new (a comment changed):
             what each new submission of a class costs
     warm    everything cached (the same file again)
   The build cache is pointed at a temporary folder for these runs.
2. Where one warm and one new grading spend their time (in-process, median
   of the repeats): the build, the worker's start, each check
   (CheckResult.duration_s), the reports.
3. A class of --class-size generated submissions (copies of correct and
   wrong solutions, each with a comment that makes its hash unique) graded
   with `python -m grader grade-all --jobs N`: wall time, and the time per
   check summed over the class (from each student's .grade.json), the
   slowest submissions. These builds go to the project's build cache
   (build/submissions/, ~50 KB each; `make clean` empties it).

   crash   a submission that crashes on every -Z direction (wrong/crash-null.cpp),
           built, to its verdict
   hang    one that spins forever on directions along the x axis
           (wrong/timeout-loop.cpp), built, to its verdict

Goals on a 2-core machine (issue 13): warm <= 1.5 s, cold < 6 s, crash and
hang <= 5 s, 100 submissions with --jobs 2 <= 100 s.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import uuid
from collections import defaultdict
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

SUBMISSIONS = ROOT / "tests" / "submissions"
CORRECT = SUBMISSIONS / "correct" / "if_chain.cpp"
GOALS = {"warm": 1.5, "cold": 6.0, "crash": 5.0, "hang": 5.0, "class_of_100": 100.0}
CRASH = SUBMISSIONS / "wrong" / "crash-null.cpp"
HANG = SUBMISSIONS / "wrong" / "timeout-loop.cpp"
# The class: mostly correct, the common mistakes, a few crashes and build
# errors, one slow solution (weights: how many of every 100). The hanging
# solution (wrong/timeout-loop.cpp) is left out unless --with-hang.
CLASS_MIX = {
    **{f"correct/{p.name}": 10 for p in sorted((SUBMISSIONS / "correct").glob("*.cpp"))},
    "wrong/nearest-neighbor.cpp": 6, "wrong/v-flipped-pos-z.cpp": 4, "wrong/u-flipped-pos-x.cpp": 4,
    "wrong/uv-swapped-neg-y.cpp": 3, "wrong/wrong-face-x-swapped.cpp": 3, "wrong/half-texel-offset.cpp": 3,
    "wrong/weights-swapped.cpp": 3, "wrong/not-normalized-length.cpp": 3, "wrong/combo-swapped-and-flipped.cpp": 2,
    "wrong/nan-huge.cpp": 2, "wrong/out-of-bounds-x1.cpp": 2, "wrong/crash-null.cpp": 2,
    "wrong/syntax-error.cpp": 2, "wrong/slow.cpp": 1,
}

# A `python -m grader` with the build cache moved (grade() has no option for it).
CLI_WITH_CACHE = ("import sys; from pathlib import Path; import grader.build.common as b; "
                  "b.DEFAULT_CACHE = Path(sys.argv[1]); from grader.cli import main; "
                  "raise SystemExit(main(sys.argv[2:]))")


def cli_seconds(cache: Path, submission: Path, out: Path) -> float:
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", CLI_WITH_CACHE, str(cache), "grade", str(submission), "--out", str(out)],
                   cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def with_comment(source: Path, folder: Path, tag: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "EnvironmentMap.cpp"
    path.write_bytes(f"// {tag}\n".encode() + source.read_bytes())
    return path


def single(repeats: int, work: Path) -> dict[str, list[float]]:
    times = defaultdict(list)
    for i in range(repeats):
        cache = work / f"cache-{i}"
        times["cold"].append(cli_seconds(cache, with_comment(CORRECT, work / f"cold-{i}", uuid.uuid4().hex),
                                         work / "out"))
        times["new"].append(cli_seconds(cache, with_comment(CORRECT, work / f"new-{i}", uuid.uuid4().hex),
                                        work / "out"))
        times["warm"].append(cli_seconds(cache, work / f"new-{i}", work / "out"))
        for kind, source in (("crash", CRASH), ("hang", HANG)):
            if i == 0:      # built once: what is timed is grading to the verdict
                cli_seconds(cache, source, work / "out")
            times[kind].append(cli_seconds(cache, source, work / "out"))
    return times


@contextmanager
def _timed(module, name: str, into: dict, label: str):
    """Wrap module.name (a function or a context-manager factory) to add its time to into[label]."""
    original = getattr(module, name)

    def wrapper(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return original(*args, **kwargs)
        finally:
            into[label] = into.get(label, 0.0) + time.perf_counter() - t0

    setattr(module, name, wrapper)
    try:
        yield
    finally:
        setattr(module, name, original)


def breakdown(repeats: int, work: Path) -> dict[str, dict[str, list[float]]]:
    """In-process phases of a warm and a new grading."""
    import grader.build.common as build_common
    import grader.reports as reports
    from grader.grading.grade import grade
    cache = work / "cache-breakdown"
    build_common.DEFAULT_CACHE = cache
    result: dict[str, dict[str, list[float]]] = {"new": defaultdict(list), "warm": defaultdict(list)}

    for i in range(repeats + 1):
        source = with_comment(CORRECT, work / f"breakdown-{i}", uuid.uuid4().hex)
        for kind in ("new", "warm"):
            phases: dict[str, float] = {}

            with _timed(build, "build_submission", phases, "build"), \
                    _timed(reports, "write_all", phases, "reports"):
                t0 = time.perf_counter()
                graded = grade(source, work / "out-breakdown")
                total = time.perf_counter() - t0
            if graded.score != graded.max_score:   # e.g. the speed check on a loaded machine
                print(f"  note: {CORRECT.name} scored {graded.score:g} / {graded.max_score:g} in one run")
            if i == 0:
                continue   # the first round pays for imports and the common objects
            for check in graded.checks:
                phases[f"check {check.name}"] = check.duration_s
            phases["total"] = total
            for k, v in phases.items():
                result[kind][k].append(v)
    return result


def make_class(folder: Path, size: int, with_hang: bool) -> dict[str, str]:
    mix = dict(CLASS_MIX)
    if with_hang:
        mix["wrong/timeout-loop.cpp"] = 1
    pool = [name for name, weight in mix.items() for _ in range(weight)]
    nonce = uuid.uuid4().hex[:8]
    kinds = {}
    for i in range(size):
        name = pool[i * len(pool) // size]
        student = f"student{i:03d}"
        with_comment(SUBMISSIONS / name, folder / student, f"{student} {nonce}")
        kinds[student] = name
    return kinds


def class_run(size: int, jobs: int, work: Path, with_hang: bool) -> dict:
    folder, out = work / "class", work / "class-out"
    kinds = make_class(folder, size, with_hang)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "grader", "grade-all", str(folder), "--out", str(out),
                    "--jobs", str(jobs), "--no-progress"], cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    per_check, per_student = defaultdict(float), {}
    for student in kinds:
        record = json.loads((out / student / ".grade.json").read_text())
        results = json.loads((out / student / "results.json").read_text())
        for name, seconds in record["check_seconds"].items():
            per_check[name] += seconds
        per_student[student] = (results["execution_time"], kinds[student], results["extra_data"]["status"])
    return {"wall": wall, "per_check": dict(per_check), "per_student": per_student, "out": out}


def median(values) -> float:
    return statistics.median(values) if values else float("nan")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--class-size", type=int, default=100)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--no-class", action="store_true", help="skip the class of submissions")
    parser.add_argument("--with-hang", action="store_true", help="add one hanging submission to the class")
    parser.add_argument("--keep", action="store_true", help="keep the work folder (printed)")
    args = parser.parse_args()

    subprocess.run(["make", "-s", "reference"], cwd=ROOT, check=True)
    print(f"load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores "
          "(other work on the machine inflates every figure)")
    work = Path(tempfile.mkdtemp(prefix="bench-grading-"))
    try:
        print(f"one correct submission ({CORRECT.name}), `python -m grader grade`, median of {args.repeats}:")
        times = single(args.repeats, work)
        for kind, label in (("cold", "cold (fresh build cache)"), ("new", "new source, our objects cached"),
                            ("warm", "warm (everything cached)"), ("crash", f"crash ({CRASH.name}, built)"),
                            ("hang", f"hang ({HANG.name}, built)")):
            goal = GOALS.get(kind)
            verdict = "" if goal is None else f"   goal <= {goal:g} s: {'met' if median(times[kind]) <= goal else 'MISSED'}"
            spread = f"[{min(times[kind]):.2f} .. {max(times[kind]):.2f}]"
            print(f"  {label:32s} {median(times[kind]):6.2f} s  {spread}{verdict}")

        print(f"\nwhere one grading spends its time (in-process, median of {args.repeats}):")
        phases = breakdown(args.repeats, work)
        keys = list(dict.fromkeys(k for kind in phases.values() for k in kind))
        keys = ["build"] + sorted(k for k in keys if k.startswith("check ")) + ["reports", "total"]
        print(f"  {'':24s} {'new source':>10s} {'warm':>10s}")
        for k in keys:
            print(f"  {k:24s} {median(phases['new'][k]):9.3f}s {median(phases['warm'][k]):9.3f}s")
        accounted = ("build", "reports") + tuple(k for k in keys if k.startswith("check "))
        rest = median([t - sum(phases["warm"][k][i] for k in accounted)
                       for i, t in enumerate(phases["warm"]["total"])])
        print(f"  {'other (worker start and stop, rubric, fixtures check)'} {rest:.3f}s warm")

        if not args.no_class:
            print(f"\na class of {args.class_size} generated submissions, grade-all --jobs {args.jobs}:")
            c = class_run(args.class_size, args.jobs, work, args.with_hang)
            goal = GOALS["class_of_100"] * args.class_size / 100
            print(f"  wall time {c['wall']:.1f} s ({c['wall'] / args.class_size:.2f} s per submission)"
                  f"   goal < {goal:g} s: {'met' if c['wall'] < goal else 'MISSED'}")
            total = sum(c["per_check"].values())
            print(f"  time in checks, summed over the class: {total:.1f} s")
            for name, seconds in sorted(c["per_check"].items(), key=lambda kv: -kv[1]):
                print(f"    {name:14s} {seconds:7.1f} s  {100 * seconds / total:5.1f}%")
            by_kind = defaultdict(list)
            for seconds, kind, _ in c["per_student"].values():
                by_kind[kind].append(seconds)
            print("  grading time by kind of submission (median s, count, sum s):")
            for kind, values in sorted(by_kind.items(), key=lambda kv: -sum(kv[1])):
                print(f"    {kind:40s} {median(values):6.2f} {len(values):4d} {sum(values):7.1f}")
        print(f"\nload average after: {os.getloadavg()[0]:.2f}")
    finally:
        if args.keep:
            print(f"\nwork folder kept: {work}")
        else:
            shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
