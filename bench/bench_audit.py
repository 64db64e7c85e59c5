"""How long the audit takes (`python -m grader audit`), and where the time goes.

    .venv/bin/python bench/bench_audit.py [--mutants 300] [--jobs 2] [--seed 0] [--quick] [--out DIR]

Runs the audit once on the course's correct solutions and prints its wall
time per phase (enumerating, judging: build + truth, grading through
grade-all), the median and slowest truth per mutant, the median grading per
mutant (each one's check time, from its .grade.json), the machine's load
average before and after (on a shared machine the figures are only as good
as the load lets them be: quote them with it), and the audit's own figures.
The mutants' builds go to the project's build cache (build/submissions/).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--mutants", type=int, default=300)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--quick", action="store_true")
    p.add_argument("--out", type=Path)
    args = p.parse_args()
    from grader.course.audit import run_audit
    from grader.course.audit.report import summarise, terminal_text
    out = args.out or Path(tempfile.mkdtemp(prefix="bench-audit-"))
    load_before = os.getloadavg()
    began = time.monotonic()
    result = run_audit(mutants=args.mutants, seed=args.seed, jobs=args.jobs, out=out, quick=args.quick,
                       progress=False)
    wall = time.monotonic() - began
    load_after = os.getloadavg()
    data = summarise(result)
    truth = [a.truth.seconds for a in result.mutants]
    grading = []
    for a in result.mutants:
        record = out / "graded" / a.name / ".grade.json"
        if record.is_file():
            grading.append(sum(json.loads(record.read_text()).get("check_seconds", {}).values()))
    print(terminal_text(data))
    print(f"\nwall {wall:.0f} s for {len(result.mutants)} mutants and {len(result.controls)} controls, "
          f"--jobs {args.jobs}, {os.cpu_count()} cores; phases: "
          + ", ".join(f"{k} {v:.0f} s" for k, v in result.seconds.items()))
    print(f"truth per mutant (build + judge, one core): median {statistics.median(truth):.2f} s, "
          f"slowest {max(truth):.1f} s")
    if grading:
        print(f"grading per mutant (its checks, one core): median {statistics.median(grading):.2f} s, "
              f"slowest {max(grading):.1f} s")
    print(f"load average (1, 5, 15 min) before {tuple(round(x, 1) for x in load_before)}, "
          f"after {tuple(round(x, 1) for x in load_after)}")
    print(f"results: {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
