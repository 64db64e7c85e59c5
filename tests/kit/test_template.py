"""student_template/: the start of what students receive. It holds no copy
of the reference (the kit is generated from reference/ by `python -m grader
kit`, tests/kit/test_kit.py), keeps the interface the grader compiles against,
and, inside the kit, builds, runs and renders as the reference does."""
from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from skimage.io import imread

from grader import PROJECT_ROOT
from grader.envmap.library import CubeMap, Scene, read_hdr
from project_paths import SUBMISSIONS

TEMPLATE = PROJECT_ROOT / "student_template"
CORRECT_SOLUTION = SUBMISSIONS / "correct" / "if_chain.cpp"


def test_template_holds_no_copy_of_the_reference():
    assert not (TEMPLATE / "reference").exists()
    for path in TEMPLATE.rglob("*"):
        assert path.name not in {"lookup.c", "envmap.h", "render.c"}, path
    # Nothing the kit takes from the project is duplicated in the template.
    assert not (TEMPLATE / "Cubemap").exists() and not (TEMPLATE / "envmap_test.cfg").exists()


def test_the_interface_the_grader_compiles_against_is_there():
    # grader/build/__init__.py compiles the student's file with student_template/*.h
    # and EnvironmentMapLoader.cpp.
    for name in ("EnvironmentMap.h", "Vector3.h", "Color.h", "EnvironmentMapLoader.cpp", "EnvironmentMap.cpp"):
        assert (TEMPLATE / name).is_file(), name
    header = (TEMPLATE / "EnvironmentMap.h").read_text()
    assert "Color fetchColor(const Vector3& direction) const;" in header
    assert "Color readTexture(const float* addr, double u, double v) const;" in header
    # Third-party headers come into the kit only: the grader must not see them.
    assert sorted(p.name for p in TEMPLATE.glob("*.h")) == ["Color.h", "EnvironmentMap.h", "PngWriter.h", "Vector3.h"]


def test_readme_figures_exist_in_the_project():
    readme = (TEMPLATE / "README.md").read_text()
    for figure in re.findall(r"\]\((figures/[\w.]+)\)", readme):
        assert (PROJECT_ROOT / "docs" / figure).is_file(), figure
    assert "figures/cross_layout.png" in readme and "figures/face_uv.png" in readme


def test_workflow_uses_nothing_private():
    workflow = (TEMPLATE / ".github" / "workflows" / "grade.yml").read_text()
    assert "secrets." not in workflow and "token" not in workflow.lower().replace("no token", "")
    assert workflow.count("uses: actions/checkout") == 1 and "repository:" not in workflow
    assert "make selfcheck" in workflow
    assert "build/selfcheck/report.md" in workflow and "GITHUB_STEP_SUMMARY" in workflow
    assert "build/selfcheck/report.html" in workflow and "upload-artifact" in workflow


@pytest.fixture(scope="module")
def kit_copy(student_kit, tmp_path_factory) -> Path:
    """The kit, as a student receives it (a copy of the session's, which stays untouched)."""
    copy = tmp_path_factory.mktemp("kit") / "student-kit"
    shutil.copytree(student_kit.folder, copy, symlinks=True)
    return copy


def make_run(folder: Path) -> str:
    run = subprocess.run(["make", "-C", str(folder), "run"], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    return run.stdout + run.stderr


def srgb8(linear: np.ndarray) -> np.ndarray:
    """The template's documented tone map: clamp to [0, 1], sRGB curve, 8 bits."""
    c = np.clip(np.nan_to_num(linear), 0.0, 1.0).astype(np.float64)
    c = np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)
    return np.floor(c * 255 + 0.5).astype(np.uint8)


# slow: several real builds each, in more than one isolation mode (12-16 s)
@pytest.mark.slow
def test_untouched_template_builds_without_warnings_and_renders_black(kit_copy):
    output = make_run(kit_copy)
    assert "warning" not in output
    hdr = read_hdr(kit_copy / "out.hdr")
    png = imread(kit_copy / "out.png")
    assert hdr.shape == png.shape == (512, 512, 3)   # envmap_test.cfg's camera
    # The scene is lit only by the environment, and fetchColor starts black.
    assert not hdr.any() and not png.any()


# slow: several real builds each, in more than one isolation mode (12-16 s)
@pytest.mark.slow
def test_make_run_with_a_solution_renders_the_reference_image(kit_copy):
    shutil.copyfile(CORRECT_SOLUTION, kit_copy / "EnvironmentMap.cpp")
    make_run(kit_copy)
    scene = Scene.load(kit_copy / "envmap_test.cfg")
    expected = scene.render(CubeMap.load_cross(kit_copy / "Cubemap" / "test_environment_map.hdr"))
    hdr = read_hdr(kit_copy / "out.hdr")
    # RGBE keeps 8 bits of mantissa per channel: within one step of the
    # largest channel of the pixel. The lookups run on every core: the
    # picture is the same as the reference's single-threaded one.
    step = np.max(expected, axis=2, keepdims=True) / 128
    assert np.all(np.abs(hdr - expected) <= step + 1e-12)
    png = imread(kit_copy / "out.png")
    diff = np.abs(png.astype(int) - srgb8(expected).astype(int))
    assert diff.max() <= 1  # float vs double rounding at the 8-bit boundary
    assert png.std() > 10   # not a flat image
