"""report.html opened as a student would: in a real browser (headless
Chromium, Debian's package), with its images.

Two runs of the browser per page. The first opens a copy with a small probe
script added (the report itself has none, and its Content-Security-Policy
would block one) that writes, for every image, whether it decoded, its
natural size and where it sits on the page into the DOM, which --dump-dom
prints. The second takes a screenshot of the unmodified report, and the
test finds each image's own colours again at the place the probe measured.
"""
from __future__ import annotations

import base64
import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest

from grader.reports import write_all
from test_report_injection import class_rows, make_hostile
from test_reports import HOSTILE, make_build_error, make_diagnosed, make_speed_only

CHROMIUM = shutil.which("chromium") or (
    "/usr/bin/chromium" if Path("/usr/bin/chromium").exists() else None)
pytestmark = pytest.mark.skipif(
    CHROMIUM is None,
    reason="chromium is not installed (Debian package `chromium`; `make system-deps` installs it)")

WIDTH = 1280
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars", "--force-device-scale-factor=1"]

PROBE = """<script>
window.addEventListener("load", () => {
  for (const img of document.images) {
    const r = img.getBoundingClientRect();
    img.setAttribute("data-probe", JSON.stringify({
      complete: img.complete, naturalWidth: img.naturalWidth, naturalHeight: img.naturalHeight,
      x: r.left + window.scrollX, y: r.top + window.scrollY, w: r.width, h: r.height}));
  }
  document.body.setAttribute("data-page-height", document.documentElement.scrollHeight);
  document.body.setAttribute("data-page-width", document.documentElement.scrollWidth);
  document.body.setAttribute("data-scripts", document.querySelectorAll("script").length);
  let right = 0;
  for (const cell of document.querySelectorAll("table.checks .pts")) {
    if (cell.closest("details:not([open])")) continue;   // collapsed: not on the screen
    right = Math.max(right, cell.getBoundingClientRect().right);
  }
  document.body.setAttribute("data-points-right", right);
  let handlers = 0;
  for (const el of document.querySelectorAll("*")) {
    for (const a of el.attributes) { if (a.name.startsWith("on")) handlers++; }
  }
  document.body.setAttribute("data-handlers", handlers);
  if (window.parent !== window) {   // framed (narrow windows): report to the frame's page
    const data = {};
    for (const a of document.body.attributes) { if (a.name.startsWith("data-")) data[a.name] = a.value; }
    window.parent.postMessage(data, "*");
  }
});
</script>"""


def chromium(tmp_path: Path, *args: str) -> str:
    profile = Path(subprocess.check_output(["mktemp", "-d", "-p", str(tmp_path)], text=True).strip())
    run = subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", *args],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-2000:]
    return run.stdout


class _Dom(HTMLParser):
    def __init__(self):
        super().__init__()
        self.images: list[dict] = []
        self.body: dict = {}

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "img":
            self.images.append(attrs)
        elif tag == "body":
            self.body = attrs


def probe(report: Path, tmp_path: Path, width: int = WIDTH) -> _Dom:
    """Load a copy of the report with the probe added (and its CSP removed:
    what must hold here holds by escaping alone); return its DOM."""
    page = report.read_text()
    page = re.sub(r'<meta http-equiv="Content-Security-Policy"[^>]*>', "", page)
    copy = tmp_path / f"probe-{report.parent.name}.html"
    copy.write_text(page.replace("</body>", PROBE + "</body>"))
    dom = _Dom()
    dom.feed(chromium(tmp_path, "--virtual-time-budget=10000", f"--window-size={max(width, MIN_WINDOW)},2000",
                      "--dump-dom", (framed(copy, width, 2000) if width < MIN_WINDOW else copy).as_uri()))
    assert "data-page-height" in dom.body, "the probe did not run"
    return dom


# Headless Chromium's window is at least 500 px wide: narrower pages are
# loaded in a frame of that width inside a page that receives the probe's
# findings by postMessage.
MIN_WINDOW = 500
FRAME = """<!DOCTYPE html><html><body style="margin:0">
<iframe src="{src}" width="{width}" height="{height}" style="border:0;display:block"></iframe>
<script>addEventListener("message", e => {{
  for (const [k, v] of Object.entries(e.data)) document.body.setAttribute(k, v); }});</script>
</body></html>"""


def framed(page: Path, width: int, height: int) -> Path:
    outer = page.with_name(f"frame-{width}-{page.name}")
    outer.write_text(FRAME.format(src=page.name, width=width, height=height))
    return outer


def screenshot(report: Path, tmp_path: Path, height: int, *extra: str, width: int = WIDTH) -> np.ndarray:
    png = tmp_path / f"{report.parent.name}-{width}{'-'.join(('',) + extra).replace('=', '_')}.png"
    page = framed(report, width, height) if width < MIN_WINDOW else report
    chromium(tmp_path, f"--window-size={max(width, MIN_WINDOW)},{height}", f"--screenshot={png}", *extra,
             page.as_uri())
    return read_png(png)


def read_png(path: Path) -> np.ndarray:
    pixels = oiio.ImageBuf(str(path)).get_pixels(oiio.FLOAT)
    assert pixels is not None and pixels.size, f"cannot read {path}"
    return pixels[..., :3]


