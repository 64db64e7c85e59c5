"""Cutting a vertical cross into six faces and back (reference/src/cross.c).

The expected faces come from numpy slicing of the cross, with the cell of each
face written out here from ASSIGNMENT.md ("Vertical cross", "Buffer").
"""
from __future__ import annotations

import os

import numpy as np
import OpenImageIO as oiio
import pytest

from grader import PROBES
from grader.envmap.library import EnvmapError, cross_to_faces, faces_to_cross, library, write_hdr

PROBE_CROSSES = sorted(PROBES.glob("*_cross.hdr"))

EM_ERR_IO, EM_ERR_LAYOUT, EM_ERR_ARGUMENT = -1, -5, -7

# (column, row) of each face's cell, row 0 at the top of the image, in face
# order +X -X +Y -Y +Z -Z:
#            [+Y]
#      [-X]  [-Z]  [+X]
#            [-Y]
#            [+Z]
CELL = {"+X": (2, 1), "-X": (0, 1), "+Y": (1, 0), "-Y": (1, 2), "+Z": (1, 3), "-Z": (1, 1)}
FACES = ["+X", "-X", "+Y", "-Y", "+Z", "-Z"]
UNUSED = [(c, r) for r in range(4) for c in range(3) if (c, r) not in CELL.values()]


def cell(image: np.ndarray, column: int, row: int) -> np.ndarray:
    n = image.shape[1] // 3
    return image[row * n:(row + 1) * n, column * n:(column + 1) * n]


def expected_faces(cross: np.ndarray) -> np.ndarray:
    """Faces (6, n, n, 3), y = 0 the bottom row: each cell flipped upside down."""
    return np.stack([cell(cross, *CELL[f])[::-1] for f in FACES])


def random_cross(face: int, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).random((4 * face, 3 * face, 3), dtype=np.float32)


def test_faces_are_the_cross_cells_flipped_upside_down():
    cross = random_cross(5)
    np.testing.assert_array_equal(cross_to_faces(cross), expected_faces(cross))


def test_each_cell_goes_to_its_face():
    cross = np.zeros((8, 6, 3), np.float32)
    for k, name in enumerate(FACES):
        cell(cross, *CELL[name])[:] = k + 1
    for column, row in UNUSED:
        cell(cross, column, row)[:] = 99      # never copied
    faces = cross_to_faces(cross)
    for k, name in enumerate(FACES):
        assert np.all(faces[k] == k + 1), f"face {name} did not come from cell {CELL[name]}"


def test_top_row_of_a_cell_is_the_last_row_of_its_face():
    cross = np.zeros((16, 12, 3), np.float32)
    top_left_of_plus_y = (0, 4)               # image row 0, column 4: cell (1, 0)
    cross[top_left_of_plus_y] = [1, 2, 3]
    faces = cross_to_faces(cross)
    assert faces[FACES.index("+Y"), 3, 0].tolist() == [1, 2, 3]   # y = H-1 (top), x = 0 (left)
    assert np.count_nonzero(faces) == 3


def test_to_cross_inverts_from_cross_on_the_face_cells():
    cross = random_cross(4, seed=1)
    back = faces_to_cross(cross_to_faces(cross))
    assert back.shape == cross.shape
    for name in FACES:
        np.testing.assert_array_equal(cell(back, *CELL[name]), cell(cross, *CELL[name]))
    for column, row in UNUSED:
        assert not cell(back, column, row).any(), f"unused cell {(column, row)} is not 0"


def test_from_cross_inverts_to_cross():
    faces = np.random.default_rng(2).random((6, 3, 3, 3), dtype=np.float32)
    np.testing.assert_array_equal(cross_to_faces(faces_to_cross(faces)), faces)


def test_smallest_cross_has_one_texel_faces():
    cross = random_cross(1, seed=3)
    np.testing.assert_array_equal(cross_to_faces(cross), expected_faces(cross))


@pytest.mark.parametrize("height,width", [(1024, 770), (1022, 768), (8, 9), (4, 6), (8, 3), (3, 3)])
def test_an_image_that_is_not_a_vertical_cross_is_refused(height, width):
    with pytest.raises(EnvmapError) as caught:
        cross_to_faces(np.zeros((height, width, 3), np.float32))
    assert caught.value.code == EM_ERR_LAYOUT
    assert f"{width} x {height}" in str(caught.value) and "vertical cross" in str(caught.value)


# ---- the C entry points the Python helpers do not wrap ----------------------

def load_cross(path) -> np.ndarray:
    """em_cubemap_load_cross, faces as (6, n, n, 3)."""
    ffi, lib = library()
    cube, err = ffi.new("em_cubemap *"), ffi.new("em_error *")
    status = lib.em_cubemap_load_cross(os.fsencode(path), cube, err)
    if status != 0:
        raise EnvmapError(status, ffi.string(err.message).decode())
    try:
        w, h = cube.face_width, cube.face_height
        data = np.frombuffer(ffi.buffer(cube.texels, 6 * w * h * 3 * 4), np.float32)
        for k in range(6):   # em_cubemap_face points at face k
            assert lib.em_cubemap_face(cube, k) == cube.texels + k * w * h * 3
        assert lib.em_cubemap_face(cube, 6) == ffi.NULL and lib.em_cubemap_face(cube, -1) == ffi.NULL
        return data.copy().reshape(6, h, w, 3)
    finally:
        lib.em_cubemap_free(cube)
        assert cube.texels == ffi.NULL


@pytest.mark.parametrize("path", PROBE_CROSSES[:2], ids=lambda p: p.name)
def test_load_cross_of_a_real_probe_matches_slicing_the_openimageio_image(path):
    image = oiio.ImageBuf(str(path)).get_pixels(oiio.FLOAT)
    np.testing.assert_array_equal(load_cross(path), expected_faces(image))


def test_load_cross_of_a_written_cross(tmp_path):
    # values exactly representable in RGBE, so the file round trip is exact
    cross = np.ldexp(np.random.default_rng(4).integers(128, 256, (24, 18, 3)), -7).astype(np.float32)
    path = tmp_path / "cross.hdr"
    write_hdr(path, cross)
    np.testing.assert_array_equal(load_cross(path), expected_faces(cross))


def test_load_cross_names_the_file_when_it_is_not_a_cross(tmp_path):
    path = tmp_path / "wide.hdr"
    write_hdr(path, np.ones((4, 8, 3), np.float32))
    with pytest.raises(EnvmapError) as caught:
        load_cross(path)
    assert caught.value.code == EM_ERR_LAYOUT and str(caught.value).startswith(f"{path}: ")


def test_load_cross_of_a_missing_file_is_an_io_error(tmp_path):
    with pytest.raises(EnvmapError) as caught:
        load_cross(tmp_path / "none.hdr")
    assert caught.value.code == EM_ERR_IO and "none.hdr" in str(caught.value)


def test_alloc_zeroes_and_refuses_bad_sizes():
    ffi, lib = library()
    cube, err = ffi.new("em_cubemap *"), ffi.new("em_error *")
    assert lib.em_cubemap_alloc(3, 2, cube, err) == 0
    assert (cube.face_width, cube.face_height) == (3, 2)
    assert not np.frombuffer(ffi.buffer(cube.texels, 6 * 3 * 2 * 3 * 4), np.float32).any()
    lib.em_cubemap_free(cube)
    assert lib.em_cubemap_alloc(0, 2, cube, err) == EM_ERR_ARGUMENT and cube.texels == ffi.NULL
    assert lib.em_cubemap_alloc(1 << 20, 1 << 20, cube, err) == -4  # EM_ERR_TOO_LARGE
