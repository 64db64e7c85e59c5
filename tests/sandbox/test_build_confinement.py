"""Privilege-drop mode's confinement of the compiler (grader/build/compiler.py):
the build uid's view is asked of the kernel (a shell and find running as
that uid), the folders we own are closed, and when they cannot be nothing
is built. Layouts live in a folder of /tmp made 0755: mkdtemp's 0700
would hide them from the build uid whatever the code does."""
from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import pytest

from grader import build
from grader.build import compiler
from grader.build.compiler import BUILD_GID, BUILD_UID, HarnessBuildError
from grader.build import build_submission
from grader.build.compiler import BuildConfinementError, ensure_confined, readable_by, readable_tree
from project_paths import SUBMISSIONS

pytestmark = pytest.mark.skipif(os.geteuid() != 0, reason="needs root (to run as the build uid)")
GOOD = (SUBMISSIONS / "correct" / "idiomatic.cpp").read_bytes()


@pytest.fixture
def layout(monkeypatch):
    """An /autograder-like root, world-readable as an image's files are."""
    top = Path(tempfile.mkdtemp(prefix="confinement-"))
    root = top / "autograder"
    for folder in ("source/grader/grading", "submission", "results"):
        (root / folder).mkdir(parents=True)
    (root / "source" / "grader" / "grading" / "rubric.toml").write_text('secret = "s3cret"\n')
    (root / "submission" / "EnvironmentMap.cpp").write_bytes(GOOD)
    (root / "submission_metadata.json").write_text("{}")
    for path in [top, *top.rglob("*")]:
        path.chmod(0o755 if path.is_dir() else 0o644)
    monkeypatch.setenv("AUTOGRADER_ROOT", str(root))
    compiler._ensured.cache_clear()
    yield root
    compiler._ensured.cache_clear()
    shutil.rmtree(top, ignore_errors=True)


def test_the_probe_asks_the_kernel(layout):
    private = layout / "submission_metadata.json"
    public = layout / "source" / "grader" / "grading" / "rubric.toml"
    private.chmod(0o600)
    assert readable_by(BUILD_UID, BUILD_GID, [private, public, layout]) == [public, layout]


def test_a_readable_layout_is_closed_before_a_build(layout, tmp_path):
    before = readable_tree(BUILD_UID, BUILD_GID, [layout])
    assert {layout / "source" / "grader" / "grading" / "rubric.toml", layout / "submission" / "EnvironmentMap.cpp",
            layout / "submission_metadata.json"} <= set(before)
    ensure_confined(layout / "submission", tmp_path / "cache")
    assert readable_tree(BUILD_UID, BUILD_GID, [layout]) == []
    assert os.stat(layout).st_mode & 0o777 == 0o750     # only "other" lost access
    assert (layout / "source" / "grader" / "grading" / "rubric.toml").read_text()   # root still reads it


def test_when_our_files_cannot_be_closed_nothing_is_built(layout, tmp_path, monkeypatch):
    # As on a read-only bind mount: chmod cannot help, so the build refuses
    # with a typed error for the instructor, before compiling anything.
    monkeypatch.setattr(compiler, "_close", lambda root: None)
    monkeypatch.setattr(build, "build_isolation", lambda: "privilege-drop")
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    with pytest.raises(BuildConfinementError) as raised:
        build_submission(layout / "submission", cache_dir=tmp_path / "cache")
    assert isinstance(raised.value, HarnessBuildError)       # grade() makes it ungradable, not the student's
    assert str(layout) in str(raised.value) and "chmod o-rwx" in str(raised.value)
    assert not [p for p in scratch.iterdir() if p.name.startswith("envmap-build-")]


def test_a_grading_that_cannot_confine_is_ungradable_and_says_why(layout, tmp_path, monkeypatch):
    # The instructor reads what to close, not "could not build its own files".
    from grader.grading import grade as grading
    monkeypatch.setattr(compiler, "_close", lambda root: None)
    monkeypatch.setattr(build, "build_isolation", lambda: "privilege-drop")
    source = layout / "submission" / "EnvironmentMap.cpp"
    source.write_bytes(GOOD + f"\n// not in any build cache: {os.getpid()} {tmp_path.name}\n".encode())
    result = grading.grade(layout / "submission", tmp_path / "out", grading.GradeOptions(quick=True, allow_stale=True))
    assert result.status == "ungradable"
    assert any("chmod o-rwx" in w and "could not build its own files" not in w for w in result.warnings), result.warnings


def test_a_privilege_drop_build_closes_the_layout_and_builds(layout, tmp_path, monkeypatch):
    monkeypatch.setattr(build, "build_isolation", lambda: "privilege-drop")
    result = build_submission(layout / "submission", cache_dir=tmp_path / "cache")
    assert result.ok and result.isolation == "privilege-drop", result.log
    assert readable_tree(BUILD_UID, BUILD_GID, [layout]) == []
