"""The reference renderer (reference/src/render.c): determinism, trace +
resolve == render, and the optics checked against values this file computes
on its own (mirror reflection, Fresnel, Snell, total internal reflection,
energy conservation).

Environments here are cube maps with constant faces, so a lookup's colour
depends only on the face a direction exits through (the largest component,
ASSIGNMENT.md); the texel conventions do not matter."""
from __future__ import annotations

import numpy as np
import pytest

from grader import PROJECT_ROOT
from grader.envmap.library import EnvmapError, Escapes, CubeMap, Scene

# Distinct colours for faces +X -X +Y -Y +Z -Z.
FACE_COLOURS = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1],
                         [1, 1, 0], [0, 1, 1], [1, 0, 1]], np.float32) * 0.75 + 0.125
POS_Z, NEG_Z = 4, 5


def constant_faces(colours) -> CubeMap:
    colours = np.broadcast_to(np.asarray(colours, np.float32), (6, 3))
    return CubeMap(np.broadcast_to(colours[:, None, None, :], (6, 4, 4, 3)).copy())


def face_of(d: np.ndarray) -> np.ndarray:
    """The face each direction (n, 3) exits through, computed here."""
    axis = np.argmax(np.abs(d), axis=1)
    negative = d[np.arange(len(d)), axis] < 0
    return 2 * axis + negative


def scene(body: str, width: int, height: int, spp: int) -> Scene:
    s = Scene.parse(body + '\nenvironment_light { filename = "unused.hdr"; }\n', "t.cfg")
    s.set_resolution(width, height)
    s.set_samples(spp)
    return s


def camera_rays(position, look_at, fov_degrees, width, height, sub):
    """Unit ray directions (height, width, len(sub), 3) through the points
    `sub` ((x, y) in [0, 1]^2, y down) of every pixel: a pinhole camera with a
    vertical field of view, y = 0 the top row, up = +y."""
    position, look_at = np.asarray(position, float), np.asarray(look_at, float)
    forward = (look_at - position) / np.linalg.norm(look_at - position)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    t = np.tan(np.radians(fov_degrees) / 2)
    ys, xs = np.mgrid[0:height, 0:width]
    sub = np.asarray(sub, float)
    fx = (2 * (xs[..., None] + sub[:, 0]) / width - 1) * t * width / height
    fy = (1 - 2 * (ys[..., None] + sub[:, 1]) / height) * t
    d = forward + fx[..., None] * right + fy[..., None] * up
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def mirror_ball_escape(origin, d, radius=1.0):
    """Where rays from origin leave a mirror ball at the world origin: the
    reflected direction where they hit it, else the ray itself."""
    b = d @ origin
    disc = b * b - (origin @ origin - radius * radius)
    hit = disc > 0
    t = -b - np.sqrt(np.where(hit, disc, 0))
    n = (origin + t[..., None] * d) / radius
    reflected = d - 2 * np.sum(d * n, axis=-1, keepdims=True) * n
    return np.where(hit[..., None], reflected, d), hit


# ---- determinism and the two-step render -------------------------------------------

MAIN = PROJECT_ROOT / "envmap_test.cfg"


def test_renders_are_identical_run_to_run():
    cube = CubeMap(np.random.default_rng(1).random((6, 8, 8, 3), dtype=np.float32))
    images = []
    for _ in range(2):
        s = Scene.load(MAIN)
        s.set_resolution(40, 40)
        s.set_samples(4)
        images.append(s.render(cube))
    assert images[0].tobytes() == images[1].tobytes()
    assert images[0].tobytes() == s.render(cube).tobytes()


@pytest.mark.parametrize("hdr_gamma", [1.0, 2.2])
def test_trace_then_resolve_equals_render_exactly(hdr_gamma):
    """At 72 x 64 x 16 the scene has more than one 65536-escape lookup batch."""
    text = MAIN.read_text().replace("hdr_gamma = 1.0", f"hdr_gamma = {hdr_gamma}")
    s = Scene.parse(text, "envmap_test.cfg", str(PROJECT_ROOT))
    s.set_resolution(72, 64)
    s.set_samples(16)
    cube = CubeMap(np.random.default_rng(2).random((6, 8, 8, 3), dtype=np.float32) * 4)
    escapes = s.trace()
    assert len(escapes.dirs) > 2 * 65536
    np.testing.assert_allclose(np.linalg.norm(escapes.dirs, axis=1), 1.0, atol=1e-12)
    assert escapes.resolve(cube.fetch(escapes.dirs)).tobytes() == s.render(cube).tobytes()


