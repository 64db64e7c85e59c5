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

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]   # unpacks and runs the autograder

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


def run_autograder(root: Path, submission: Path | None, *args: str, name: str = "EnvironmentMap.cpp",
                   stdout: list | None = None) -> dict:
    """Run run_autograder on `submission` (uploaded as `name`); its stdout,
    which Gradescope shows to instructors only, is appended to `stdout`."""
    for folder in ("submission", "results"):
        shutil.rmtree(root / folder, ignore_errors=True)
        (root / folder).mkdir()
    if submission is not None:
        shutil.copy(submission, root / "submission" / name)
    run = subprocess.run([str(root / "run_autograder"), *args], cwd=root, capture_output=True, text=True,
                         timeout=300, env={**os.environ, "AUTOGRADER_ROOT": str(root)})
    assert run.returncode == 0, run.stdout + run.stderr
    if stdout is not None:
        stdout.append(run.stdout)
    data = json.loads((root / "results" / "results.json").read_text())
    jsonschema.validate(data, load_schema())
    return data


def student_visible_text(data: dict) -> str:
    """What Gradescope shows a student: the top-level output and the visible tests."""
    shown = [data["output"]] + [t["name"] + "\n" + t["output"] for t in data["tests"] if t["visibility"] == "visible"]
    return "\n".join(shown)


def test_zip_has_the_scripts_at_the_top_and_no_build_outputs(bundle):
    with zipfile.ZipFile(bundle) as z:
        infos = {i.filename: i for i in z.infolist()}
    for script in ("setup.sh", "run_autograder"):
        assert script in infos
        assert (infos[script].external_attr >> 16) & 0o111, f"{script} is not executable"
    for needed in ("grader/__main__.py", "grader/grading/rubric.toml", "reference/include/envmap.h", "Makefile",
                   "requirements.txt", "fixtures/manifest.json", "student_template/EnvironmentMap.h"):
        assert needed in infos, needed
    parts = {p for name in infos for p in Path(name).parts}
    assert not parts & {".venv", "__pycache__", "out", "tests"}
    from grader import in_build_output
    assert not [name for name in infos if in_build_output(Path(name).parts)]
    assert "grader/build/__init__.py" in infos and "grader/build/shim/shim.cpp" in infos


def test_zip_is_reproducible(bundle, tmp_path):
    assert build_bundle(tmp_path / "again.zip").read_bytes() == bundle.read_bytes()


@pytest.mark.representative
def test_correct_submission_scores_full_marks(autograder):
    data = run_autograder(autograder, SUBMISSIONS / "correct" / "switch_on_face.cpp", "--quick")
    assert data["extra_data"]["status"] == "graded" and data["output_format"] == "html"
    assert data["score"] == data["extra_data"]["max_score"] == sum(t["max_score"] for t in data["tests"]) > 0
    assert all(t["status"] == "passed" for t in data["tests"])
    # The zip holds what the speed check's chart is drawn from.
    assert (autograder / "results" / "images" / "speed_accuracy_chart.png").is_file()


def test_a_zip_uploaded_to_gradescope_is_graded(autograder, tmp_path):
    """Gradescope puts an uploaded zip in /autograder/submission as it is: the
    zip is opened (the student's message says zips are accepted)."""
    handin = tmp_path / "handin.zip"
    with zipfile.ZipFile(handin, "w") as z:
        z.write(SUBMISSIONS / "correct" / "switch_on_face.cpp", "my_work/EnvironmentMap.cpp")
    stdout: list[str] = []
    data = run_autograder(autograder, handin, "--quick", name="handin.zip", stdout=stdout)
    assert data["extra_data"]["status"] == "graded"
    assert data["score"] == data["extra_data"]["max_score"] > 0
    assert "note: graded handin.zip, the archive in submission." in stdout[0]


@pytest.mark.representative
def test_build_error_gives_valid_results_and_no_check_passes(autograder):
    """Nothing ran, so nothing is "passed", not even the check worth no points."""
    data = run_autograder(autograder, SUBMISSIONS / "build" / "syntax_error.cpp", "--quick")
    assert data["extra_data"]["status"] == "build-error" and data["score"] == 0
    assert data["tests"] and all(t["status"] == "failed" for t in data["tests"])
    assert any(t["max_score"] == 0 for t in data["tests"])     # the informational check is among them
    assert "expected" in data["output"]                          # the compiler's message, for the student


