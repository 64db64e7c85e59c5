"""The two production isolation modes as fixtures, for every test that grades
in both (tests/conftest.py registers them):

- `isolation_mode`: "bubblewrap" (as this machine runs it) and
  "privilege-drop" (root with a failing `bwrap` first on PATH, as in a
  container without user namespaces: Gradescope, PrairieLearn); a mode this
  machine cannot run is skipped, saying why.
- `privilege_drop`: the second alone.
ISOLATION names the mode a grading reports for each (GradeResult.isolation).
"""
from __future__ import annotations

import os
import stat

import pytest

from fake_bwrap import write_failing_bwrap

ISOLATION = {"bubblewrap": "bubblewrap", "privilege-drop": "privilege-drop"}


def _clear_caches():
    from grader.worker import sandbox
    sandbox.sandbox_problem.cache_clear()
    sandbox.privilege_drop_problem.cache_clear()


def _drop_privileges(tmp_path, monkeypatch):
    from grader.worker import sandbox
    if sandbox.privilege_drop_problem() is not None:
        pytest.skip(f"no privilege drop here: {sandbox.privilege_drop_problem()}")
    folder = write_failing_bwrap(tmp_path / "fakebin")
    # The worker's uid reads its inputs from below tmp_path.
    tmp_path.chmod(tmp_path.stat().st_mode | stat.S_IXOTH | stat.S_IROTH)
    monkeypatch.setenv("PATH", f"{folder}:{os.environ.get('PATH', '/usr/bin:/bin')}")
    _clear_caches()


@pytest.fixture
def privilege_drop(tmp_path, monkeypatch):
    """Root grading with a bwrap that always fails: privilege-drop mode."""
    _drop_privileges(tmp_path, monkeypatch)
    yield
    _clear_caches()


@pytest.fixture(params=list(ISOLATION))
def isolation_mode(request, tmp_path, monkeypatch):
    """Each production mode in turn (its name)."""
    from grader.worker import sandbox
    if request.param == "bubblewrap" and sandbox.sandbox_problem() is not None:
        pytest.skip(f"bubblewrap does not run here: {sandbox.sandbox_problem()}")
    if request.param == "privilege-drop":
        _drop_privileges(tmp_path, monkeypatch)
    yield request.param
    _clear_caches()
