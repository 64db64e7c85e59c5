"""Grading does not depend on what else the machine does (issue 21): the
zoo's correct submissions, graded while more busy processes than cores run
(and two gradings at a time, as the suite's xdist workers do), each get full
marks: half of them in bubblewrap, half in privilege-drop mode."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from grader.worker import sandbox
from fake_bwrap import write_failing_bwrap
from project_paths import SUBMISSIONS

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]

CORRECT = sorted((SUBMISSIONS / "correct").glob("*.cpp"))
BUSY = [sys.executable, "-c", "import time\nend = time.monotonic() + 900\nwhile time.monotonic() < end: pass"]
LOAD = 8      # busy processes, on a 2-core machine: load 4 to 5 and more
MODES = [pytest.param("bubblewrap", marks=pytest.mark.skipif(sandbox.sandbox_problem() is not None,
                                                            reason="no bubblewrap here")),
         pytest.param("privilege-drop", marks=pytest.mark.skipif(sandbox.privilege_drop_problem() is not None,
                                                                reason="no privilege drop here"))]


def grade_two_at_a_time(paths: list[Path], out: Path, env: dict) -> dict[str, dict]:
    results = {}
    for pair in (paths[i:i + 2] for i in range(0, len(paths), 2)):
        runs = [(p, subprocess.Popen([sys.executable, "-m", "grader", "grade", str(p), "--quick", "--allow-stale",
                                      "--out", str(out / p.stem)], env=env, stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True)) for p in pair]
        for p, run in runs:
            printed = run.communicate(timeout=900)[0]
            results[p.stem] = json.loads((out / p.stem / "results.json").read_text())
            results[p.stem]["printed"] = printed
    return results


@pytest.mark.parametrize("mode", MODES)
def test_correct_submissions_get_full_marks_on_a_loaded_machine(mode, tmp_path):
    env = dict(os.environ)
    if mode == "privilege-drop":
        fake = write_failing_bwrap(tmp_path / "fakebin")
        env["PATH"] = f"{fake}:{env['PATH']}"
    busy = [subprocess.Popen(BUSY) for _ in range(LOAD)]
    try:
        # Each correct submission once, half in each mode: the load slows the
        # rest of the suite too, so it is kept short.
        results = grade_two_at_a_time(CORRECT[0::2] if mode == "bubblewrap" else CORRECT[1::2], tmp_path, env)
        assert all(p.poll() is None for p in busy)       # the load lasted the whole grading
    finally:
        for p in busy:
            p.kill()
            p.wait()
    short = {name: (r["score"], [t["name"][:40] + ": " + t.get("output", "")[:200] for t in r["tests"]
                                 if t["score"] < t["max_score"]])
             for name, r in results.items() if r["score"] < sum(t["max_score"] for t in r["tests"])}
    assert not short, short
