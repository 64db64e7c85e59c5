"""A correct grading with the record (issue 29) against a commit before it, in one run.

    .venv/bin/python bench/bench_record.py [--against 2455426] [--repeats 5] [--submission PATH]

The commit's tree is unpacked (`git archive`) into a temporary folder, its
reference library built there (`make -s reference`), and both trees grade
the same correct submission (tests/submissions/correct/if_chain.cpp) with
`python -m grader grade`, warm (each tree's build cache and its own bytecode
cache filled by a first, untimed run: where the environment sets
PYTHONDONTWRITEBYTECODE, as this project's machines do, each run would
otherwise compile the grader's source again, a cost an installed grader does
not pay), in turn, --repeats times. Printed per tree: the median wall
time and the median CPU time of the grading process and its children (user
+ system: steadier than the wall clock on a shared machine; counted in a
cpuacct cgroup of its own where the machine has cgroup v1's cpuacct, so that
the workers' and compilers' CPU counts too), the score, and
the ratios this / that. The machine's load average is printed before and
after: quote the figures with it.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SUBMISSION = ROOT / "tests" / "submissions" / "correct" / "if_chain.cpp"


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


CPUACCT = Path("/sys/fs/cgroup/cpuacct")


def _accounting_group() -> Path | None:
    """A cgroup v1 cpuacct group of our own, or None: every process a grading
    starts (workers in their sandboxes, compilers) is charged to it, which
    the grader's rusage misses (a worker is reaped by its sandbox's own init)."""
    group = CPUACCT / f"bench-record-{os.getpid()}"
    try:
        group.mkdir()
        return group
    except OSError:
        return None


def grade(tree: Path, submission: Path, out: Path, group: Path | None) -> tuple[float, float, str]:
    """(wall s, CPU s, score) of one `python -m grader grade` in `tree`; the
    CPU of everything it started where `group` accounts for it."""
    cpu, wall = _children_cpu(), time.perf_counter()
    used = int((group / "cpuacct.usage").read_text()) if group else 0
    env = {**os.environ, "PYTHONPATH": str(tree), "PYTHONPYCACHEPREFIX": str(out.parent / f"pycache-{tree.name}")}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    command = [sys.executable, "-m", "grader", "grade", str(submission), "--out", str(out)]
    if group:
        command = ["/bin/sh", "-c", f'echo $$ > {group}/cgroup.procs && exec "$@"', "sh", *command]
    done = subprocess.run(command, cwd=tree, env=env, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - wall, _children_cpu() - cpu
    if group:
        cpu = (int((group / "cpuacct.usage").read_text()) - used) / 1e9
    results = out / "results.json"
    score = f"{json.loads(results.read_text())['score']:g}" if results.is_file() else f"exit {done.returncode}"
    return wall, cpu, score


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--against", default="2455426")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--submission", type=Path, default=SUBMISSION)
    args = p.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench-record-") as work:
        work = Path(work)
        before = work / "before"
        before.mkdir()
        archive = subprocess.run(["git", "archive", args.against], cwd=ROOT, check=True, capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", str(before)], input=archive, check=True)
        for tree in (ROOT, before):
            subprocess.run(["make", "-s", "reference"], cwd=tree, check=True)
        trees = {"this": ROOT, args.against: before}
        group = _accounting_group()
        print(f"load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; CPU counted "
              + ("in a cpuacct cgroup (workers and compilers included)" if group else
                 "by rusage (the grading process and the children it reaped)"))
        for name, tree in trees.items():     # fills each tree's build cache
            grade(tree, args.submission, work / f"out-{name}", group)
        times = {name: [] for name in trees}
        for _ in range(args.repeats):
            for name, tree in trees.items():
                times[name].append(grade(tree, args.submission, work / f"out-{name}", group))
        print(f"load average after: {os.getloadavg()[0]:.2f}")
        medians = {}
        for name, runs in times.items():
            wall = statistics.median(r[0] for r in runs)
            cpu = statistics.median(r[1] for r in runs)
            medians[name] = (wall, cpu)
            print(f"{name:>10}: wall {wall:6.2f} s, CPU {cpu:6.2f} s, scores {sorted({r[2] for r in runs})}")
        (w1, c1), (w0, c0) = medians["this"], medians[args.against]
        print(f"ratio this / {args.against}: wall {w1 / w0:.2f}, CPU {c1 / c0:.2f}")
        if group:
            group.rmdir()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
