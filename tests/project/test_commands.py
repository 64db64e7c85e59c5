"""The command line as a newcomer meets it: `python -m grader ...`, the
Makefile's grade targets, and the student template's `make selfcheck`.

Grading runs with --quick where the grading configuration does not matter;
what is checked is the wiring: exit statuses, where reports land, messages.
"""
from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import jsonschema
import pytest

from grader import PROJECT_ROOT
from grader.reports.gradescope_json import load_schema

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]   # grades through the command line

CORRECT = PROJECT_ROOT / "tests" / "submissions" / "correct" / "if_chain.cpp"
BROKEN = PROJECT_ROOT / "tests" / "submissions" / "build" / "syntax_error.cpp"
TEMPLATE = PROJECT_ROOT / "student_template"
EXAMPLES = PROJECT_ROOT / "examples"
REPORTS = ("report.html", "report.md", "junit.xml", "results.json")
SUBCOMMANDS = ("grade", "grade-all", "fixtures", "bundle", "lookup", "render", "gradescope", "prairielearn")


def grader(*args: str, cwd: Path = PROJECT_ROOT, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "grader", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=timeout)


def results(out: Path) -> dict:
    data = json.loads((out / "results.json").read_text())
    jsonschema.validate(data, load_schema())
    return data


# ---- help ------------------------------------------------------------------------


def test_top_level_help_lists_every_command():
    run = grader("--help")
    assert run.returncode == 0, run.stderr
    for name in SUBCOMMANDS:
        assert re.search(rf"^\s+{re.escape(name)}\b", run.stdout, re.M), f"{name} missing from --help"


@pytest.mark.representative
@pytest.mark.parametrize("command", SUBCOMMANDS)
def test_each_subcommand_has_help(command):
    run = grader(command, "--help")
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith(f"usage: python -m grader {command}")


def test_grade_help_explains_defaults_and_exit_status():
    text = grader("grade", "--help").stdout
    for phrase in ("examples/", "out/<submission name>/", "--fail-under", "--student-view", "exit status"):
        assert phrase in text, phrase


# ---- grade -----------------------------------------------------------------------


@pytest.fixture(scope="module")
def graded_correct() -> tuple[subprocess.CompletedProcess, Path]:
    """Once per session for both xdist workers (tests/helpers/session_once.py): read, never changed."""
    import session_once
    return session_once.once("cli-graded-correct", lambda folder: (
        grader("grade", str(CORRECT), "--quick", "--out", str(folder / "reports")), folder / "reports"))


@pytest.mark.representative
def test_grade_correct_writes_every_report_and_exits_0(graded_correct):
    run, out = graded_correct
    assert run.returncode == 0, run.stdout + run.stderr
    for name in REPORTS:
        assert (out / name).stat().st_size > 0, name
    data = results(out)
    assert data["extra_data"]["status"] == "graded"
    assert data["score"] == data["extra_data"]["max_score"] > 0
    assert str(out / "report.html") in run.stdout   # the terminal says where to look


def test_grade_broken_writes_every_report_and_exits_0(tmp_path):
    out = tmp_path / "broken"
    run = grader("grade", str(BROKEN), "--quick", "--out", str(out))
    assert run.returncode == 0, run.stdout + run.stderr   # grading completed: the score is not the exit status
    for name in REPORTS:
        assert (out / name).stat().st_size > 0, name
    data = results(out)
    assert data["extra_data"]["status"] == "build-error"
    assert data["score"] == 0
    assert "build-error" in {d["id"] for d in data["extra_data"]["diagnoses"]}


def test_fail_under_exits_1_below_the_score_and_0_at_it(tmp_path, graded_correct):
    below = grader("grade", str(BROKEN), "--quick", "--out", str(tmp_path / "b"), "--fail-under", "50")
    assert below.returncode == 1, below.stdout + below.stderr
    full = results(graded_correct[1])["score"]
    at = grader("grade", str(CORRECT), "--quick", "--out", str(tmp_path / "c"), "--fail-under", f"{full:g}")
    assert at.returncode == 0, at.stdout + at.stderr


def test_missing_submission_is_a_clear_error(tmp_path):
    missing = tmp_path / "no-such-student.zip"
    run = grader("grade", str(missing), "--out", str(tmp_path / "out"))
    assert run.returncode == 2
    assert f"{missing} does not exist" in run.stderr
    assert not (tmp_path / "out").exists()


def test_grade_without_arguments_grades_the_examples(tmp_path, monkeypatch, capsys):
    """The examples folder is looked up when the command runs: a stand-in
    with two quick-to-grade submissions shows what `make grade` does."""
    from grader import cli
    from grader.commands import grade as grade_command
    examples = tmp_path / "examples"
    for name, source in (("first", BROKEN), ("second", BROKEN)):
        (examples / name).mkdir(parents=True)
        shutil.copy(source, examples / name / "EnvironmentMap.cpp")
    (examples / "README.md").write_text("not a submission\n")
    monkeypatch.setattr(grade_command, "EXAMPLES", examples)
    status = cli.main(["grade", "--quick", "--out", str(tmp_path / "out")])
    printed = capsys.readouterr().out
    assert status == 0
    for name in ("first", "second"):
        assert (tmp_path / "out" / name / "results.json").is_file()
        assert str(tmp_path / "out" / name / "report.html") in printed
    assert not (tmp_path / "out" / "README").exists()


def test_bundled_examples_are_submissions_described_in_their_readme():
    from grader.commands.grade import example_submissions
    found = example_submissions()
    assert len(found) >= 4
    readme = (EXAMPLES / "README.md").read_text()
    for folder in found:
        assert (folder / "EnvironmentMap.cpp").is_file(), folder
        assert f"`{folder.name}/`" in readme, f"examples/README.md does not describe {folder.name}"


def test_default_output_folder_is_named_after_the_submission():
    from grader.commands.grade import output_folders
    outs = output_folders([Path("class/alice.tar.gz"), Path("class/bob.cpp"), Path("class/carol")], None)
    assert outs == [PROJECT_ROOT / "out" / n for n in ("alice", "bob", "carol")]
    assert output_folders([Path("x/alice.zip")], Path("mine")) == [Path("mine")]
    # Two submissions with the same file name do not overwrite each other's reports.
    twins = output_folders([Path("a/EnvironmentMap.cpp"), Path("b/EnvironmentMap.cpp")], Path("o"))
    assert len(set(twins)) == 2


# ---- Makefile --------------------------------------------------------------------


def test_make_grade_one_submission_into_out(tmp_path):
    out = tmp_path / "made"
    run = subprocess.run(["make", "-s", "grade", f"SUBMISSION={BROKEN}", f"OUT={out}"], cwd=PROJECT_ROOT,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert results(out)["extra_data"]["status"] == "build-error"


def test_make_grade_all_without_submissions_says_how_to_use_it():
    run = subprocess.run(["make", "-s", "grade-all"], cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=300)
    assert run.returncode == 2     # the recipe's usage error (exit 2), passed on by make
    assert "SUBMISSIONS=dir" in run.stderr


# The student template's self-check now runs inside the generated student kit
# (python -m grader kit): tests/kit/test_kit.py.
