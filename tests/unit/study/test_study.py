"""The study (grader/study/): the bake, the seam measurements, and a small run."""
from __future__ import annotations

import csv

import numpy as np
import pytest

from grader.envmap.library import CubeMap, direction_to_face
from grader.study import chart, failure_map
from grader.study.bake import bake, bake_error
from grader.envmap.geometry import face_uv_to_direction, texel_centre_uv
from grader.study.ground_truth import DEFAULT_ENVIRONMENT, SMOOTH_ENVIRONMENT
from grader.study.methods import numpy_bilinear


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("study-cache")


def texel_centres(size: int) -> np.ndarray:
    """Unit directions (6, N, N, 3) float64 through texel centres, [face, y, x]."""
    u, v = texel_centre_uv(size, size)
    return np.stack([face_uv_to_direction(f, u, v) for f in range(6)])


def test_bake_converges_to_the_smooth_environment_at_second_order(cache):
    """A texel's solid-angle average differs from the radiance at its centre by
    O(h^2) (the centroid offset and the curvature term are both second order),
    so doubling the face size divides the largest difference by about 4."""
    errors = []
    for size in (8, 16, 32, 64):
        faces = bake(SMOOTH_ENVIRONMENT, size, cache_dir=cache).astype(np.float64)
        errors.append(np.abs(faces - SMOOTH_ENVIRONMENT.radiance(texel_centres(size))).max())
    rates = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((rates > 1.8) & (rates < 2.2)), (errors, rates)


def test_bake_is_the_solid_angle_average_of_the_radiance(cache):
    """Independent check of the weighting: directions uniform on the sphere are
    solid-angle weighted by construction, so their mean radiance per texel
    (binned with the reference C's face choice) must match the bake."""
    size = 4
    rng = np.random.default_rng(11)
    dirs = rng.normal(size=(1_500_000, 3))
    face, uv = direction_to_face(dirs)
    x = np.minimum((uv[:, 0] * size).astype(int), size - 1)
    y = np.minimum((uv[:, 1] * size).astype(int), size - 1)
    index = (face * size + y) * size + x
    radiance = SMOOTH_ENVIRONMENT.radiance(dirs)
    count = np.bincount(index, minlength=6 * size * size)
    mean = np.stack([np.bincount(index, radiance[:, c], 6 * size * size) for c in range(3)], 1) / count[:, None]
    sq = np.stack([np.bincount(index, radiance[:, c] ** 2, 6 * size * size) for c in range(3)], 1) / count[:, None]
    stderr = np.sqrt(np.maximum(sq - mean ** 2, 0) / count[:, None])
    baked = bake(SMOOTH_ENVIRONMENT, size, cache_dir=cache).reshape(-1, 3)
    assert np.all(np.abs(baked - mean) < 5 * stderr + 1e-6)


def test_bake_error_is_far_below_lookup_error(cache):
    """Against a finer bake: smooth texels agree to float precision; texels on
    the sun rim or horizon within 0.05 (the sun's contrast is 20, and a
    lookup next to it is wrong by a large share of that)."""
    err = bake_error(DEFAULT_ENVIRONMENT, 16, cache_dir=cache)
    assert err["max_smooth"] < 1e-5
    assert err["max_feature"] < 0.05 and err["rms_feature"] < 0.01


def test_seam_jump_measures_a_planted_seam():
    """A map constant except face +X (1 brighter): for nearest, every edge of
    +X jumps by exactly 1 and no other edge moves."""
    faces = np.full((6, 8, 8, 3), 0.5, np.float32)
    faces[0] += 1.0
    jumps = failure_map.seam_jump(faces, "nearest")
    assert len(jumps) == 12
    for name, jump in jumps.items():
        expected = 1.0 if "+X" in name.split("/") else 0.0
        assert jump == pytest.approx(expected, abs=1e-12), name
    corners = failure_map.corner_jump(faces, "nearest")
    assert len(corners) == 8
    assert all(v == pytest.approx(1.0 if k[0] == "+" else 0.0) for k, v in corners.items())


def test_seamless_is_continuous_across_every_edge_and_bilinear_is_not(cache):
    """Stated bound: across each edge and corner, seamless moves by at most
    SEAMLESS_TOLERANCE (1e-6) times the largest texel; the handout's bilinear
    (per-face clamp, texel x at u = x/W) jumps at every edge of a smooth map."""
    faces = bake(SMOOTH_ENVIRONMENT, 16, cache_dir=cache)
    bound = failure_map.SEAMLESS_TOLERANCE * float(faces.max())
    assert max(failure_map.seam_jump(faces, "seamless").values()) <= bound
    assert max(failure_map.corner_jump(faces, "seamless").values()) <= bound
    bilinear = failure_map.seam_jump(faces, "bilinear")
    assert all(jump > 100 * bound for jump in bilinear.values()), bilinear


