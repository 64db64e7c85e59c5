"""Shared test set-up: project paths, a seeded rng, the reference library built
once per run, one correct submission built once per run, and markers.

Markers (registered in pytest.ini):
    slow       grades whole submissions or classes (seconds each)
    sandbox    starts sandboxed workers or compiles in bubblewrap
    browser    drives a headless browser
    sanitizer  reruns suites under AddressSanitizer / UBSan
    agreement  the student kit against the grader on every zoo submission
               (many minutes: pytest.ini leaves it out; `make kit-agreement`)
`make test` runs everything but agreement; `make test-fast` leaves out slow, sanitizer and
browser tests. Markers are given per test file below (MODULE_MARKERS) and
per test (TEST_MARKERS), so test files owned by different people need no
edits to be classified; a test file may also mark single tests with
@pytest.mark.<name>.
"""
from __future__ import annotations

import sys
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest

TESTS = Path(__file__).resolve().parent
PROJECT_ROOT = TESTS.parent
SUBMISSIONS = TESTS / "submissions"
CORRECT_SUBMISSION = SUBMISSIONS / "correct"

# Helpers next to the tests (assignment_model, fake_lookups) import by name.
if str(TESTS) not in sys.path:
    sys.path.insert(0, str(TESTS))

# What each test file needs or costs. Files not listed are fast: unit tests,
# the reference through cffi, report writers on hand-made results.
MODULE_MARKERS = {
    "test_grading_zoo": ("slow", "sandbox"),
    "test_grade_all": ("slow", "sandbox"),
    "test_commands": ("slow", "sandbox"),
    "test_gradescope": ("slow", "sandbox"),
    "test_report_words": ("slow", "sandbox"),
    "test_hostile": ("slow", "sandbox"),
    "test_worker": ("sandbox",),
    "test_build_sandbox": ("sandbox",),
    "test_reference_asan": ("sanitizer", "slow"),
    "test_reference_sanitizers": ("sanitizer", "slow"),
    "test_report_html_browser": ("browser", "slow"),
    "test_markers": ("slow",),      # collects three test files in a subprocess, twice
    "test_kit_agreement": ("slow", "sandbox"),   # builds the kit, grades each submission twice
}
# Single tests in otherwise fast files, by "module::test name" (parametrized
# cases included): what would keep `make test-fast` from its 60 s.
TEST_MARKERS = {
    # headless Chromium on a graded class
    "test_report_injection_e2e::test_no_name_runs_as_script_in_a_browser": ("browser", "slow"),
    # a whole-class grading (grade-all)
    "test_report_injection_e2e::test_grade_all_with_markup_and_mathtext_names": ("slow",),
    # a hypothesis property test of about 76 s
    "test_texture_model::test_one_mistake_in_each_function_is_named_and_neither_is_blamed_for_the_other": ("slow",),
}


def pytest_collection_modifyitems(config, items):
    for item in items:
        module = item.module.__name__.rsplit(".", 1)[-1]
        test = f"{module}::{getattr(item, 'originalname', None) or item.name}"
        for name in MODULE_MARKERS.get(module, ()) + TEST_MARKERS.get(test, ()):
            item.add_marker(getattr(pytest.mark, name))


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded generator: random tests repeat exactly."""
    return np.random.default_rng(20261201)


@pytest.fixture(scope="session")
def reference_library() -> Path:
    """build/libenvmap.so, built once per test run (make reference)."""
    from grader import reference
    path = reference.ensure_built()
    reference.library()
    return path


@pytest.fixture(scope="session")
def correct_build(reference_library):
    """One correct submission, compiled once per test run (grader.build's cache)."""
    from grader.build import build_submission
    source = sorted(CORRECT_SUBMISSION.glob("*.cpp"))[0]
    build = build_submission(source)
    assert build.ok, build.log
    return build


# ---- what another user (nobody) can reach -------------------------------------------

NOBODY = ["setpriv", "--reuid", "65534", "--regid", "65534", "--clear-groups"]
# What a copy of the project for another user leaves out (the venv is the
# interpreter's; build outputs are made again).
NOT_COPIED = (".venv", "build", "out", ".git", "__pycache__", ".pytest_cache", ".tmp-*")


def nobody_python() -> tuple[str | None, str]:
    """An interpreter path user nobody can run with the grader's packages
    (this one, or the same venv by its real path when only the way to it is
    closed, e.g. a .venv symlink inside a 0700 checkout), and why not when none."""
    import os
    import subprocess
    why = ""
    real = os.path.join(os.path.realpath(sys.prefix), "bin", "python")
    for python in dict.fromkeys([sys.executable, real]):
        done = subprocess.run([*NOBODY, python, "-c", "import numpy, cffi, rich"], capture_output=True,
                              text=True, timeout=60, cwd="/")
        if done.returncode == 0:
            return python, ""
        why = (done.stderr.strip().splitlines() or [f"exit {done.returncode}"])[-1]
    return None, why


class NobodyCopy(NamedTuple):
    root: Path       # the project, readable by nobody
    python: str      # an interpreter nobody can run with the grader's packages


@pytest.fixture(scope="session")
def nobody_project(tmp_path_factory) -> NobodyCopy:
    """The project as user nobody can read it: PROJECT_ROOT itself when it
    can, else a copy (without .venv/ and build outputs) in a folder open to
    all, as a checkout in /root or any 0700 folder needs. Skips, saying why,
    when nobody cannot run this interpreter with the grader's packages (a
    virtual environment inside such a folder)."""
    import shutil
    import subprocess
    import tempfile
    python, why = nobody_python()
    if python is None:
        pytest.skip(f"user nobody cannot run {sys.executable} with the grader's packages ({why}): "
                    "the virtual environment is in a folder other users cannot read")
    readable = subprocess.run([*NOBODY, "test", "-r", str(PROJECT_ROOT / "grader" / "__init__.py")],
                              timeout=60, cwd="/").returncode == 0
    if readable:
        yield NobodyCopy(PROJECT_ROOT, python)
        return
    folder = Path(tempfile.mkdtemp(prefix="envmap-for-nobody-"))
    try:
        folder.chmod(0o755)
        copy = folder / "project"
        shutil.copytree(PROJECT_ROOT, copy, ignore=shutil.ignore_patterns(*NOT_COPIED), symlinks=True)
        for path in [copy, *copy.rglob("*")]:
            if not path.is_symlink():
                path.chmod(path.stat().st_mode | (0o755 if path.is_dir() else 0o444))
        yield NobodyCopy(copy, python)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
