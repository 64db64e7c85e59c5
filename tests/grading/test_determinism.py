"""The same submission graded twice, in two processes that hash strings
differently (PYTHONHASHSEED), gets the same score and the same report text,
times aside: nothing in a verdict may hang on set or dict order, on the
process, or on the clock."""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys

import pytest

from project_paths import PROJECT_ROOT, SUBMISSIONS

# What may differ between two gradings: times (s, ms, ns, the speed ratio),
# the fields that hold them, and the speed check's measurements in
# report.html's metrics tables (times, and how many rounds it took).
TIMES = re.compile(r"\d+(?:\.\d+)?\s*(?:ns|ms|s|x)\b|\d+(?:\.\d+)?\s*倍|time=\"[\d.]+\"|\"execution_time\": [\d.]+"
                   r"|<tr><td>[^<]*(?:per lookup|time relative|rounds)[^<]*</td><td>[^<]*</td></tr>")


def graded(source, out, seed: str) -> dict[str, str]:
    done = subprocess.run([sys.executable, "-m", "grader", "grade", "--quick", str(source), "--out", str(out)],
                          cwd=PROJECT_ROOT, env={**os.environ, "PYTHONHASHSEED": seed},
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    return {name: (out / name).read_text() for name in ("report.md", "report.html", "results.json", "junit.xml")}


@pytest.mark.parametrize("name", ["wrong/v-flipped-pos-z", "compound/float-args_wh-swapped"])
def test_two_processes_grade_alike(tmp_path, name):
    source = SUBMISSIONS / f"{name}.cpp"
    first, second = graded(source, tmp_path / "a", "1"), graded(source, tmp_path / "b", "4242")
    assert json.loads(first["results.json"])["score"] == json.loads(second["results.json"])["score"]
    for report in first:
        assert TIMES.sub("", first[report]) == TIMES.sub("", second[report]), report
    # The reports said something worth comparing: a diagnosis, not only a score.
    assert json.loads(first["results.json"])["score"] < 100 and "What to fix" in first["report.md"]
