"""Shared test set-up: project paths, a seeded rng, the reference library built
once per run, one correct submission built once per run, and markers.

Markers (registered in pytest.ini):
    slow       grades whole submissions or classes (seconds each)
    sandbox    starts sandboxed workers or compiles in bubblewrap
    browser    drives a headless browser
    sanitizer  reruns suites under AddressSanitizer / UBSan
`make test` runs everything; `make test-fast` leaves out slow, sanitizer and
browser tests. Markers are given per test file below (MODULE_MARKERS) and
per test (TEST_MARKERS), so test files owned by different people need no
edits to be classified; a test file may also mark single tests with
@pytest.mark.<name>.
"""
from __future__ import annotations

import sys
from pathlib import Path

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
    "test_hostile": ("slow", "sandbox"),
    "test_worker": ("sandbox",),
    "test_build_sandbox": ("sandbox",),
    "test_reference_asan": ("sanitizer", "slow"),
    "test_reference_sanitizers": ("sanitizer", "slow"),
    "test_report_html_browser": ("browser", "slow"),
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
