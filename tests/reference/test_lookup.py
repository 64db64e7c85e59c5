"""The reference lookups (reference/src/lookup.c) against ASSIGNMENT.md.

Expected values come from tests/helpers/assignment_model.py (an independent numpy
model of the handout) or from closed forms (linear functions, corner texels),
never from the C code under test.
"""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import assignment_model as model
from grader import PROJECT_ROOT
from grader.envmap.library import FILTERS, CubeMap, direction_to_face, library

SIDE = 16                     # face size of the random test maps: small, so seams matter
RTOL = ATOL = 1e-12           # both sides compute in double from float texels
EPSILON_ANGLE = 1e-9          # radians either side of an edge for continuity
SEAMLESS_JUMP_BOUND = 1e-6    # largest jump allowed for seamless (texel steps are ~0.3)


def random_cube(rng, width=SIDE, height=SIDE, low=0.0, high=1.0) -> np.ndarray:
    return rng.uniform(low, high, (6, height, width, 3)).astype(np.float32)


@pytest.fixture
def rng():
    return np.random.default_rng(20140516)


@pytest.fixture
def cube(rng):
    return random_cube(rng)


def explain_mismatch(what: str, actual, expected, dirs=None, extra=None, rtol=RTOL, atol=ATOL) -> None:
    """Fail, naming the worst offender, unless actual matches expected
    (rows of colours). The one comparison every test here goes through."""
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    bad = ~np.isclose(actual, expected, rtol=rtol, atol=atol).reshape(len(actual), -1).all(axis=1)
    if not bad.any():
        return
    error = np.abs(actual - expected).reshape(len(actual), -1).max(axis=1)
    worst = int(np.argmax(np.where(bad, error, -1)))
    lines = [f"{what}: {bad.sum()} of {len(actual)} differ; worst is row {worst}:",
             f"  actual   {actual[worst]}", f"  expected {expected[worst]}"]
    if dirs is not None:
        faces, uv = direction_to_face(dirs[worst:worst + 1])
        lines.append(f"  direction {dirs[worst]!r} -> face {faces[0]} uv {uv[0]!r}")
    if extra is not None:
        lines.append(f"  {extra[worst]!r}")
    pytest.fail("\n".join(lines))


def seam_corner_axis_directions() -> np.ndarray:
    """Every axis, corner, points along every edge, directions a hair off the
    edges, and directions through texel boundaries of every face."""
    eye = np.eye(3)
    out = [eye, -eye]
    signs = np.array([[sx, sy, sz] for sx in (1, -1) for sy in (1, -1) for sz in (1, -1)], float)
    out.append(signs)                                         # the 8 corners
    t = np.linspace(-1, 1, 2 * SIDE + 1)                      # hits texel boundaries too
    for i, j in ((0, 1), (0, 2), (1, 2)):
        k = 3 - i - j
        for si in (1, -1):
            for sj in (1, -1):
                edge = np.zeros((len(t), 3))
                edge[:, i], edge[:, j], edge[:, k] = si, sj, t
                out.append(edge)                              # on the edge (ties)
                for hair in (1 + 2.0 ** -52, 1 - 2.0 ** -52):
                    off = edge.copy()
                    off[:, j] *= hair
                    out.append(off)                           # just either side
    a, b = np.meshgrid(t, t)
    for axis in range(3):
        for sign in (1, -1):
            grid = np.zeros((a.size, 3))
            grid[:, axis] = sign
            grid[:, (axis + 1) % 3], grid[:, (axis + 2) % 3] = a.ravel(), b.ravel()
            out.append(grid)                                  # texel boundaries on each face
    return np.concatenate(out)


def colour_of_some_touching_face(actual, model_colours, touched):
    """The model colour, among the faces each direction touches, closest to
    actual (ASSIGNMENT.md: every touching face is a correct answer)."""
    distance = np.abs(model_colours - actual[:, None, :]).max(axis=2)
    distance[~touched] = np.inf
    return model_colours[np.arange(len(actual)), np.argmin(distance, axis=1)]


# ---- faces and (u, v) ------------------------------------------------------

def test_direction_to_face_picks_a_touching_face_and_the_table_uv(rng):
    dirs = np.concatenate([rng.normal(size=(100_000, 3)), seam_corner_axis_directions()])
    faces, uv = direction_to_face(dirs)
    touched = model.touching_faces(dirs)
    assert touched[np.arange(len(dirs)), faces].all(), "chose a face the direction does not touch"
    u, v = model.face_uv(dirs, faces)
    explain_mismatch("(u, v)", uv, np.stack([u, v], axis=1), dirs)