@pytest.mark.representative
def test_students_see_no_instructor_notes_and_instructors_get_them_on_stdout(autograder):
    """Uploaded as mine.cpp: the note on which file was graded and the
    isolation mode are the instructor's (stdout, hidden; extra_data), never
    in what the student is shown."""
    stdout: list[str] = []
    data = run_autograder(autograder, SUBMISSIONS / "correct" / "switch_on_face.cpp", "--quick",
                          name="mine.cpp", stdout=stdout)
    assert data["stdout_visibility"] == "hidden"
    shown = student_visible_text(data)
    for note in ("no file is named EnvironmentMap.cpp", "used mine.cpp", "ran under", "sandbox",
                 "fixtures were made"):
        assert note not in shown, note
    assert "note: no file is named EnvironmentMap.cpp; used mine.cpp" in stdout[0]
    assert "note: the submission's code ran under: " in stdout[0]
    assert [w for w in data["extra_data"]["warnings"] if "mine.cpp" in w]
    assert data["extra_data"]["isolation"] in ("bubblewrap", "privilege-drop")


def test_html_output_embeds_the_render_that_differs_most(autograder, tmp_path):
    """output_format html: the summary and the worst render pair as PNG data
    URLs, the same pictures the render check wrote; results.json stays small."""
    import base64
    import re
    data = run_autograder(autograder, SUBMISSIONS / "wrong" / "v-flipped-pos-z.cpp", "--quick")
    assert data["output_format"] == "html"
    assert "v runs the wrong way" in data["output"]
    urls = re.findall(r'<img src="data:image/png;base64,([A-Za-z0-9+/=]+)" alt="([^"]+)"', data["output"])
    assert [alt for _, alt in urls] == ["Your render", "Reference render"]
    images = autograder / "results" / "images"
    for (encoded, _), name in zip(urls, ("render_submission.png", "render_reference.png")):
        assert base64.b64decode(encoded) == (images / name).read_bytes()
    assert len((autograder / "results" / "results.json").read_bytes()) < 200_000
    assert "<script" not in data["output"]


def test_a_large_picture_is_halved_until_it_fits(tmp_path):
    import base64
    import io

    import numpy as np
    from PIL import Image
    from grader.reports.gradescope_json import png_data_url
    noise = np.random.default_rng(1).integers(0, 256, (256, 256, 3), dtype=np.uint8)
    Image.fromarray(noise).save(tmp_path / "noise.png")
    assert (tmp_path / "noise.png").stat().st_size > 150_000
    url = png_data_url(tmp_path / "noise.png", max_bytes=60_000)
    assert url is not None and len(url) <= 60_000
    assert Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1]))).size == (64, 64)
    (tmp_path / "fake.png").write_bytes(b"GIF89a")
    assert png_data_url(tmp_path / "fake.png") is None


CHROMIUM = shutil.which("chromium")