@pytest.fixture(scope="module")
def diagnosed_report(tmp_path_factory):
    """The report of a result with diagnoses and images, its probed DOM and a
    screenshot of the whole page (light colour scheme, Chromium's default)."""
    tmp = tmp_path_factory.mktemp("browser")
    result = make_diagnosed(tmp)
    report = write_all(result, tmp / "diagnosed")["report.html"]
    artifacts = {name: Path(p) for c in result.checks for name, p in c.artifacts.items()}
    dom = probe(report, tmp)
    height = min(int(float(dom.body["data-page-height"])), 16000)
    shot = screenshot(report, tmp, height)
    print(f"screenshots in {tmp}")      # shown with -s, to look at them
    return report, artifacts, dom, shot, tmp


@pytest.mark.representative
def test_every_image_loads_and_shows_where_it_is_placed(diagnosed_report):
    report, artifacts, dom, shot, tmp = diagnosed_report
    # Every image but the speed chart, which waits until the lookup works.
    by_bytes = {p.read_bytes(): name for name, p in artifacts.items() if name != "speed_accuracy_chart"}
    assert len(dom.images) == len(artifacts) - 1 == 5

    for img in dom.images:
        src = img["src"]
        assert src.startswith("data:image/png;base64,")
        name = by_bytes[base64.b64decode(src.split(",", 1)[1])]
        source = read_png(artifacts[name])
        info = json.loads(img["data-probe"])
        assert info["complete"] and (info["naturalWidth"], info["naturalHeight"]) == (
            source.shape[1], source.shape[0]), name

        # Where the image is on the page, a little inside its rounded border.
        x0, y0 = int(info["x"]) + 4, int(info["y"]) + 4
        x1, y1 = int(info["x"] + info["w"]) - 4, int(info["y"] + info["h"]) - 4
        assert info["w"] >= 150 and y1 <= shot.shape[0], f"{name} is too small or off the page"
        region = shot[y0:y1, x0:x1]
        assert region.std() > 0.05, f"{name}: the place where it should be is blank"
        assert np.abs(region.mean(axis=(0, 1)) - source.mean(axis=(0, 1))).max() < 0.06, (
            f"{name}: the colours on screen are not the image's")


def test_the_report_follows_the_light_and_dark_colour_schemes(diagnosed_report):
    report, _, _, light, tmp = diagnosed_report
    dark = screenshot(report, tmp, 400, "--force-dark-mode",
                      "--blink-settings=preferredColorScheme=0")
    # The page background at the top left corner.
    assert light[5, 5].mean() > 0.85 and dark[5, 5].mean() < 0.15


def test_hostile_build_output_stays_text(tmp_path):
    report = write_all(make_build_error(), tmp_path / "build-error")["report.html"]
    dom = probe(report, tmp_path)
    assert dom.body["data-scripts"] == "1"          # the probe's own, nothing else
    assert dom.images == []                         # <img src=x onerror=...> is text
    page = chromium(tmp_path, "--virtual-time-budget=5000", "--dump-dom", report.as_uri())
    assert HOSTILE.replace("<", "&lt;").replace(">", "&gt;") in page


def test_the_speed_chart_shows_when_the_lookup_works(tmp_path):
    report = write_all(make_speed_only(tmp_path), tmp_path / "slow")["report.html"]
    dom = probe(report, tmp_path)
    (img,) = dom.images
    info = json.loads(img["data-probe"])
    assert info["complete"] and info["naturalWidth"] == 64 and info["w"] >= 150


def test_no_student_text_runs_as_script(tmp_path):
    """The payloads set data-pwned on <body> if they ever run."""
    report = write_all(make_hostile(), tmp_path / "hostile")["report.html"]
    for page in (report, _class_summary(tmp_path)):
        dom = probe(page, tmp_path)
        assert "data-pwned" not in dom.body, page
        assert dom.body["data-scripts"] == "1" and dom.body["data-handlers"] == "0", page
    assert [i for i in probe(report, tmp_path).images] == []


def _class_summary(tmp_path: Path) -> Path:
    from grader.reports.class_summary import write_summary
    out = tmp_path / "class"
    rows = class_rows()
    for r in rows:
        (out / r.student).mkdir(parents=True)
        (out / r.student / "report.html").write_text("")
    write_summary(rows, out)
    return out / "summary.html"


@pytest.mark.parametrize("width", [360, 1280])
def test_the_report_fits_a_phone_and_a_desktop(width, tmp_path):
    """Nothing wider than the window (no sideways scrolling of the page),
    and the points column inside it. The screenshots stay in tmp_path for a
    person to look at (pytest -s prints where)."""
    reports = [write_all(make_diagnosed(tmp_path), tmp_path / "diagnosed")["report.html"],
               write_all(make_hostile(), tmp_path / "hostile")["report.html"],
               _class_summary(tmp_path)]
    for report in reports:
        dom = probe(report, tmp_path, width)
        assert int(float(dom.body["data-page-width"])) <= width, (report, dom.body["data-page-width"])
        assert float(dom.body["data-points-right"]) <= width, report
        height = min(int(float(dom.body["data-page-height"])), 16000)
        screenshot(report, tmp_path, height, width=width)
    print(f"screenshots in {tmp_path}")
