"""What issue 29's additions cost a correct grading (quick), in one run:
the checks stability, arrows and renders with each addition on and off,
interleaved, median per check (CheckResult.duration_s).

    PYTHONPATH=. .venv/bin/python bench/bench_two_sizes.py [--repeats 3]

on       faces set after a first call on larger faces (context.set_faces_after_another_size)
         and stability's same directions at lengths a power of two apart
off      neither
warm     only the first call on larger faces
length   only the lengths
"""
from __future__ import annotations

import argparse
import statistics
import tempfile
from pathlib import Path

from grader.checks import arrows, context, renders, stability
from grader.grading.grade import GradeOptions, grade

SUBMISSION = Path(__file__).resolve().parents[1] / "tests" / "submissions" / "correct" / "if_chain.cpp"
CHECKS = ("stability", "arrows", "renders")


def _plain(lookups, faces):
    lookups.set_faces(faces)


VARIANTS = {"on": (context.set_faces_after_another_size, stability.length_dependence),
            "off": (_plain, lambda *a: None),
            "warm": (context.set_faces_after_another_size, lambda *a: None),
            "length": (_plain, stability.length_dependence)}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    times = {name: [] for name in VARIANTS}
    for _ in range(args.repeats):
        for name, (set_faces, lengths) in VARIANTS.items():
            for module in (stability, arrows, renders):
                module.set_faces_after_another_size = set_faces
            stability.length_dependence = lengths
            with tempfile.TemporaryDirectory() as out:
                result = grade(SUBMISSION, Path(out), GradeOptions(quick=True, only=CHECKS), write_reports=False)
            times[name].append({c.name: c.duration_s for c in result.checks})
    for name, runs in times.items():
        print(f"{name:7s}", "  ".join(f"{c} {statistics.median(r[c] for r in runs):.3f} s" for c in CHECKS))


if __name__ == "__main__":
    main()