def test_degenerate_directions_give_black_in_the_reference(cache):
    faces = bake(SMOOTH_ENVIRONMENT, 8, cache_dir=cache)
    outcome = failure_map.degenerate_behaviour(faces, "bilinear")
    for name in ("zero", "NaN", "+inf", "inf, inf"):
        assert outcome[name] == "black", name
    assert outcome["denormal"] == "as normalised"


def test_numpy_peer_is_the_handout_bilinear(cache):
    faces = bake(DEFAULT_ENVIRONMENT, 16, cache_dir=cache)
    dirs = np.random.default_rng(5).normal(size=(20000, 3))
    np.testing.assert_allclose(numpy_bilinear(faces, dirs), CubeMap(faces).fetch(dirs, "bilinear"),
                               rtol=1e-12, atol=1e-12)


def test_pareto_front_keeps_only_undominated_points():
    points = [(10, 1.0), (20, 0.5), (15, 2.0), (30, 0.5), (40, 0.1)]
    assert chart.pareto_front(points) == [(10, 1.0), (20, 0.5), (40, 0.1)]


# slow: a mutant built and its truth decided per case (5-12 s); crashing0, wrong and not-compiling stay fast
@pytest.mark.slow
def test_quick_study_writes_its_csv_chart_and_failure_map(tmp_path, monkeypatch):
    from grader.cli import main
    from grader.study import run

    monkeypatch.setattr(run.StudyConfig, "quick", classmethod(
        lambda cls, **kw: cls(sizes=(8, 32), n_uniform=20000, n_edge=4000, n_corner=2000,
                              n_timing=2048, repeats=2)))
    assert main(["study", "--quick", "--out", str(tmp_path)]) == 0
    rows = run.read_csv(tmp_path / "study.csv")
    methods = {r["method"] for r in rows}
    assert {"nearest", "bilinear", "seamless", "numpy-bilinear", "oiio-latlong", "bicubic"} <= methods
    assert len(rows) == 2 * len(methods)
    for name in ("study.png", "failure_map.png"):
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "study.svg").read_text().lstrip().startswith("<?xml")
    with open(tmp_path / "failure_map.csv") as f:
        assert [r["method"] for r in csv.DictReader(f)][:3] == ["nearest", "bilinear", "seamless"]

    def smooth_rms(method, size):
        return next(r["uniform_smooth_rms"] for r in rows if r["method"] == method and r["face_size"] == size)
    # Expected orders: nearest and the handout's bilinear (half a texel off)
    # are first order (x4 for sizes 8 -> 32), seamless second order (x16).
    assert 2.5 < smooth_rms("nearest", 8) / smooth_rms("nearest", 32) < 6
    assert 2.5 < smooth_rms("bilinear", 8) / smooth_rms("bilinear", 32) < 6
    assert smooth_rms("seamless", 8) / smooth_rms("seamless", 32) > 6


def test_chart_draws_extra_points(tmp_path):
    rows = [{"method": "seamless", "label": "s", "face_size": n, "ns_random": 50.0 + n,
             "uniform_smooth_rms": 1.0 / n ** 2, "edge_smooth_rms": 1.0 / n} for n in (8, 16, 32)]
    extra = [{"label": "student A", "ns_random": 80.0, "uniform_smooth_rms": 1e-3},
             {"label": "student B", "ns_random": 90.0, "uniform_smooth_rms": 2e-3, "edge_smooth_rms": 0.1}]
    path = chart.draw(rows, extra, tmp_path / "c.png")
    assert path.stat().st_size > 10_000


def test_the_study_writes_to_build_unless_asked_to_update_the_committed_figures():
    """`make study` must not rewrite tracked files with this machine's timings."""
    from grader import PROJECT_ROOT
    from grader.commands.study import destinations
    from grader.study import STUDY_CSV
    out, rows = destinations(None, update=False)
    assert out == PROJECT_ROOT / "build" / "study-figures" and rows == out / "study.csv"
    assert destinations(PROJECT_ROOT / "x", update=False) == (PROJECT_ROOT / "x", PROJECT_ROOT / "x" / "study.csv")
    assert destinations(None, update=True) == (PROJECT_ROOT / "docs" / "study", STUDY_CSV)
    assert STUDY_CSV == PROJECT_ROOT / "fixtures" / "study.csv"
    makefile = (PROJECT_ROOT / "Makefile").read_text()
    assert "-m grader study $(if $(UPDATE),--update)" in makefile


def test_update_and_out_together_are_refused(capsys):
    from grader.cli import main
    assert main(["study", "--update", "--out", "/tmp/x"]) == 2
    assert "--update writes to docs/study/" in capsys.readouterr().err