def test_resolve_applies_hdr_gamma_and_sums_per_pixel():
    e = Escapes(dirs=np.zeros((3, 3)), weights=np.array([[0.5, 1, 2], [0.25, 0.25, 0.25], [1, 1, 1]]),
                pixels=np.array([1, 1, 0], np.uint32), width=2, height=1, hdr_gamma=2.0)
    image = e.resolve(np.array([[2.0, 3, 0.5], [4, 4, 4], [-1, 0, 1]]))
    np.testing.assert_allclose(image[0, 1], [0.5 * 4 + 0.25 * 16, 9 + 4, 0.5 + 4])
    np.testing.assert_allclose(image[0, 0], [0, 0, 1])   # colours <= 0 give 0 when hdr_gamma != 1


def test_resolve_refuses_pixels_outside_the_image():
    e = Escapes(np.zeros((1, 3)), np.ones((1, 3)), np.array([6], np.uint32), 3, 2, 1.0)
    with pytest.raises(EnvmapError, match="pixel 6 outside the 3 x 2 image"):
        e.resolve(np.ones((1, 3)))


def test_samples_are_jittered_on_a_grid_in_each_pixel():
    """With no spheres every sample escapes along its camera ray; mapping the
    ray back to the film shows one sample per cell of an m x (spp/m) grid."""
    for spp, columns in ((16, 4), (6, 2), (7, 1), (1, 1)):
        s = scene("camera { fov = 90; }", 1, 1, spp)
        d = s.trace().dirs
        assert len(d) == spp
        x = (d[:, 0] / -d[:, 2] + 1) / 2          # [0, 1) across the pixel
        y = (1 - d[:, 1] / -d[:, 2]) / 2          # [0, 1) down the pixel
        cells = np.floor(x * columns).astype(int) + columns * np.floor(y * (spp // columns)).astype(int)
        assert sorted(cells) == list(range(spp)), spp
    centres = scene("camera { fov = 90; }", 1, 1, 1)
    other_seed = Scene.parse('camera { fov = 90; }\nsampling { seed = 9; }\nenvironment_light { filename = "u"; }')
    other_seed.set_resolution(1, 1)
    other_seed.set_samples(1)
    assert not np.array_equal(centres.trace().dirs, other_seed.trace().dirs)


# ---- the background and mirrors ---------------------------------------------------------

SUB = [(a, b) for a in (0.01, 0.5, 0.99) for b in (0.01, 0.5, 0.99)]


def test_a_mirror_ball_reflects_the_faces_computed_independently():
    """Camera on +z looking at a mirror ball: every pixel whose 3 x 3 probe
    rays (computed here) all leave through one face shows that face's colour;
    the centre pixel looks back along the camera axis (+Z)."""
    w = h = 33
    s = scene("camera { position = (0, 0, 5); look_at = (0, 0, 0); fov = 40; }\n"
              'sphere { center = (0, 0, 0); radius = 1; material = "mirror"; }', w, h, 16)
    image = s.render(constant_faces(FACE_COLOURS))
    d = camera_rays([0, 0, 5], [0, 0, 0], 40, w, h, SUB)
    out, _ = mirror_ball_escape(np.array([0.0, 0, 5]), d)
    faces = face_of(out.reshape(-1, 3)).reshape(h, w, len(SUB))
    certain = np.all(faces == faces[..., :1], axis=-1)
    assert certain.mean() > 0.8
    assert set(np.unique(faces[certain][:, 0])) == set(range(6))
    np.testing.assert_allclose(image[certain], FACE_COLOURS[faces[certain][:, 0]], atol=1e-6)
    np.testing.assert_allclose(image[h // 2, w // 2], FACE_COLOURS[POS_Z], atol=1e-6)


def test_the_background_is_the_environment_in_the_view_direction():
    """No spheres, a 120 degree view down -z: background pixels show the face
    their rays leave through (-Z ahead, +-X and +-Y at the sides)."""
    w = h = 24
    s = scene("camera { fov = 120; }", w, h, 4)
    image = s.render(constant_faces(FACE_COLOURS))
    d = camera_rays([0, 0, 0], [0, 0, -1], 120, w, h, SUB)
    faces = face_of(d.reshape(-1, 3)).reshape(h, w, len(SUB))
    certain = np.all(faces == faces[..., :1], axis=-1)
    assert set(np.unique(faces[certain][:, 0])) == {0, 1, 2, 3, NEG_Z}
    np.testing.assert_allclose(image[certain], FACE_COLOURS[faces[certain][:, 0]], atol=1e-6)


def test_a_constant_environment_renders_its_colour_through_mirrors():
    colour = [0.2, 0.5, 0.9]
    s = Scene.load(MAIN)
    s.set_resolution(48, 48)
    s.set_samples(4)
    text = MAIN.read_text().replace('material = "glass";\n    ior = 1.5;', 'material = "mirror";')
    mirrors = Scene.parse(text, "envmap_test.cfg")
    mirrors.set_resolution(48, 48)
    mirrors.set_samples(4)
    np.testing.assert_allclose(mirrors.render(constant_faces(colour)), np.broadcast_to(colour, (48, 48, 3)),
                               rtol=1e-6)


def test_hdr_gamma_raises_the_environment_to_its_power():
    s = Scene.parse('camera { width = 4; height = 3; }\n'
                    'environment_light { filename = "u"; hdr_gamma = 2.0; }')
    np.testing.assert_allclose(s.render(constant_faces([0.5, 0.25, 2.0])),
                               np.broadcast_to([0.25, 0.0625, 4.0], (3, 4, 3)), rtol=1e-6)


def test_mirror_tint_multiplies_the_reflection():
    """The ball fills the view (its angular radius 19.5 degrees > the half field of view)."""
    s = scene('camera { position = (0, 0, 3); look_at = (0, 0, 0); fov = 20; }\n'
              'sphere { center = (0, 0, 0); radius = 1; material = "mirror"; tint = (0.5, 1, 0.25); }', 8, 8, 4)
    np.testing.assert_allclose(s.render(constant_faces([1, 1, 1])),
                               np.broadcast_to([0.5, 1, 0.25], (8, 8, 3)), rtol=1e-6)


def test_paths_deeper_than_max_depth_are_black():
    w = h = 16
    body = ("camera { position = (0, 0, 5); look_at = (0, 0, 0); fov = 40; }\n"
            "sampling { max_depth = 0; }\n"
            'sphere { center = (0, 0, 0); radius = 1; material = "mirror"; }')
    image = scene(body, w, h, 4).render(constant_faces([1, 1, 1]))
    d = camera_rays([0, 0, 5], [0, 0, 0], 40, w, h, SUB)
    _, hit = mirror_ball_escape(np.array([0.0, 0, 5]), d)
    assert np.all(image[hit.all(axis=-1)] == 0) and hit.all(axis=-1).sum() > 20
    assert np.all(image[~hit.any(axis=-1)] == 1)


# ---- glass ----------------------------------------------------------------------------

def fresnel(cos_i: float, n1: float, n2: float) -> float:
    """Unpolarised reflectance at a dielectric boundary (Hecht, Optics, 4.34 and 4.40)."""
    sin_t = n1 / n2 * np.sqrt(1 - cos_i ** 2)
    if sin_t >= 1:
        return 1.0
    cos_t = np.sqrt(1 - sin_t ** 2)
    rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t)
    rp = (n1 * cos_t - n2 * cos_i) / (n1 * cos_t + n2 * cos_i)
    return (rs * rs + rp * rp) / 2


def test_glass_seen_head_on_splits_by_fresnel_at_normal_incidence():
    """On the axis every path leaves along +z (back) or -z (through). With
    R = ((n-1)/(n+1))^2 the series of internal reflections sums to
    2R/(1+R) back and (1-R)/(1+R) through."""
    s = scene("camera { position = (0, 0, 5); look_at = (0, 0, 0); fov = 0.0001; }\n"
              'sphere { center = (0, 0, 0); radius = 1; material = "glass"; ior = 1.5; }', 1, 1, 1)
    colours = np.zeros((6, 3))
    colours[POS_Z], colours[NEG_Z] = [1, 0, 0], [0, 1, 0]
    r = ((1.5 - 1) / (1.5 + 1)) ** 2
    np.testing.assert_allclose(s.render(constant_faces(colours))[0, 0], [2 * r / (1 + r), (1 - r) / (1 + r), 0],
                               atol=1e-5)


def test_glass_off_axis_follows_snell_and_fresnel():
    """A ray along -z at height h = sin(theta_i) above the centre of a unit
    glass ball: the first reflection leaves along (0, sin 2theta_i, cos
    2theta_i) with weight R(theta_i); the ray refracted in and out leaves
    turned by 2(theta_i - theta_t) towards the axis, weight (1-R_in)(1-R_out)."""
    h, ior = 0.6, 1.5
    s = scene(f"camera {{ position = (0, {h}, 1000); look_at = (0, {h}, 0); fov = 1e-9; }}\n"
              f'sphere {{ center = (0, 0, 0); radius = 1; material = "glass"; ior = {ior}; }}', 1, 1, 1)
    e = s.trace()
    theta_i = np.arcsin(h)
    theta_t = np.arcsin(h / ior)
    r_in = fresnel(np.cos(theta_i), 1.0, ior)
    r_out = fresnel(np.cos(theta_t), ior, 1.0)
    deviation = 2 * (theta_i - theta_t)
    expected = {
        "reflected": ((0, np.sin(2 * theta_i), np.cos(2 * theta_i)), r_in),
        "through": ((0, -np.sin(deviation), -np.cos(deviation)), (1 - r_in) * (1 - r_out)),
    }
    for name, (direction, weight) in expected.items():
        closest = np.argmin(np.linalg.norm(e.dirs - direction, axis=1))
        np.testing.assert_allclose(e.dirs[closest], direction, atol=1e-6, err_msg=name)
        np.testing.assert_allclose(e.weights[closest], [weight] * 3, rtol=1e-6, err_msg=name)
    assert abs(e.weights.sum(axis=0) - 1).max() < 1e-5    # what is not reflected is transmitted


def test_total_internal_reflection_traps_rays_in_glass():
    """A camera inside a glass ball (radius 2) at height 1.9, looking along
    -z, meets the surface at 71.8 degrees, beyond the critical angle
    asin(1/1.5) = 41.8: every hit reflects fully, so no path escapes before
    max_depth and the pixel is black. At height 0.5 (14.5 degrees) light leaves."""
    def pixel(height):
        return scene(f"camera {{ position = (0, {height}, 0); look_at = (0, {height}, -1); fov = 0.0001; }}\n"
                     'sphere { center = (0, 0, 0); radius = 2; material = "glass"; ior = 1.5; }', 1, 1, 1)
    assert len(pixel(1.9).trace().dirs) == 0
    assert np.all(pixel(1.9).render(constant_faces([1, 1, 1])) == 0)
    assert pixel(0.5).render(constant_faces([1, 1, 1]))[0, 0, 0] > 0.99


@pytest.mark.parametrize("max_depth, bound", [(64, 3e-4), (32, 1e-3)])
def test_glass_conserves_energy_in_a_white_environment(max_depth, bound):
    """Fresnel splits sum to 1, so with white tints and a white environment
    every pixel is 1 less what the depth limit and the negligible-branch
    cut drop. Measured on envmap_test.cfg at 64 x 64 x 16: largest loss
    1.7e-4 at max_depth 64, 6.9e-4 at 32 (the default), 1.6e-3 at 16, at
    the glass ball's rim, where grazing rays reflect inside it many times."""
    text = MAIN.read_text().replace("max_depth = 32;", f"max_depth = {max_depth};")
    s = Scene.parse(text, "envmap_test.cfg")
    s.set_resolution(64, 64)
    s.set_samples(16)
    image = s.render(constant_faces([1, 1, 1]))
    assert image.max() <= 1 + 1e-6
    assert 1 - image.min() < bound


# ---- writing renders: `python -m grader render` and grader.envmap.imaging ----------------------

def write_constant_cross(path, colours):
    """A vertical cross whose faces are constant colours (exact in RGBE)."""
    from grader.envmap.library import faces_to_cross, write_hdr
    write_hdr(path, faces_to_cross(constant_faces(colours).faces))


def test_the_render_command_writes_what_the_reference_renders(tmp_path, capsys):
    from grader.cli import main
    from grader.envmap.imaging import read_image, to_8bit, tone_map
    colours = np.array([[0.5, 0.25, 1], [1, 2, 4], [0.125, 0.5, 0.5], [3, 1, 0.5], [0.75, 0.75, 0.25], [2, 0.5, 1]])
    (tmp_path / "maps").mkdir()
    write_constant_cross(tmp_path / "maps" / "m_cross.hdr", colours)
    text = MAIN.read_text().replace("Cubemap/test_environment_map.hdr", "maps/m_cross.hdr")
    (tmp_path / "s.cfg").write_text(text)
    expected = Scene.load(tmp_path / "s.cfg")
    expected.set_resolution(20, 10)
    expected.set_samples(4)
    image = expected.render(CubeMap.load_cross(tmp_path / "maps" / "m_cross.hdr"))

    for name in ("r.exr", "r.png"):
        assert main(["render", str(tmp_path / "s.cfg"), "--out", str(tmp_path / name),
                     "--width", "20", "--height", "10", "--spp", "4"]) == 0
    assert read_image(tmp_path / "r.exr").tobytes() == image.tobytes()
    assert np.array_equal(np.round(read_image(tmp_path / "r.png") * 255), to_8bit(tone_map(image)))
    assert "r.png (20 x 10" in capsys.readouterr().out

    # One side given keeps the scene's aspect ratio (512 x 512).
    assert main(["render", str(tmp_path / "s.cfg"), "--out", str(tmp_path / "w.exr"), "--width", "6", "--spp", "1"]) == 0
    assert read_image(tmp_path / "w.exr").shape == (6, 6, 3)


def test_the_render_command_reports_errors(tmp_path, capsys):
    from grader.cli import main
    (tmp_path / "s.cfg").write_text("sphere { radus = 1; }\n")
    assert main(["render", str(tmp_path / "s.cfg"), "--out", str(tmp_path / "r.png")]) == 1
    assert f"{tmp_path / 's.cfg'}:1: unknown key 'radus' in sphere" in capsys.readouterr().err
    (tmp_path / "t.cfg").write_text('environment_light { filename = "missing_cross.hdr"; }\n')
    assert main(["render", str(tmp_path / "t.cfg"), "--out", str(tmp_path / "r.png")]) == 1
    assert "missing_cross.hdr" in capsys.readouterr().err


def test_tone_map_is_reinhard_then_srgb():
    from grader.envmap.imaging import tone_map
    linear = np.array([[[0.0, 1.0, 3.0], [-1.0, np.nan, np.inf], [0.5, 0.002, 1e9]]], np.float32)
    # Worked by hand: 1 -> 1/2 -> 1.055 * 0.5^(1/2.4) - 0.055 = 0.73536;
    # 3 -> 3/4 -> 0.88083; 0.002 -> 0.001996 -> 12.92 * 0.001996 = 0.025790.
    np.testing.assert_allclose(tone_map(linear)[0, 0], [0, 0.73536, 0.88083], atol=2e-5)
    np.testing.assert_allclose(tone_map(linear)[0, 1], [0, 0, 1], atol=1e-6)
    np.testing.assert_allclose(tone_map(linear)[0, 2, 1], 0.025790, atol=2e-5)
    # One stop up doubles the linear value first.
    np.testing.assert_allclose(tone_map(linear[:, 2:, :1], exposure=1.0), tone_map(linear[:, :1, 1:2]), atol=1e-6)
    assert tone_map(linear).dtype == np.float32 and 0 <= tone_map(linear).min() and tone_map(linear).max() <= 1


def test_images_round_trip_through_their_files(tmp_path):
    from grader.envmap.imaging import read_image, to_8bit, write_image
    image = np.random.default_rng(3).random((5, 7, 3), dtype=np.float32) * 8
    write_image(tmp_path / "a.exr", image)
    assert read_image(tmp_path / "a.exr").tobytes() == image.tobytes()
    write_image(tmp_path / "a.hdr", image)
    # RGBE: 8-bit mantissas under the pixel's largest channel's exponent.
    error = np.abs(read_image(tmp_path / "a.hdr") - image)
    assert np.all(error <= image.max(axis=2, keepdims=True) * 2 ** -7)
    display = np.linspace(0, 1, 105, dtype=np.float32).reshape(5, 7, 3)
    write_image(tmp_path / "d.png", display, display_referred=True)
    assert np.array_equal(np.round(read_image(tmp_path / "d.png") * 255), to_8bit(display))
    with pytest.raises(ValueError, match="unsupported"):
        write_image(tmp_path / "a.jpg", image)
