"""The speed check's chart: the study's part drawn once and cached, the
submission's star painted on a copy where matplotlib would have put it."""
from __future__ import annotations

import json

import numpy as np
from PIL import Image

from grader.study import chart

ROWS = [{"method": m, "label": m, "face_size": n, "ns_random": base * n ** 0.5,
         "uniform_smooth_rms": err / n ** 2, "edge_smooth_rms": err / n}
        for m, base, err in (("bilinear", 20.0, 1.0), ("seamless", 30.0, 0.5)) for n in (8, 32, 128)]
POINT = {"label": "your fetchColor (face 64)", "ns_random": 60.0, "uniform_smooth_rms": 1e-3}


def gold_near(image: Image.Image, x: float, y: float) -> bool:
    pixels = np.asarray(image.convert("RGB"), dtype=int)[int(y) - 2:int(y) + 3, int(x) - 2:int(x) + 3]
    return bool((np.abs(pixels - (255, 215, 0)).sum(axis=2) < 60).any())


def test_the_star_is_painted_where_matplotlib_draws_it(tmp_path):
    cached = chart.draw_with_point(ROWS, POINT, tmp_path / "fast.png", tmp_path / "cache", dpi=90)
    full = chart.draw(ROWS, [POINT], tmp_path / "full.png", panels=chart.PANELS[:1], dpi=90)
    layout = json.loads(next((tmp_path / "cache").glob("chart-*.json")).read_text())[0]
    (x0, x1), (y0, y1) = layout["xlim"], layout["ylim"]
    left, top, right, bottom = layout["box"]
    px = left + np.log(60 / x0) / np.log(x1 / x0) * (right - left)
    py = bottom - np.log(1e-3 / y0) / np.log(y1 / y0) * (bottom - top)
    fast, slow = Image.open(cached), Image.open(full)
    assert fast.size == slow.size
    assert gold_near(slow, px, py) and gold_near(fast, px, py)
    # Away from the star the two pictures are the same.
    a = np.asarray(fast.convert("RGB"), dtype=int)
    b = np.asarray(slow.convert("RGB"), dtype=int)
    assert (np.abs(a - b).sum(axis=2) > 30).mean() < 0.005


def test_the_cached_part_is_drawn_once(tmp_path, monkeypatch):
    chart.draw_with_point(ROWS, POINT, tmp_path / "a.png", tmp_path / "cache", dpi=90)

    def no_drawing(*args, **kwargs):
        raise AssertionError("drawn again")

    monkeypatch.setattr(chart, "draw", no_drawing)
    other = dict(POINT, ns_random=80.0)
    chart.draw_with_point(ROWS, other, tmp_path / "b.png", tmp_path / "cache", dpi=90)
    assert Image.open(tmp_path / "a.png").size == Image.open(tmp_path / "b.png").size
    assert (np.asarray(Image.open(tmp_path / "a.png")) != np.asarray(Image.open(tmp_path / "b.png"))).any()


def test_a_point_off_the_cached_axes_gets_the_full_drawing(tmp_path, monkeypatch):
    calls = []
    real = chart.draw

    def counting(*args, **kwargs):
        calls.append(args[1])
        return real(*args, **kwargs)

    monkeypatch.setattr(chart, "draw", counting)
    far = dict(POINT, ns_random=1e7)
    chart.draw_with_point(ROWS, far, tmp_path / "far.png", tmp_path / "cache", dpi=90)
    assert calls[-1] == [far] and (tmp_path / "far.png").stat().st_size > 10_000


def test_an_unwritable_cache_gets_the_full_drawing(tmp_path):
    blocker = tmp_path / "cache"
    blocker.write_text("a file, not a folder")
    path = chart.draw_with_point(ROWS, POINT, tmp_path / "c.png", blocker, dpi=90)
    assert path.stat().st_size > 10_000
