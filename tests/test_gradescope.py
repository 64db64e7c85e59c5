"""autograder.zip, run as Gradescope runs it.

The zip is unpacked into a temporary tree laid out as Gradescope lays out
/autograder: source/ (the zip's contents), submission/ (the student's
files), results/ (where results.json must appear). setup.sh is not run (it
installs Debian packages and a virtual environment, which Gradescope does
once per image): source/.venv is this project's virtual environment, and
`make reference` builds the reference inside the unpacked tree, so the
grading uses only what the zip holds. run_autograder is copied to the root,
where Gradescope puts it, and run with AUTOGRADER_ROOT pointing there.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import jsonschema
import pytest

from grader import PROJECT_ROOT
from grader.platforms.gradescope import build_bundle
from grader.reports.gradescope_json import load_schema

SUBMISSIONS = PROJECT_ROOT / "tests" / "submissions"


@pytest.fixture(scope="module")
def bundle(tmp_path_factory) -> Path:
    return build_bundle(tmp_path_factory.mktemp("bundle") / "autograder.zip")


@pytest.fixture(scope="module")
def autograder(tmp_path_factory, bundle) -> Path:
    """An /autograder tree with the zip unpacked and the reference built."""
    root = tmp_path_factory.mktemp("autograder")
    source = root / "source"
    # unzip keeps the scripts' execute bits, as Gradescope's unpacking does.
    subprocess.run(["unzip", "-q", str(bundle), "-d", str(source)], check=True)
    (source / ".venv").symlink_to(PROJECT_ROOT / ".venv")
    subprocess.run(["make", "-s", "-C", str(source), "reference"], check=True, capture_output=True, timeout=300)
    shutil.copy2(source / "run_autograder", root / "run_autograder")
    return root


def run_autograder(root: Path, submission: Path | None, *args: str) -> dict:
    for folder in ("submission", "results"):
        shutil.rmtree(root / folder, ignore_errors=True)
        (root / folder).mkdir()
    if submission is not None:
        shutil.copy(submission, root / "submission" / "EnvironmentMap.cpp")
    run = subprocess.run([str(root / "run_autograder"), *args], cwd=root, capture_output=True, text=True,
                         timeout=300, env={**os.environ, "AUTOGRADER_ROOT": str(root)})
    assert run.returncode == 0, run.stdout + run.stderr
    data = json.loads((root / "results" / "results.json").read_text())
    jsonschema.validate(data, load_schema())
    return data


def test_zip_has_the_scripts_at_the_top_and_no_build_outputs(bundle):
    with zipfile.ZipFile(bundle) as z:
        infos = {i.filename: i for i in z.infolist()}
    for script in ("setup.sh", "run_autograder"):
        assert script in infos
        assert (infos[script].external_attr >> 16) & 0o111, f"{script} is not executable"
    for needed in ("grader/__main__.py", "grader/rubric.toml", "reference/include/envmap.h", "Makefile",
                   "requirements.txt", "fixtures/manifest.json", "student_template/EnvironmentMap.h"):
        assert needed in infos, needed
    parts = {p for name in infos for p in Path(name).parts}
    assert not parts & {"build", ".venv", "__pycache__", "out", "tests"}


def test_zip_is_reproducible(bundle, tmp_path):
    assert build_bundle(tmp_path / "again.zip").read_bytes() == bundle.read_bytes()


def test_correct_submission_scores_full_marks(autograder):
    data = run_autograder(autograder, SUBMISSIONS / "correct" / "switch_on_face.cpp", "--quick")
    assert data["extra_data"]["status"] == "graded"
    assert data["score"] == data["extra_data"]["max_score"] == sum(t["max_score"] for t in data["tests"]) > 0
    assert all(t["status"] == "passed" for t in data["tests"])
    # The zip holds what the speed check's chart is drawn from.
    assert (autograder / "results" / "images" / "speed_accuracy_chart.png").is_file()


def test_build_error_gives_valid_results(autograder):
    data = run_autograder(autograder, SUBMISSIONS / "build" / "syntax_error.cpp", "--quick")
    assert data["extra_data"]["status"] == "build-error" and data["score"] == 0


def test_grader_that_cannot_start_still_leaves_valid_results(autograder, tmp_path):
    """No virtual environment: run_autograder's fallback results.json, which
    says the failure is not the student's."""
    broken = tmp_path / "broken"
    shutil.copytree(autograder, broken, symlinks=True, ignore=shutil.ignore_patterns(".venv"))
    data = run_autograder(broken, SUBMISSIONS / "correct" / "switch_on_face.cpp")
    assert data["extra_data"]["status"] == "ungradable"
    assert "not your fault" in data["output"]


# ---- the leaderboard (off by default) ---------------------------------------------------