def test_ties_go_to_the_first_of_x_y_z():
    faces, _ = direction_to_face(np.array([[1, 1, 1], [-2, 2, -2], [0, -3, 3], [0, 0, -1], [5, -5, 0]], float))
    assert faces.tolist() == [0, 1, 3, 5, 0]


@pytest.mark.parametrize("bad", [
    (0, 0, 0), (-0.0, 0.0, -0.0), (np.nan, 1, 0), (1, np.nan, 0), (0, 0, np.nan),
    (np.inf, 0, 0), (0, -np.inf, 0), (1, 2, np.inf), (np.inf, np.inf, np.inf)])
def test_zero_nan_and_infinite_directions_have_no_face_and_are_black(cube, bad):
    dirs = np.array([bad], float)
    faces, uv = direction_to_face(dirs)
    assert faces[0] == -1 and uv[0].tolist() == [0.5, 0.5]
    for name in FILTERS:
        rgb, faces = CubeMap(cube).fetch_with_faces(dirs, name)
        assert faces[0] == -1 and rgb[0].tolist() == [0, 0, 0]


@pytest.mark.parametrize("filter", list(FILTERS))
def test_non_unit_lengths_give_the_unit_direction_answer(rng, cube, filter):
    dirs = rng.normal(size=(2000, 3))
    unit = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
    expected, expected_faces = CubeMap(cube).fetch_with_faces(unit, filter)
    for scale in [10.0 ** k for k in range(-30, 31, 5)] + [1e-300, 1e300, 1e-310]:
        rgb, faces = CubeMap(cube).fetch_with_faces(unit * scale, filter)
        assert (faces == expected_faces).all(), f"scale {scale}"
        explain_mismatch(f"scale {scale}", rgb, expected, unit * scale, rtol=1e-9, atol=1e-9)


def test_denormal_directions():
    tiny = 5e-324  # the smallest denormal: multiples of it are exact
    faces, uv = direction_to_face(np.array([[8 * tiny, 4 * tiny, -2 * tiny], [tiny, 0, 0]]))
    expected_faces, expected_uv = direction_to_face(np.array([[1.0, 0.5, -0.25], [1.0, 0, 0]]))
    assert faces.tolist() == expected_faces.tolist() == [0, 0]
    assert uv.tolist() == expected_uv.tolist()
    assert expected_uv.tolist() == [[(1 - 0.25) / 2, (1 + 0.5) / 2], [0.5, 0.5]]


# ---- the filters against the model -------------------------------------------

@pytest.mark.parametrize("filter", model.FILTERS)
@pytest.mark.parametrize("shape", [(SIDE, SIDE), (12, 7)])
def test_fetch_matches_the_model(rng, filter, shape):
    cube = random_cube(rng, *shape)
    dirs = np.concatenate([rng.normal(size=(100_000, 3)), seam_corner_axis_directions()])
    rgb = CubeMap(cube).fetch(dirs, filter)
    model_colours, touched = model.fetch_touching(cube, dirs, filter)
    explain_mismatch(f"{filter} fetch", rgb, colour_of_some_touching_face(rgb, model_colours, touched), dirs)


