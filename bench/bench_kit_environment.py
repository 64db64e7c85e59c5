"""The student kit's first use and later runs, measured (issue 20's figures):
how long selfcheck/bootstrap.py takes to make its environment from nothing
(pip's cache off, the network as this machine has it), how big the
environment is on disk, and what the bootstrap adds to a later run.

    .venv/bin/python bench/bench_kit_environment.py [--runs 3] [--kit build/student-kit] [--python python3]

With --kit, a copy of that built kit is measured (its own self-check runs,
with no arguments, after the install). Without it, a folder laid out like
the kit is made from this checkout (selfcheck/bootstrap.py, the
requirements from grader.kit.environment, a copy of grader/ and the
reference header) with a stand-in self-check that only imports what the
grader's kit-side code imports; it is written into the temporary folder,
never into the project.

Prints the median of each figure; the machine is shared, so quote the
bootstrap's overhead as a difference measured in the same run.
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

STAND_IN = '''"""Stand-in self-check (bench/bench_kit_environment.py): the imports only."""
import os, sys, time
if os.environ.get("BENCH_EMPTY"):
    sys.exit(0)
start = time.monotonic()
import numpy, cffi, OpenImageIO, flip_evaluator, markdown_it, rich.console, rich.table, rich.panel
import grader.grading.grade, grader.checks, grader.reports, grader.reports.terminal
from grader.checks.instruments import image_metrics, face_map
print("imports %.2f s" % (time.monotonic() - start))
'''


def layout(dest: Path, kit: Path | None) -> None:
    if kit is not None:
        from grader import in_build_output
        shutil.copytree(kit, dest, ignore=lambda folder, names: {n for n in names if n == "build" and in_build_output(
            (*Path(folder).parts[-1:], n, "x"))})
        return
    from grader.kit.environment import write_requirements
    selfcheck = dest / "selfcheck"
    selfcheck.mkdir(parents=True)
    shutil.copy(ROOT / "student_template" / "selfcheck" / "bootstrap.py", selfcheck)
    write_requirements(selfcheck)
    shutil.copytree(ROOT / "grader", selfcheck / "grader", ignore=shutil.ignore_patterns("__pycache__"))
    (selfcheck / "reference" / "include").mkdir(parents=True)
    shutil.copy(ROOT / "reference" / "include" / "envmap.h", selfcheck / "reference" / "include")
    (selfcheck / "grader" / "kit" / "selfcheck.py").write_text(STAND_IN)


def disk_usage(folder: Path) -> int:
    """Bytes on disk, as du counts them (files and folders, links as links)."""
    total = folder.lstat().st_blocks * 512
    for path in folder.rglob("*"):
        total += path.lstat().st_blocks * 512
    return total


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--warm-runs", type=int, default=7)
    parser.add_argument("--kit", type=Path, help="a built kit (make student-kit) instead of a laid-out copy")
    parser.add_argument("--python", default="python3", help="the interpreter `make selfcheck` would run "
                        "(a pyenv shim adds its own start-up to every run)")
    args = parser.parse_args()
    python = shutil.which(args.python) or args.python
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONDONTWRITEBYTECODE")}
    env["PIP_NO_CACHE_DIR"] = "1"
    first, sizes, last = [], [], None
    for _ in range(args.runs):
        folder = Path(tempfile.mkdtemp(prefix="bench-kit-env-"))
        layout(folder / "kit", args.kit)
        start = time.monotonic()
        done = subprocess.run([python, "selfcheck/bootstrap.py"], cwd=folder / "kit", env=env, capture_output=True,
                              text=True)
        first.append(time.monotonic() - start)
        print(done.stdout.strip().splitlines()[0] if done.stdout.strip() else done.stderr[-500:])
        sizes.append(disk_usage(folder / "kit" / "build" / "selfcheck-env"))
        if last is not None:
            shutil.rmtree(last)
        last = folder
    print(f"first use (install, then one self-check run): median {statistics.median(first):.1f} s of "
          f"{', '.join(f'{t:.1f}' for t in first)}; environment {statistics.median(sizes) / 1e6:.1f} MB on disk")
    kit, quiet = last / "kit", {**env, "BENCH_EMPTY": "1"}
    envpy = str(kit / "build" / "selfcheck-env" / "bin" / "python")
    through, direct = [], []
    for _ in range(args.warm_runs):
        start = time.monotonic()
        subprocess.run([python, "selfcheck/bootstrap.py"], cwd=kit, env=quiet, capture_output=True)
        middle = time.monotonic()
        subprocess.run([envpy, "-m", "grader.kit.selfcheck"], cwd=kit, env={**quiet, "PYTHONPATH": "selfcheck"},
                       capture_output=True)
        direct.append(time.monotonic() - middle)
        through.append(middle - start)
    print(f"later runs: through the bootstrap median {statistics.median(through):.3f} s, the environment's python "
          f"alone {statistics.median(direct):.3f} s: the bootstrap adds "
          f"{statistics.median(through) - statistics.median(direct):.3f} s ({python})")
    shutil.rmtree(last)
    return 0


if __name__ == "__main__":
    sys.exit(main())
