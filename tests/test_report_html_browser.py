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
from test_reports import HOSTILE, make_build_error, make_diagnosed

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
  document.body.setAttribute("data-scripts", document.querySelectorAll("script").length);
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


def probe(report: Path, tmp_path: Path) -> _Dom:
    """Load a copy of the report with the probe added; return its DOM."""
    page = report.read_text()
    page = re.sub(r'<meta http-equiv="Content-Security-Policy"[^>]*>', "", page)
    copy = tmp_path / f"probe-{report.parent.name}.html"
    copy.write_text(page.replace("</body>", PROBE + "</body>"))
    dom = _Dom()
    dom.feed(chromium(tmp_path, "--virtual-time-budget=10000", f"--window-size={WIDTH},2000",
                      "--dump-dom", copy.as_uri()))
    assert "data-page-height" in dom.body, "the probe did not run"
    return dom


def screenshot(report: Path, tmp_path: Path, height: int, *extra: str) -> np.ndarray:
    png = tmp_path / f"{report.parent.name}{'-'.join(('',) + extra).replace('=', '_')}.png"
    chromium(tmp_path, f"--window-size={WIDTH},{height}", f"--screenshot={png}", *extra,
             report.as_uri())
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


def test_every_image_loads_and_shows_where_it_is_placed(diagnosed_report):
    report, artifacts, dom, shot, tmp = diagnosed_report
    by_bytes = {p.read_bytes(): name for name, p in artifacts.items()}
    assert len(dom.images) == len(artifacts) == 6

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