def test_leaderboard_is_off_in_the_shipped_rubric():
    from grader.platforms.gradescope import leaderboard_enabled
    from grader.score import load_rubric
    assert leaderboard_enabled(load_rubric(PROJECT_ROOT / "grader" / "rubric.toml")) is False
    assert leaderboard_enabled({"gradescope": {"leaderboard": True}}) is True
    assert leaderboard_enabled({"gradescope": {"leaderboard": "yes"}}) is False   # only a real true


def test_leaderboard_entries_need_both_axes():
    from types import SimpleNamespace

    from grader.platforms.gradescope import leaderboard
    timed = SimpleNamespace(checks=[SimpleNamespace(metrics={"flip_mean": 0.1}),
                                    SimpleNamespace(metrics={"ns_per_lookup": 41.5, "uniform_smooth_rms": 0.0125})])
    assert leaderboard(timed) == [
        {"name": "Speed (ns per lookup)", "value": 41.5, "order": "asc"},
        {"name": "Accuracy (RMS error on the study's map)", "value": 0.0125, "order": "asc"}]
    crashed = SimpleNamespace(checks=[SimpleNamespace(metrics={"ns_per_lookup": float("nan")})])
    assert leaderboard(crashed) == []


@pytest.mark.slow
def test_leaderboard_in_results_when_the_rubric_turns_it_on(autograder, tmp_path):
    on = tmp_path / "on"
    shutil.copytree(autograder, on, symlinks=True)
    rubric = on / "source" / "grader" / "rubric.toml"
    text = rubric.read_text()
    assert "leaderboard = false" in text
    rubric.write_text(text.replace("leaderboard = false", "leaderboard = true"))
    data = run_autograder(on, SUBMISSIONS / "correct" / "switch_on_face.cpp", "--quick")
    board = {e["name"]: e["value"] for e in data["leaderboard"]}
    assert set(board) == {"Speed (ns per lookup)", "Accuracy (RMS error on the study's map)"}
    assert all(v > 0 for v in board.values())
    broken = run_autograder(on, SUBMISSIONS / "build" / "syntax_error.cpp", "--quick")
    assert "leaderboard" not in broken       # nothing measured: not on the board
    default = run_autograder(autograder, SUBMISSIONS / "correct" / "switch_on_face.cpp", "--quick")
    assert "leaderboard" not in default


def test_setup_sh_installs_like_make_venv_from_the_lock(bundle, tmp_path):
    """setup.sh is not run here (it is the image build), but it parses, and
    everything it calls is in the zip: the package script with the core
    group, make-venv.sh with the lock (pip install --require-hashes)."""
    with zipfile.ZipFile(bundle) as z:
        names = set(z.namelist())
        setup = z.read("setup.sh").decode()
    (tmp_path / "setup.sh").write_text(setup)
    assert subprocess.run(["bash", "-n", str(tmp_path / "setup.sh")], capture_output=True).returncode == 0
    assert "bash scripts/install-system-deps.sh core" in setup
    assert 'bash scripts/make-venv.sh .venv requirements.lock "$python"' in setup
    assert {"scripts/install-system-deps.sh", "scripts/make-venv.sh", "requirements.lock", "packages.txt"} <= names
    assert "pip install --quiet" not in setup     # progress is shown while the image builds


def test_the_bundle_carries_grader_secret_and_warns_about_the_public_default(tmp_path, monkeypatch):
    """The shipped rubric's secret is public (issue 11, red team): GRADER_SECRET
    set while building goes into the bundled rubric; left unset, the command
    warns instead of shipping the default silently."""
    import tomllib
    from grader.platforms.gradescope import DEFAULT_SECRET, course_secret_problem
    monkeypatch.setenv("GRADER_SECRET", 'per-course "quoted" secret')
    assert course_secret_problem() is None
    with zipfile.ZipFile(build_bundle(tmp_path / "secret.zip")) as z:
        rubric = tomllib.loads(z.read("grader/rubric.toml").decode())
    assert rubric["grading"]["secret"] == 'per-course "quoted" secret'
    assert rubric["checks"]          # the rest of the rubric is intact
    monkeypatch.delenv("GRADER_SECRET")
    with zipfile.ZipFile(build_bundle(tmp_path / "default.zip")) as z:
        assert tomllib.loads(z.read("grader/rubric.toml").decode())["grading"]["secret"] == DEFAULT_SECRET
    assert "GRADER_SECRET" in course_secret_problem()
    warned = subprocess.run([sys.executable, "-m", "grader", "gradescope", "--out", str(tmp_path / "cli.zip")],
                            cwd=PROJECT_ROOT, capture_output=True, text=True,
                            env={k: v for k, v in os.environ.items() if k != "GRADER_SECRET"})
    assert warned.returncode == 0 and "course secret is the public default" in warned.stderr
