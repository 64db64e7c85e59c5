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

from .. import PROJECT_ROOT, in_build_output

INCLUDE = ("grader", "reference", "student_template", "Cubemap", "fixtures", "scenes",
           "envmap_test.cfg", "requirements.txt", "requirements.lock", "packages.txt", "Makefile", "scripts")
# Build outputs, caches, a student's local self-check, CI files: never shipped.
EXCLUDE_PARTS = {"__pycache__", ".venv", "out", "selfcheck", ".github", ".pytest_cache", "fuzz"}   # and build outputs
FIXED_TIME = (2020, 1, 1, 0, 0, 0)   # byte-identical zips from identical trees

SETUP_SH = """#!/usr/bin/env bash
# Gradescope runs this once when it builds the autograder image (as root).
# scripts/install-grading-env.sh installs what grading needs the way `make
# venv` does on an instructor's machine (the core packages of packages.txt,
# Python 3.11 or later, exactly the versions of requirements.lock); it is
# the same script PrairieLearn's image runs.
set -euo pipefail
cd /autograder/source
bash scripts/install-grading-env.sh .venv
make reference
# Fail here, when the image is built, rather than on every submission.
.venv/bin/python -m grader fixtures --check
# Grade the untouched template once: every submission's container starts
# from this image, so what this builds and caches (our objects, the worker,
# the study's bake) is not redone per submission. Exit 3 (the grader
# failed) stops the image build.
.venv/bin/python -m grader grade student_template --out /tmp/warm-up >/dev/null
rm -rf /tmp/warm-up
"""

RUN_AUTOGRADER = """#!/usr/bin/env bash
# Gradescope runs this for every submission. AUTOGRADER_ROOT lets tests
# lay out the same tree elsewhere.
set -uo pipefail
root="${AUTOGRADER_ROOT:-/autograder}"
cd "$root/source"
mkdir -p "$root/results"
# The exit status is not Gradescope's business: results.json carries the grade.
# `gradescope --grade` is `grade --student-view` plus the leaderboard, when
# the rubric turns it on ([gradescope] leaderboard).
.venv/bin/python -m grader gradescope --grade "$root/submission" --results "$root/results" "$@"
# grade writes results.json whatever the submission does; if the grader
# itself could not start, Gradescope still gets a file that says so.
if [ ! -s "$root/results/results.json" ]; then
  cat > "$root/results/results.json" <<'JSON'
{"score": 0, "execution_time": 0, "output_format": "md",
 "output": "The autograder failed before it could grade your submission. This is not your fault: please tell your instructor.",
 "tests": [],
 "extra_data": {"status": "ungradable", "warnings": ["run_autograder: the grader did not write results.json"], "diagnoses": []}}
JSON
fi
exit 0
"""


# ---- the leaderboard ----------------------------------------------------------------

# Gradescope's leaderboard: each submission's speed and accuracy, the two
# axes of the speed-against-accuracy chart, both "lower is better".
LEADERBOARD = (("ns_per_lookup", "Speed (ns per lookup)"),
               ("uniform_smooth_rms", "Accuracy (RMS error on the study's map)"))


def leaderboard_enabled(rubric: dict) -> bool:
    """[gradescope] leaderboard = true in the rubric (off by default)."""
    section = rubric.get("gradescope") or {}
    return isinstance(section, dict) and section.get("leaderboard") is True


def leaderboard(result) -> list[dict]:
    """The entries for results.json, or [] when the speed check did not
    measure the submission (it did not build, crashed or is wrong): such a
    submission is not on the board."""
    import math
    found: dict[str, float] = {}
    for check in result.checks:
        for metric, _ in LEADERBOARD:
            value = check.metrics.get(metric)
            if metric not in found and isinstance(value, (int, float)) and math.isfinite(value) and value > 0:
                found[metric] = float(value)
    if len(found) < len(LEADERBOARD):
        return []
    return [{"name": name, "value": round(found[metric], 6), "order": "asc"} for metric, name in LEADERBOARD]


def add_leaderboard(results_json: Path, entries: list[dict]) -> None:
    """Put the entries into results.json (Gradescope reads a top-level "leaderboard")."""
    import json
    import os
    data = json.loads(results_json.read_text())
    data["leaderboard"] = entries
    tmp = results_json.with_name(".results.json.tmp")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    os.replace(tmp, results_json)


def _files():
    for name in INCLUDE:
        path = PROJECT_ROOT / name
        if path.is_file():
            yield path
        elif path.is_dir():
            for f in sorted(path.rglob("*")):
                parts = f.relative_to(PROJECT_ROOT).parts
                if f.is_file() and not (EXCLUDE_PARTS & set(parts)) and not in_build_output(parts):
                    yield f


def _add(z: zipfile.ZipFile, arcname: str, data: bytes, executable: bool = False) -> None:
    info = zipfile.ZipInfo(arcname, FIXED_TIME)
    info.external_attr = ((0o755 if executable else 0o644) | stat.S_IFREG) << 16
    info.compress_type = zipfile.ZIP_DEFLATED
    z.writestr(info, data)


DEFAULT_SECRET = "change-me-per-course"   # grader/grading/rubric.toml as shipped
RUBRIC = "grader/grading/rubric.toml"


def course_secret_problem() -> str | None:
    """Why the bundle's course secret is unsafe, or None. The shipped rubric's
    secret is public: with it, a submission that knows its own hash can work
    out the speed check's timed directions (docs/security.md)."""
    import os
    import tomllib
    if os.environ.get("GRADER_SECRET"):
        return None
    secret = tomllib.loads((PROJECT_ROOT / RUBRIC).read_text()).get("grading", {}).get("secret", "")
    if secret in ("", DEFAULT_SECRET):
        return ("the course secret is the public default: set GRADER_SECRET (it is written into the "
                "bundle's rubric) or [grading] secret in grader/grading/rubric.toml before uploading")
    return None


def _with_secret(rubric_text: str, secret: str) -> str:
    """The rubric with its [grading] secret replaced (as a TOML basic string)."""
    import json
    import re
    line = f"secret = {json.dumps(secret)}"
    replaced, n = re.subn(r"^secret\s*=.*$", lambda _: line, rubric_text, count=1, flags=re.M)
    if n != 1:
        raise ValueError(f"{RUBRIC} has no [grading] secret line to replace")
    return replaced


def build_bundle(out: Path) -> Path:
    """Write autograder.zip: setup.sh and run_autograder at the top, the
    project under source/ (Gradescope unpacks the zip into /autograder/source,
    so the top-level scripts land there and the project beside them).
    GRADER_SECRET, when set, becomes the bundled rubric's course secret."""
    import os
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".tmp")
    with zipfile.ZipFile(tmp, "w") as z:
        _add(z, "setup.sh", SETUP_SH.encode(), executable=True)
        _add(z, "run_autograder", RUN_AUTOGRADER.encode(), executable=True)
        for f in _files():
            rel = f.relative_to(PROJECT_ROOT).as_posix()
            data = f.read_bytes()
            if rel == RUBRIC and os.environ.get("GRADER_SECRET"):
                data = _with_secret(data.decode(), os.environ["GRADER_SECRET"]).encode()
            _add(z, rel, data, executable=bool(f.stat().st_mode & 0o111))
    tmp.replace(out)
    return out
