"""A cold PrairieLearn job: the time from the entry point's start to
/grade/results/results.json, in a fresh copy of /grade as docs/platforms.md
lays it out (serverFilesCourse/envmap holding the files the course
repository holds: no build/, no .venv), the image's environment standing in
for the container's. A container's own start (docker run) is not counted:
no Docker daemon runs here. Wall time and CPU time (the entry point's
children: user + system, steadier on a loaded machine), median of --runs.

    .venv/bin/python bench/bench_prairielearn_cold.py [--runs 3] [--submission FILE] [--quick] [--against REV]

--against REV (e.g. main) also runs that commit's tree (`git archive`, as the
course repository would hold it), run by run in turn with this one, and
prints the ratio of the medians this / REV.
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
sys.path.insert(0, str(ROOT))
from grader.platforms.gradescope import _files  # noqa: E402  (what a course repository holds)

ENTRYPOINT = Path("grader/platforms/prairielearn/entrypoint.sh")


def fresh_grade_root(base: Path, submission: Path, rev: str | None = None) -> Path:
    root = base / "grade"
    course = root / "serverFilesCourse" / "envmap"
    if rev is None:
        for f in _files():
            target = course / f.relative_to(ROOT)
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(f, target)
    else:
        course.mkdir(parents=True)
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev], capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(course)], input=archive, check=True)
    (root / "student").mkdir()
    shutil.copy(submission, root / "student" / "EnvironmentMap.cpp")
    return root


def one_job(submission: Path, args: list[str], rev: str | None = None) -> tuple[float, float, str]:
    with tempfile.TemporaryDirectory(prefix="pl-cold-") as tmp:
        root = fresh_grade_root(Path(tmp), submission, rev)
        env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
        env.update(PL_GRADE_ROOT=str(root), ENVMAP_VENV=str((ROOT / ".venv").resolve()))
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        job = subprocess.run([str(root / "serverFilesCourse" / "envmap" / ENTRYPOINT), *args], cwd="/", env=env,
                             capture_output=True, text=True, timeout=900)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        assert (root / "results" / "results.json").is_file(), job.stderr[-2000:]
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        return wall, cpu, job.stderr


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--submission", type=Path, default=ROOT / "tests" / "submissions" / "correct" / "idiomatic.cpp")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--against", metavar="REV")
    args = parser.parse_args()
    trees = [None] + ([args.against] if args.against else [])
    walls, cpus = {t: [] for t in trees}, {t: [] for t in trees}
    for run in range(args.runs):
        for tree in trees:
            wall, cpu, log = one_job(args.submission, ["--quick"] if args.quick else [], tree)
            walls[tree].append(wall)
            cpus[tree].append(cpu)
            print(f"run {run + 1} ({tree or 'this tree'}): {wall:.1f} s wall, {cpu:.1f} s CPU; "
                  f"job log: {log.strip().splitlines()[-1]}", flush=True)
    for tree in trees:
        print(f"{tree or 'this tree'}: median of {args.runs}: {statistics.median(walls[tree]):.1f} s wall, "
              f"{statistics.median(cpus[tree]):.1f} s CPU")
    if args.against:
        print(f"this / {args.against}: {statistics.median(walls[None]) / statistics.median(walls[args.against]):.2f} "
              f"wall, {statistics.median(cpus[None]) / statistics.median(cpus[args.against]):.2f} CPU "
              f"(load average {os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main()