@pytest.mark.browser
@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (Debian package `chromium`)")
def test_the_student_view_renders_with_its_pictures_in_a_browser(autograder, tmp_path):
    """The html output as a page (the tests' Markdown rendered the way
    Gradescope renders md, by a CommonMark renderer), opened in headless
    Chromium: both pictures decode at their size; a screenshot is kept in
    build/screenshots/ for a person to look at."""
    from markdown_it import MarkdownIt
    data = run_autograder(autograder, SUBMISSIONS / "wrong" / "v-flipped-pos-z.cpp", "--quick")
    md = MarkdownIt("commonmark", {"html": False}).enable("table")
    tests = "".join(f"<section><h2>{t['name']} ({t['score']:g} / {t['max_score']:g}, {t['status']})</h2>"
                    f"{md.render(t['output'])}</section>" for t in data["tests"] if t["visibility"] == "visible")
    probe = ('<script>addEventListener("load",()=>{document.body.setAttribute("data-images",'
             'JSON.stringify([...document.images].map(i=>[i.complete,i.naturalWidth,i.naturalHeight])))})</script>')
    page = tmp_path / "student.html"
    page.write_text(f"<!doctype html><meta charset=utf-8><body style='font-family:sans-serif;max-width:60em'>"
                    f"<h1>Autograder results</h1>{data['output']}{tests}{probe}</body>")
    profile = tmp_path / "profile"
    flags = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", f"--user-data-dir={profile}",
             "--hide-scrollbars", "--force-device-scale-factor=1"]
    dom = subprocess.run([CHROMIUM, *flags, "--virtual-time-budget=5000", "--dump-dom", page.as_uri()], capture_output=True, text=True,
                         timeout=120)
    assert dom.returncode == 0, dom.stderr[-2000:]
    import re
    found = json.loads(re.search(r'data-images="([^"]*)"', dom.stdout).group(1).replace("&quot;", '"'))
    assert found == [[True, 128, 128], [True, 128, 128]]
    shots = PROJECT_ROOT / "build" / "screenshots"
    shots.mkdir(parents=True, exist_ok=True)
    shot = subprocess.run([CHROMIUM, *flags, f"--screenshot={shots / 'gradescope_student_view.png'}",
                           "--window-size=1100,1400", page.as_uri()], capture_output=True, text=True, timeout=120)
    assert shot.returncode == 0 and (shots / "gradescope_student_view.png").stat().st_size > 10_000


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
    from grader.grading.score import load_rubric
    assert leaderboard_enabled(load_rubric(PROJECT_ROOT / "grader" / "grading" / "rubric.toml")) is False
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
    rubric = on / "source" / "grader" / "grading" / "rubric.toml"
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
    everything it calls is in the zip: install-grading-env.sh, which runs the
    package script with the core group and make-venv.sh with the lock (pip
    install --require-hashes)."""
    with zipfile.ZipFile(bundle) as z:
        names = set(z.namelist())
        setup = z.read("setup.sh").decode()
        env_script = z.read("scripts/install-grading-env.sh").decode()
    (tmp_path / "setup.sh").write_text(setup)
    for script in (tmp_path / "setup.sh", PROJECT_ROOT / "scripts" / "install-grading-env.sh"):
        assert subprocess.run(["bash", "-n", str(script)], capture_output=True).returncode == 0
    assert "bash scripts/install-grading-env.sh .venv" in setup
    assert "bash scripts/install-system-deps.sh core" in env_script
    assert 'bash scripts/make-venv.sh "$venv" requirements.lock "$python"' in env_script
    assert {"scripts/install-system-deps.sh", "scripts/make-venv.sh", "scripts/install-grading-env.sh",
            "requirements.lock", "packages.txt"} <= names
    assert "pip install --quiet" not in setup + env_script     # progress is shown while the image builds


def test_the_bundle_carries_grader_secret_and_warns_about_the_public_default(tmp_path, monkeypatch):
    """The shipped rubric's secret is public (issue 11, red team): GRADER_SECRET
    set while building goes into the bundled rubric; left unset, the command
    warns instead of shipping the default silently."""
    import tomllib
    from grader.platforms.gradescope import DEFAULT_SECRET, course_secret_problem
    monkeypatch.setenv("GRADER_SECRET", 'per-course "quoted" secret')
    assert course_secret_problem() is None
    with zipfile.ZipFile(build_bundle(tmp_path / "secret.zip")) as z:
        rubric = tomllib.loads(z.read("grader/grading/rubric.toml").decode())
    assert rubric["grading"]["secret"] == 'per-course "quoted" secret'
    assert rubric["checks"]          # the rest of the rubric is intact
    monkeypatch.delenv("GRADER_SECRET")
    with zipfile.ZipFile(build_bundle(tmp_path / "default.zip")) as z:
        assert tomllib.loads(z.read("grader/grading/rubric.toml").decode())["grading"]["secret"] == DEFAULT_SECRET
    assert "GRADER_SECRET" in course_secret_problem()
    warned = subprocess.run([sys.executable, "-m", "grader", "gradescope", "--out", str(tmp_path / "cli.zip")],
                            cwd=PROJECT_ROOT, capture_output=True, text=True,
                            env={k: v for k, v in os.environ.items() if k != "GRADER_SECRET"})
    assert warned.returncode == 0 and "course secret is the public default" in warned.stderr


# ---- the student view, on hand-made results (no grading) -----------------------------------

def made_result(**fields):
    from grader.grading.results import CheckResult, GradeResult
    checks = [CheckResult("sweeps", "fetchColor picks the right face.", status="failed", fraction=0.5,
                          output="half of them", score=15, max_score=30),
              CheckResult("face_recovery", "fetchColor samples the face it exits through.", status="skipped",
                          fraction=0.0, output="Not run.", score=0, max_score=0)]
    return GradeResult(submission="s", checks=checks, score=15, max_score=30, **fields)


def test_environment_and_sandbox_warnings_are_the_instructors_only():
    from grader.reports.gradescope_json import instructor_notes, results_json
    mismatch = "cc is 'cc (Ubuntu 13.3.0)' here but the fixtures were made with 'cc (Debian 12.2.0)'"
    result = made_result(warnings=[mismatch, "plain sandbox unavailable: bwrap failed"], isolation="privilege-drop")
    for output_format in ("md", "html"):
        data = results_json(result, output_format)
        jsonschema.validate(data, load_schema())
        assert "fixtures were made" not in student_visible_text(data)
        assert "sandbox" not in student_visible_text(data) and "ran under" not in student_visible_text(data)
        assert data["extra_data"]["warnings"] == result.warnings
    notes = instructor_notes(result)
    assert notes[:2] == result.warnings and notes[2].startswith("the submission's code ran under: ")


def test_a_skipped_check_is_failed_even_when_worth_no_points():
    from grader.reports.gradescope_json import results_json
    status = {t["extra_data"]["check"]: t["status"] for t in results_json(made_result())["tests"]}
    assert status == {"sweeps": "failed", "face_recovery": "failed"}
