"""autograder.zip for Gradescope, which grades each submission in its own
container: setup.sh installs what the grader needs, run_autograder grades
/autograder/submission into /autograder/results.

The zip holds the project's own files (grader, reference, template, maps,
fixtures, requirements), never a student's work or build outputs.
"""
from __future__ import annotations

import stat
import zipfile
from pathlib import Path

from . import PROJECT_ROOT

INCLUDE = ("grader", "reference", "student_template", "Cubemap", "fixtures", "scenes",
           "envmap_test.cfg", "requirements.txt", "packages.txt", "Makefile", "scripts")
EXCLUDE_PARTS = {"__pycache__", ".venv", "build", "out"}
FIXED_TIME = (2020, 1, 1, 0, 0, 0)   # byte-identical zips from identical trees

SETUP_SH = """#!/usr/bin/env bash
# Gradescope runs this once when it builds the autograder image.
set -euo pipefail
cd /autograder/source
apt-get update -qq
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \\
    python3 python3-venv python3-pip g++ gcc make bubblewrap >/dev/null
python3 -m venv .venv
.venv/bin/pip install --quiet -r requirements.txt
make reference
"""

RUN_AUTOGRADER = """#!/usr/bin/env bash
# Gradescope runs this for every submission. AUTOGRADER_ROOT lets tests
# lay out the same tree elsewhere.
set -uo pipefail
root="${AUTOGRADER_ROOT:-/autograder}"
cd "$root/source"
mkdir -p "$root/results"
.venv/bin/python -m grader grade "$root/submission" --out "$root/results" --student-view "$@"
status=$?
# results.json is written even when grading fails; make sure Gradescope sees one.
if [ ! -s "$root/results/results.json" ]; then
  echo '{"score": 0, "output": "The autograder failed before it could write results; please tell your instructor.", "tests": []}' > "$root/results/results.json"
fi
exit 0
"""


def _files():
    for name in INCLUDE:
        path = PROJECT_ROOT / name
        if path.is_file():
            yield path
        elif path.is_dir():
            for f in sorted(path.rglob("*")):
                if f.is_file() and not (EXCLUDE_PARTS & set(f.relative_to(PROJECT_ROOT).parts)):
                    yield f


def _add(z: zipfile.ZipFile, arcname: str, data: bytes, executable: bool = False) -> None:
    info = zipfile.ZipInfo(arcname, FIXED_TIME)
    info.external_attr = ((0o755 if executable else 0o644) | stat.S_IFREG) << 16
    info.compress_type = zipfile.ZIP_DEFLATED
    z.writestr(info, data)


def build_bundle(out: Path) -> Path:
    """Write autograder.zip: setup.sh and run_autograder at the top, the
    project under source/ (Gradescope unpacks the zip into /autograder/source,
    so the top-level scripts land there and the project beside them)."""
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".tmp")
    with zipfile.ZipFile(tmp, "w") as z:
        _add(z, "setup.sh", SETUP_SH.encode(), executable=True)
        _add(z, "run_autograder", RUN_AUTOGRADER.encode(), executable=True)
        for f in _files():
            rel = f.relative_to(PROJECT_ROOT).as_posix()
            _add(z, rel, f.read_bytes(), executable=bool(f.stat().st_mode & 0o111))
    tmp.replace(out)
    return out
