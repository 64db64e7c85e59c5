"""student_template/: what students receive builds, runs and renders as the
reference does, and its bundled copies of the reference are the originals."""
from __future__ import annotations

import filecmp
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from skimage.io import imread

from grader import PROJECT_ROOT
from grader.reference import CubeMap, Scene, read_hdr

TEMPLATE = PROJECT_ROOT / "student_template"
REFERENCE = PROJECT_ROOT / "reference"
CORRECT_SOLUTION = Path(__file__).parent / "submissions" / "correct" / "if_chain.cpp"
# Files the template receives from elsewhere in the project when they exist
# (written out here, not taken from grader/commands/bundle.py, so a mistake
# there cannot hide itself).
OPTIONAL_COPIES = {
    "envmap_test.cfg": "envmap_test.cfg",
    "Cubemap/test_environment_map.hdr": "Cubemap/test_environment_map.hdr",
    "docs/figures/cross_layout.png": "figures/cross_layout.png",
    "docs/figures/face_uv.png": "figures/face_uv.png",
}


def test_bundled_reference_sources_are_the_originals():
    originals = [REFERENCE / "include" / "envmap.h"] + sorted((REFERENCE / "src").glob("*.[ch]"))
    copies = {TEMPLATE / p.relative_to(PROJECT_ROOT) for p in originals}
    for original in originals:
        copy = TEMPLATE / original.relative_to(PROJECT_ROOT)
        assert copy.is_file(), f"{copy} is missing: run `python -m grader bundle`"
        assert filecmp.cmp(original, copy, shallow=False), f"{copy} differs: run `python -m grader bundle`"
    extra = {p for p in (TEMPLATE / "reference").rglob("*") if p.is_file()} - copies
    assert not extra, f"stale copies (run `python -m grader bundle`): {sorted(extra)}"


@pytest.mark.parametrize("original, copy", OPTIONAL_COPIES.items())
def test_bundled_scene_map_and_figures_are_the_originals(original, copy):
    if not (PROJECT_ROOT / original).is_file():
        pytest.skip(f"{original} does not exist yet")
    assert filecmp.cmp(PROJECT_ROOT / original, TEMPLATE / copy, shallow=False), \
        f"{copy} differs from {original}: run `python -m grader bundle`"


def test_readme_figures_exist():
    readme = (TEMPLATE / "README.md").read_text()
    for figure in ("figures/cross_layout.png", "figures/face_uv.png"):
        assert figure in readme
        assert (TEMPLATE / figure).is_file()


@pytest.fixture(scope="module")
def template_copy(tmp_path_factory) -> Path:
    """A fresh copy of the template, as a student would receive it."""
    if not (TEMPLATE / "Cubemap" / "test_environment_map.hdr").is_file():
        pytest.skip("the template has no test map yet (run `python -m grader bundle`)")
    copy = tmp_path_factory.mktemp("template") / "student_template"
    shutil.copytree(TEMPLATE, copy, ignore=shutil.ignore_patterns("build", "envmap", "out.*"))
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


def test_untouched_template_builds_without_warnings_and_renders_black(template_copy):
    output = make_run(template_copy)
    assert "warning" not in output
    hdr = read_hdr(template_copy / "out.hdr")
    png = imread(template_copy / "out.png")
    assert hdr.shape == png.shape == (512, 512, 3)   # envmap_test.cfg's camera
    # The scene is lit only by the environment, and fetchColor starts black.
    assert not hdr.any() and not png.any()


def test_make_run_with_a_solution_renders_the_reference_image(template_copy):
    shutil.copyfile(CORRECT_SOLUTION, template_copy / "EnvironmentMap.cpp")
    make_run(template_copy)
    scene = Scene.load(template_copy / "envmap_test.cfg")
    expected = scene.render(CubeMap.load_cross(template_copy / "Cubemap" / "test_environment_map.hdr"))
    hdr = read_hdr(template_copy / "out.hdr")
    # RGBE keeps 8 bits of mantissa per channel: within one step of the
    # largest channel of the pixel.
    step = np.max(expected, axis=2, keepdims=True) / 128
    assert np.all(np.abs(hdr - expected) <= step + 1e-12)
    png = imread(template_copy / "out.png")
    diff = np.abs(png.astype(int) - srgb8(expected).astype(int))
    assert diff.max() <= 1  # float vs double rounding at the 8-bit boundary
    assert png.std() > 10   # not a flat image
