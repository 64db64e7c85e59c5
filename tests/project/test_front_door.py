"""The targets README.md names, run the way README shows them, in a copy of
the project: after a scene edit the grader refuses and names `make
fixtures`; `make fixtures` regenerates them; then `make grade` grades.

The copy shares the project's .venv/ (a symlink: creating one from the lock
is tested by CI's fresh clone, where `make test-all` itself makes it) and
builds everything else (reference library, grader objects) itself.
"""
from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from grader import PROJECT_ROOT

CORRECT = PROJECT_ROOT / "tests" / "submissions" / "correct" / "if_chain.cpp"
BROKEN = PROJECT_ROOT / "tests" / "submissions" / "build" / "syntax_error.cpp"
SCENE = "scenes/glass_ball_grid_room.cfg"
STUDENT_TARGETS = {"run"}   # README: "students get student_template/ (`make run` ...)"
from conftest import not_copied as LEFT_OUT  # noqa: E402  (keeps grader/build/, the build step's package)


def make(project: Path, *args: str, timeout: float = 600) -> subprocess.CompletedProcess:
    return subprocess.run(["make", "-s", *args], cwd=project, capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def project(tmp_path_factory) -> Path:
    copy = tmp_path_factory.mktemp("front-door") / "project"
    shutil.copytree(PROJECT_ROOT, copy, ignore=LEFT_OUT, symlinks=True)
    (copy / ".venv").symlink_to(PROJECT_ROOT / ".venv")
    return copy


def rules(folder: Path) -> dict[str, tuple[list[str], list[str]]]:
    """{target: (prerequisites, recipe lines)} from make's database (nothing is run)."""
    db = subprocess.run(["make", "-pRrq", "-f", "Makefile", ":"], cwd=folder, capture_output=True, text=True,
                        timeout=60).stdout
    out: dict[str, tuple[list[str], list[str]]] = {}
    target = None
    for line in db.splitlines():
        m = re.match(r"^([^\s#:=][^:=]*):(?![=:])(.*)$", line)
        if m and not line.startswith("\t"):
            target = m[1]
            out.setdefault(target, ([], []))[0].extend(m[2].replace("|", " ").split())
        elif line.startswith("\t") and target:
            out[target][1].append(line.strip())
        elif not line.strip():
            target = None
    return out


def runs_something(db, target: str, depth: int = 3) -> bool:
    prerequisites, recipe = db.get(target, ([], []))
    return bool(recipe) or (depth > 0 and any(runs_something(db, p, depth - 1) for p in prerequisites))


def test_readme_names_only_targets_the_makefile_has():
    """Every `make X` in README.md has a rule that runs something (in the
    project, or in student_template/ for what README says students run)."""
    readme = (PROJECT_ROOT / "README.md").read_text()
    targets = sorted(set(re.findall(r"(?:`|^)make ([a-z][\w-]*)", readme, re.M)))
    assert {"grade", "test-all", "test", "test-fast", "fixtures", "grade-all", "gradescope", "venv"} <= set(targets)
    project, student = rules(PROJECT_ROOT), rules(PROJECT_ROOT / "student_template")
    for target in targets:
        db = student if target in STUDENT_TARGETS else project
        assert target in db and runs_something(db, target), f"make {target}: no rule, or a rule that runs nothing"
    assert not runs_something(project, "no-such-target")


@pytest.mark.slow
def test_scene_edit_then_make_fixtures_then_make_grade(project, tmp_path):
    scene = project / SCENE
    text = scene.read_text()
    assert "position = (-4, 0.5, 0.5);" in text
    scene.write_text(text.replace("position = (-4, 0.5, 0.5);", "position = (-4, 0.7, 0.5);"))
    fixture = next((project / "fixtures" / "renders").glob("glass_ball_grid_room--*.npy"))
    before = fixture.read_bytes()

    refused = make(project, "grade", f"SUBMISSION={CORRECT}", f"OUT={tmp_path / 'refused'}")
    assert refused.returncode != 0
    said = refused.stdout + refused.stderr
    assert f"{SCENE} changed" in said and "make fixtures" in said, said
    assert not (tmp_path / "refused" / "results.json").exists()

    made = make(project, "fixtures")
    assert made.returncode == 0, made.stdout + made.stderr
    assert "fixture files" in made.stdout and "recorded: numpy " in made.stdout
    assert fixture.read_bytes() != before           # the camera moved: a new render

    graded = make(project, "grade", f"SUBMISSION={CORRECT}", f"OUT={tmp_path / 'graded'}")
    assert graded.returncode == 0, graded.stdout + graded.stderr
    results = json.loads((tmp_path / "graded" / "results.json").read_text())
    assert results["extra_data"]["status"] == "graded"
    assert results["score"] == results["extra_data"]["max_score"] > 0   # the new fixture matches the reference


@pytest.mark.slow
def test_make_grade_all_and_gradescope_in_the_copy(project, tmp_path):
    made = make(project, "fixtures")    # the other test may have moved the scene
    assert made.returncode == 0, made.stderr
    klass = tmp_path / "class"
    klass.mkdir()
    shutil.copy(BROKEN, klass / "alice.cpp")
    shutil.copy(BROKEN, klass / "bob.cpp")
    graded = make(project, "grade-all", f"SUBMISSIONS={klass}", f"OUT={tmp_path / 'out'}", "JOBS=1")
    assert graded.returncode == 0, graded.stdout + graded.stderr
    gradebook = (tmp_path / "out" / "gradebook.csv").read_text().splitlines()
    assert [line.split(",")[0] for line in gradebook[1:]] == ["alice", "bob"]

    zipped = make(project, "gradescope")
    assert zipped.returncode == 0, zipped.stdout + zipped.stderr
    assert (project / "build" / "autograder.zip").stat().st_size > 100_000


@pytest.mark.slow
def test_make_venv_in_a_fresh_copy_installs_the_lock(tmp_path):
    """`make venv` as a fresh clone runs it: a new .venv/ from requirements.lock
    (pip install --require-hashes), showing progress; pip's wheel cache keeps
    it to seconds on a machine that has installed it before."""
    copy = tmp_path / "fresh"
    shutil.copytree(PROJECT_ROOT, copy, ignore=LEFT_OUT, symlinks=True)
    made = make(copy, "venv", timeout=900)
    assert made.returncode == 0, made.stdout[-3000:] + made.stderr[-3000:]
    assert "venv: installing requirements.lock" in made.stdout and "venv: ready" in made.stdout
    frozen = subprocess.run([str(copy / ".venv" / "bin" / "python"), "-m", "pip", "freeze"], capture_output=True,
                            text=True, check=True).stdout
    installed = {line.split("==")[0].lower().replace("_", "-"): line.split("==")[1]
                 for line in frozen.splitlines() if "==" in line}
    lock = (PROJECT_ROOT / "requirements.lock").read_text()
    pins = dict(re.findall(r"^([a-z0-9._-]+)==([^\s;\\]+)(?! ; sys_platform == 'win32')", lock, re.M))
    pins = {k.lower(): v for k, v in pins.items() if k.lower() != "colorama"}     # Windows only
    assert installed == pins
