"""Shared test set-up: project paths, a seeded rng, the reference library built
once per run, one correct submission built once per run, and markers.

Markers (registered in pytest.ini):
    slow       grades whole submissions or classes (seconds each)
    sandbox    starts sandboxed workers or compiles in bubblewrap
    browser    drives a headless browser
    sanitizer  reruns suites under AddressSanitizer / UBSan
    agreement  the student kit against the grader on every zoo submission
               (many minutes: pytest.ini leaves it out; `make kit-agreement`)
    representative  a slow test `make test` runs all the same
`make test-all` (CI's gate, .ci/run) runs everything but agreement; `make test`
(about 3 min) runs the fast tests and the representative slow ones: one or two
of each family of gradings, both isolation modes; `make test-fast` (under a
minute) leaves out slow, sanitizer and browser tests. The folders say what
their tests cost (FOLDER_MARKERS below; tests/README.md); a module or a test
says it where it differs.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest

TESTS = Path(__file__).resolve().parent
PROJECT_ROOT = TESTS.parent
SUBMISSIONS = TESTS / "submissions"
CORRECT_SUBMISSION = SUBMISSIONS / "correct"

# One OpenMP thread for FLIP here and in every grader the tests start (they
# inherit it), as grader.checks sets for itself: two xdist workers already
# fill two cores, and idle OpenMP threads spin.
os.environ.setdefault("OMP_NUM_THREADS", "1")

# The helpers (tests/helpers/: assignment_model, fake_lookups, ...) import by
# name, and so do the few test modules another test borrows from (test files'
# names are unique across the folders).
for folder in [TESTS / "helpers", *sorted(p.parent for p in TESTS.glob("*/**/test_*.py")
                                          if "submissions" not in p.parts)]:
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))

# What a test costs is said where it sits: by its folder (below), by its
# module (`pytestmark = [...]`), or beside the test or case itself
# (`@pytest.mark.slow` with a comment saying why; tests/helpers/cases.py for
# single parametrized cases). `make test` also runs the slow tests marked
# `representative`: each grading path once, both isolation modes.
FOLDER_MARKERS = {
    "grading": ("slow", "sandbox"),   # the zoos, graded whole
    "sandbox": ("sandbox",),          # starts workers or compiles in the sandbox
    "browser": ("browser", "slow"),   # headless Chromium
}


def pytest_collection_modifyitems(config, items):
    for item in items:
        folder = Path(item.fspath).relative_to(TESTS).parts[0]
        for name in FOLDER_MARKERS.get(folder, ()):
            item.add_marker(getattr(pytest.mark, name))


# The isolation modes (isolation_mode, privilege_drop): tests/helpers/isolation.py.
pytest_plugins = ["isolation"]


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded generator: random tests repeat exactly."""
    return np.random.default_rng(20261201)


@pytest.fixture(scope="session", autouse=True)
def session_folder(tmp_path_factory) -> Path:
    """Where session_once keeps what is done once per session (gradings of
    grading_cache.grade_once, the student kit): one folder for every xdist
    worker (their base folders' parent)."""
    import session_once
    base = tmp_path_factory.getbasetemp()
    session_once.FOLDER = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "once"
    return session_once.FOLDER


@pytest.fixture(scope="session")
def student_kit(session_folder):
    """The student kit (grader.kit.build), built once per session: read it,
    never change it (copy it first)."""
    import session_once
    from grader.kit.build import build_kit
    return session_once.once("student-kit", lambda folder: build_kit(folder / "student-kit"))


@pytest.fixture(scope="session")
def reference_library() -> Path:
    """build/libenvmap.so, built once per test run (make reference)."""
    from grader.envmap import library
    path = library.ensure_built()
    library.library()
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


def not_copied(folder: str, names: list[str]) -> set[str]:
    """shutil.copytree's ignore for NOT_COPIED, keeping grader/build/ (the
    build step's package, not a build output)."""
    import shutil
    from grader import in_build_output
    ignored = set(shutil.ignore_patterns(*NOT_COPIED)(folder, names))
    if "build" in ignored and not in_build_output((*Path(folder).parts[-1:], "build", "x")):
        ignored.discard("build")
    return ignored


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
        shutil.copytree(PROJECT_ROOT, copy, ignore=not_copied, symlinks=True)
        for path in [copy, *copy.rglob("*")]:
            if not path.is_symlink():
                path.chmod(path.stat().st_mode | (0o755 if path.is_dir() else 0o444))
        yield NobodyCopy(copy, python)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
