"""A class graded quiet and under load, against a baseline in the same run.

    .venv/bin/python bench/bench_class.py [--size 100] [--jobs 2] [--load 4] [--baseline COMMIT]
                                          [--mode bubblewrap|privilege-drop|both] [--repeats 1]

The class is bench_grading.py's mix (60% correct, the common mistakes, two
crashes, two build errors, one slow solution), each file with a comment that
makes it new to the build cache, as a real class is. It is graded with
`python -m grader grade-all --jobs J`:

  quiet     as the machine is
  load L    beside L busy loops (`python3 -c 'while 1: pass'`), ended after

With --baseline, the same classes are graded by that commit too (exported
with `git archive` into a temporary folder sharing this .venv, its own
`make reference` and build cache), alternately with this checkout, so the
machine's other work loads both alike. Printed: wall and CPU time (user +
system of grade-all and everything it started), loaded / quiet, and now /
baseline. Every run is also checked: a correct submission (tests/submissions/
correct*) must get full marks, and no submission of the mix may be graded
`timeout` or `ungradable` (the slow one is slow, not hanging). --mode
privilege-drop puts a failing bwrap first on PATH (tests/helpers/fake_bwrap.py), as
on Gradescope and PrairieLearn. Exit status 1 when any check failed.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "tests"))
PYTHON = ROOT / ".venv" / "bin" / "python"
BUSY = "while 1: pass"


@contextmanager
def busy_loops(n: int):
    """n processes that spin until the block ends (each ended by its own pid)."""
    loops = [subprocess.Popen([sys.executable, "-c", BUSY]) for _ in range(n)]
    try:
        time.sleep(0.5 if n else 0)
        yield
    finally:
        for p in loops:
            p.kill()
        for p in loops:
            p.wait()


def grade_class(tree: Path, folder: Path, out: Path, jobs: int, env: dict) -> tuple[float, float]:
    """(wall, cpu) seconds of one grade-all in `tree`."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run([str(PYTHON), "-m", "grader", "grade-all", str(folder), "--out", str(out),
                           "--jobs", str(jobs), "--no-progress"], cwd=tree, env=env,
                          stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(f"grade-all failed in {tree} (exit {done.returncode}):\n{done.stderr[-3000:]}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def problems(out: Path, kinds: dict[str, str]) -> list[str]:
    """What is wrong with a graded class: a correct submission short of full
    marks, any submission timed out or ungradable, a missing report."""
    found = []
    for student, kind in kinds.items():
        try:
            results = json.loads((out / student / "results.json").read_text())
        except (OSError, ValueError) as e:
            found.append(f"{student} ({kind}): no results.json ({e})")
            continue
        extra = results.get("extra_data", {})
        status = extra.get("status", "graded")
        if status in ("timeout", "ungradable"):
            found.append(f"{student} ({kind}): graded {status}")
        if kind.startswith("correct") and results["score"] < extra.get("max_score", 100.0):
            lost = [t["name"] for t in results["tests"] if t.get("score", 0) < t.get("max_score", 0)]
            found.append(f"{student} ({kind}): {results['score']:g} / {extra.get('max_score')} (lost: {lost})")
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=100)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--load", type=int, default=4, help="busy loops beside the loaded run (0: no loaded run)")
    parser.add_argument("--baseline", default=None, help="a commit to measure in the same run")
    parser.add_argument("--mode", choices=("bubblewrap", "privilege-drop", "both"), default="bubblewrap")
    parser.add_argument("--repeats", type=int, default=1)
    args = parser.parse_args()

    from bench_compare import export
    from bench_grading import CLASS_MIX, make_class
    from fake_bwrap import write_failing_bwrap
    # Correct solutions from both folders of them (bench_grading's mix has correct/ only).
    mix_note = ", ".join(f"{k} x{v}" for k, v in CLASS_MIX.items() if k.startswith("correct"))

    work = Path(tempfile.mkdtemp(prefix="bench-class-"))
    failed = False
    try:
        subprocess.run(["make", "-s", "reference"], cwd=ROOT, check=True, capture_output=True)
        trees = {"now": ROOT}
        if args.baseline:
            trees["baseline"] = export(args.baseline, work)
        modes = ("bubblewrap", "privilege-drop") if args.mode == "both" else (args.mode,)
        envs = {"bubblewrap": dict(os.environ)}
        if "privilege-drop" in modes:
            fake = write_failing_bwrap(work / "fake-bwrap")
            envs["privilege-drop"] = {**os.environ, "PATH": f"{fake}:{os.environ.get('PATH', '')}"}
        loads = (0, args.load) if args.load else (0,)
        print(f"class of {args.size} ({mix_note}, the rest wrong), grade-all --jobs {args.jobs}; "
              f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} before")
        figures: dict[tuple, list[tuple[float, float]]] = {}
        for i in range(args.repeats):
            for mode in modes:
                for load in loads:
                    for name, tree in trees.items():
                        folder = work / f"class-{i}-{mode}-{load}-{name}"
                        kinds = make_class(folder, args.size, with_hang=False)
                        out = work / f"out-{i}-{mode}-{load}-{name}"
                        with busy_loops(load):
                            la = os.getloadavg()[0]
                            wall, cpu = grade_class(tree, folder, out, args.jobs, envs[mode])
                        figures.setdefault((mode, load, name), []).append((wall, cpu))
                        bad = problems(out, kinds)
                        failed |= bool(bad)
                        print(f"  {name:8s} {mode:14s} load {load}: {wall:6.1f} s wall, {cpu:6.1f} s CPU "
                              f"(load average {la:.1f} at start)" + (f"  PROBLEMS: {len(bad)}" if bad else ""))
                        for line in bad:
                            print(f"      {line}")
                        shutil.rmtree(out, ignore_errors=True)
                        shutil.rmtree(folder, ignore_errors=True)

        def med(key, k):
            values = sorted(v[k] for v in figures[key])
            return values[len(values) // 2]

        print("\nmedians:")
        for mode in modes:
            for name in trees:
                quiet = med((mode, 0, name), 0)
                line = f"  {name:8s} {mode:14s} quiet {quiet:6.1f} s"
                if args.load:
                    loaded = med((mode, args.load, name), 0)
                    line += f", load {args.load} {loaded:6.1f} s (loaded / quiet {loaded / quiet:.2f})"
                print(line)
            if "baseline" in trees:
                for load in loads:
                    w = med((mode, load, "now"), 0) / med((mode, load, "baseline"), 0)
                    c = med((mode, load, "now"), 1) / med((mode, load, "baseline"), 1)
                    print(f"  now / baseline, {mode}, load {load}: wall {w:.2f}, CPU {c:.2f}")
        print(f"load average after: {os.getloadavg()[0]:.1f}")
        print("every correct submission full marks, nothing timeout or ungradable" if not failed
              else "PROBLEMS above")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