@pytest.mark.parametrize("filter", model.FILTERS)
def test_read_texture_matches_the_model(rng, cube, filter):
    n = 50_000
    faces = rng.integers(0, 6, n)
    uv = rng.uniform(0, 1, (n, 2))
    uv[: n // 2] = np.round(uv[: n // 2] * SIDE) / SIDE      # exactly on texel boundaries
    rgb = CubeMap(cube).read_texture(faces, uv, filter)
    explain_mismatch(f"{filter} read_texture", rgb, model.read_texture(cube, faces, uv[:, 0], uv[:, 1], filter),
                     extra=np.column_stack([faces, uv]))


def test_nearest_is_the_starting_code(rng, cube):
    n = 10_000
    faces = rng.integers(0, 6, n)
    uv = np.concatenate([rng.uniform(0, 1, (n // 2, 2)), rng.integers(0, SIDE + 1, (n // 2, 2)) / SIDE])
    x0 = np.clip((uv[:, 0] * SIDE).astype(int), 0, SIDE - 1)  # clamp((int)(u*W), 0, W-1)
    y0 = np.clip((uv[:, 1] * SIDE).astype(int), 0, SIDE - 1)
    rgb = CubeMap(cube).read_texture(faces, uv, "nearest")
    explain_mismatch("nearest", rgb, cube[faces, y0, x0], rtol=0, atol=0)


@pytest.mark.parametrize("filter", ["nearest", "bilinear"])
def test_read_texture_at_u_v_exactly_0_and_1(cube, filter):
    corners = {(0, 0): (0, 0), (1, 0): (0, SIDE - 1), (0, 1): (SIDE - 1, 0), (1, 1): (SIDE - 1, SIDE - 1)}
    for face in range(6):
        for (u, v), (y, x) in corners.items():
            rgb = CubeMap(cube).read_texture(face, np.array([[u, v]], float), filter)
            assert rgb[0].tolist() == cube[face, y, x].astype(float).tolist(), (face, u, v)


def test_bilinear_reproduces_linear_functions_inside_a_face(rng):
    y, x = np.mgrid[0:SIDE, 0:SIDE]
    slopes = [(3.0, -5.0, 100.0), (-0.5, 0.25, 7.0), (1.0, 1.0, 0.0), (0.0, -2.0, 64.0), (8.0, 0.0, -3.0), (2.0, 3.0, 1.0)]
    cube = np.stack([np.repeat((a * x + b * y + c)[..., None], 3, axis=2) for a, b, c in slopes]).astype(np.float32)
    n = 20_000
    faces = rng.integers(0, 6, n)
    uv = rng.uniform(0, (SIDE - 1) / SIDE, (n, 2))   # p = (uW, vH) in [0, W-1]: away from the clamped border
    a, b, c = np.array(slopes)[faces].T
    expected = a * uv[:, 0] * SIDE + b * uv[:, 1] * SIDE + c
    rgb = CubeMap(cube).read_texture(faces, uv, "bilinear")
    explain_mismatch("bilinear of a*x + b*y + c", rgb, np.repeat(expected[:, None], 3, axis=1),
                     extra=np.column_stack([faces, uv]), rtol=1e-13, atol=1e-12)


def test_read_texture_clamps_u_v_and_reads_nan_as_the_centre(cube):
    faces = np.zeros(6, np.int32)
    strange = np.array([[np.nan, 0.3], [0.3, np.nan], [-5, 0.3], [7, 0.3], [-np.inf, np.inf], [np.nan, np.nan]])
    tame = np.array([[0.5, 0.3], [0.3, 0.5], [0, 0.3], [1, 0.3], [0, 1], [0.5, 0.5]])
    for name in FILTERS:
        explain_mismatch(name, CubeMap(cube).read_texture(faces, strange, name),
                         CubeMap(cube).read_texture(faces, tame, name), rtol=0, atol=0)


def test_bad_faces_and_filters_read_black(cube):
    ffi, lib = library()
    rgb = ffi.new("double[3]", [1, 1, 1])
    for face in (-1, 6, 1 << 30, -(1 << 31)):
        lib.em_read_texture(CubeMap(cube).c, 1, face, 0.5, 0.5, rgb)
        assert list(rgb) == [0, 0, 0]
    lib.em_fetch(CubeMap(cube).c, 7, 1.0, 0.0, 0.0, rgb)
    assert list(rgb) == [0, 0, 0]


def test_single_lookups_and_the_lookup_fn_agree_with_the_batch(rng, cube):
    ffi, lib = library()
    dirs = rng.normal(size=(64, 3))
    cubemap = CubeMap(cube)
    for name, code in FILTERS.items():
        batch = cubemap.fetch(dirs, name)
        rgb = ffi.new("double[3]")
        single = []
        for x, y, z in dirs:
            lib.em_fetch(cubemap.c, code, x, y, z, rgb)
            single.append(list(rgb))
        explain_mismatch(f"{name} em_fetch", np.array(single), batch, dirs, rtol=0, atol=0)
        context = ffi.new("em_cubemap_lookup *", {"cube": cubemap.c, "filter": code})
        out = np.empty((len(dirs), 3))
        status = lib.em_cubemap_lookup_fn(context, ffi.cast("double *", ffi.from_buffer(dirs)), len(dirs),
                                          ffi.cast("double *", ffi.from_buffer(out)))
        assert status == 0
        explain_mismatch(f"{name} em_cubemap_lookup_fn", out, batch, dirs, rtol=0, atol=0)
    assert lib.em_cubemap_lookup_fn(ffi.NULL, ffi.NULL, 0, ffi.NULL) != 0


# ---- seamless ------------------------------------------------------------------

def edge_crossings():
    """For each of the 12 edges: unit directions along it and a unit vector
    across it, from the face of axis i to the face of axis j."""
    t = np.linspace(-0.999, 0.999, 401)
    for i, j in ((0, 1), (0, 2), (1, 2)):
        k = 3 - i - j
        for si in (1, -1):
            for sj in (1, -1):
                edge = np.zeros((len(t), 3))
                edge[:, i], edge[:, j], edge[:, k] = si, sj, t
                across = np.zeros(3)
                across[i], across[j] = si, -sj
                yield (i, si, j, sj), edge / np.linalg.norm(edge, axis=1, keepdims=True), across / np.sqrt(2)


def largest_jump_across_edges(cubemap: CubeMap, filter: str) -> float:
    largest = 0.0
    for (i, si, j, sj), edge, across in edge_crossings():
        inside_i = edge + EPSILON_ANGLE * across
        inside_j = edge - EPSILON_ANGLE * across
        a, faces_i = cubemap.fetch_with_faces(inside_i, filter)
        b, faces_j = cubemap.fetch_with_faces(inside_j, filter)
        assert (faces_i == 2 * i + (si < 0)).all() and (faces_j == 2 * j + (sj < 0)).all()
        largest = max(largest, float(np.abs(a - b).max()))
    return largest


def test_seamless_is_continuous_across_all_12_edges_and_bilinear_is_not(cube):
    cubemap = CubeMap(cube)
    assert largest_jump_across_edges(cubemap, "seamless") < SEAMLESS_JUMP_BOUND
    assert largest_jump_across_edges(cubemap, "bilinear") > 0.05


def test_seamless_at_the_8_corners_is_the_average_of_the_three_corner_texels(cube):
    cubemap = CubeMap(cube)
    for corner in np.array([[sx, sy, sz] for sx in (1, -1) for sy in (1, -1) for sz in (1, -1)], float):
        faces = [2 * axis + (corner[axis] < 0) for axis in range(3)]
        u, v = model.face_uv(np.repeat(corner[None], 3, axis=0), np.array(faces))
        corner_texels = model.read_texture(cube, faces, u, v, "nearest")
        expected = corner_texels.mean(axis=0)
        approaches = [corner.copy() for _ in range(3)]
        for axis, d in enumerate(approaches):
            d[axis] *= 1 + EPSILON_ANGLE       # just inside the face of this axis
        dirs = np.array([corner] + approaches)
        rgb, got_faces = cubemap.fetch_with_faces(dirs, "seamless")
        assert got_faces[1:].tolist() == faces
        explain_mismatch(f"seamless near corner {corner}", rgb, np.repeat(expected[None], 4, axis=0), dirs,
                         rtol=0, atol=SEAMLESS_JUMP_BOUND)


def test_seamless_inside_a_face_is_bilinear_on_texel_centres(rng, cube):
    n = 20_000
    faces = rng.integers(0, 6, n)
    uv = rng.uniform(0.5 / SIDE, 1 - 0.5 / SIDE, (n, 2))   # texel-centre lattice, no neighbour needed
    rgb = CubeMap(cube).read_texture(faces, uv, "seamless")
    shifted = uv - 0.5 / SIDE
    explain_mismatch("seamless inside a face", rgb, model.read_texture(cube, faces, shifted[:, 0], shifted[:, 1]),
                     extra=np.column_stack([faces, uv]))


@pytest.mark.parametrize("shape", [(1, 1), (1, 5), (5, 1), (12, 7), (2, 2)])
def test_every_filter_blends_texels_on_tiny_and_non_square_faces(rng, shape):
    cube = random_cube(rng, *shape, low=0.25, high=1.0)
    dirs = np.concatenate([rng.normal(size=(20_000, 3)), seam_corner_axis_directions()])
    for name in FILTERS:
        rgb = CubeMap(cube).fetch(dirs, name)
        assert ((rgb >= 0.25 - 1e-12) & (rgb <= 1 + 1e-12)).all(), name   # convex combinations of texels
    if shape == (1, 1):   # one texel per face: nearest and bilinear read it whatever (u, v)
        faces, _ = direction_to_face(dirs)
        for name in model.FILTERS:
            explain_mismatch(name, CubeMap(cube).fetch(dirs, name), cube[faces, 0, 0], dirs, rtol=1e-15, atol=0)


# ---- hostile input -------------------------------------------------------------------

GUARDED_GARBAGE = textwrap.dedent("""
    # Random bytes as directions, faces and (u, v), over a cube map that sits
    # between two inaccessible pages: a read outside it is a crash.
    import ctypes, mmap, sys
    import numpy as np
    from grader.envmap.library import CubeMap, FILTERS

    page = mmap.PAGESIZE
    side = 32                                   # 6*32*32*3 floats = 18 pages of 4 KiB
    size = 6 * side * side * 3 * 4
    assert size % page == 0
    region = mmap.mmap(-1, size + 2 * page)
    libc = ctypes.CDLL(None, use_errno=True)
    libc.mprotect.argtypes = (ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int)
    base = ctypes.addressof(ctypes.c_char.from_buffer(region))
    for start in (base, base + page + size):
        assert libc.mprotect(start, page, 0) == 0, ctypes.get_errno()
    faces = np.frombuffer(region, np.float32, 6 * side * side * 3, page).reshape(6, side, side, 3)
    rng = np.random.default_rng(7)
    faces[...] = rng.uniform(0.25, 1.0, faces.shape)
    cube = CubeMap(faces)
    assert cube.faces.ctypes.data == base + page      # no copy: the guarded memory itself

    n = 1_000_000
    dirs = np.frombuffer(rng.bytes(8 * 3 * n), np.float64).reshape(n, 3).copy()
    dirs[::7] = rng.normal(size=dirs[::7].shape) * 10.0 ** rng.integers(-300, 300, (len(dirs[::7]), 1))
    face_ids = np.frombuffer(rng.bytes(4 * n), np.int32).copy()
    face_ids[::2] = rng.integers(-1, 7, len(face_ids[::2]))
    uv = np.frombuffer(rng.bytes(8 * 2 * n), np.float64).reshape(n, 2).copy()
    uv[::3] = rng.uniform(-0.5, 1.5, uv[::3].shape)
    for name in FILTERS:
        rgb, got = cube.fetch_with_faces(dirs, name)
        assert ((got >= -1) & (got <= 5)).all()
        assert ((rgb == 0).all(axis=1) == (got == -1)).all(), name
        assert ((rgb >= 0.25 - 1e-12) & (rgb <= 1 + 1e-12) | (got == -1)[:, None]).all(), name  # convex combinations
        rgb = cube.read_texture(face_ids, uv, name)
        valid = (face_ids >= 0) & (face_ids <= 5)
        assert (rgb[~valid] == 0).all() and ((rgb[valid] >= 0.25 - 1e-12) & (rgb[valid] <= 1 + 1e-12)).all(), name
    print("ok")
""")


def test_random_garbage_never_reads_outside_the_cube_map(tmp_path):
    script = tmp_path / "garbage.py"
    script.write_text(GUARDED_GARBAGE)
    done = subprocess.run([sys.executable, str(script)], cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": str(PROJECT_ROOT)})
    assert done.returncode == 0 and done.stdout.strip() == "ok", (
        f"exit status {done.returncode} (negative: killed by that signal)\n{done.stderr[-3000:]}")


# ---- python -m grader lookup ------------------------------------------------------------

def run_lookup_command(args, stdin: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "grader", "lookup", *args], input=stdin, cwd=PROJECT_ROOT,
                          capture_output=True, text=True, timeout=120)


@pytest.fixture
def cross_file(tmp_path, cube):
    from grader.envmap.library import faces_to_cross, write_hdr
    path = tmp_path / "cube_cross.hdr"
    write_hdr(path, faces_to_cross(cube))
    return path


@pytest.mark.parametrize("filter", list(FILTERS))
def test_lookup_command_prints_the_reference_colours(rng, cross_file, filter):
    dirs = np.concatenate([rng.normal(size=(200, 3)), [[0, 0, 0], [1, 1, 1]]])
    stdin = "".join(f"{x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in dirs)
    done = run_lookup_command(["--map", str(cross_file), "--filter", filter], stdin)
    assert done.returncode == 0, done.stderr
    printed = np.array([[float(w) for w in line.split()] for line in done.stdout.splitlines()])
    expected = CubeMap.load_cross(cross_file).fetch(dirs, filter)   # the map as the reader decodes it
    explain_mismatch("python -m grader lookup", printed, expected, dirs, rtol=1e-8, atol=0)


def test_lookup_command_names_the_bad_line(cross_file):
    done = run_lookup_command(["--map", str(cross_file)], "1 0 0\n0 1 0\n0 1\n0 0 1\n")
    assert done.returncode != 0 and done.stdout == ""
    assert "line 3" in done.stderr
    done = run_lookup_command(["--map", str(cross_file)], "1 0 0\n1 zero 0\n")
    assert done.returncode != 0 and "line 2" in done.stderr and "zero" in done.stderr


def test_lookup_command_reports_a_missing_map(tmp_path):
    done = run_lookup_command(["--map", str(tmp_path / "missing.hdr")], "1 0 0\n")
    assert done.returncode != 0 and "missing.hdr" in done.stderr
