"""The class page in headless Chromium at a desktop's 1280 px and a phone's
390 px: each student's roster name comes first, and name, score and status
share one line (on a desktop the first diagnosis too); nothing is off the
page. Positions are measured in the browser, not read off the markup."""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from grader.course.grade_all import Row
from grader.reports.class_summary import write_summary
from test_report_html_browser import CHROMIUM, MIN_WINDOW, chromium, framed

pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed")

# Where each student's cells are drawn: the name's link, score, status pill, diagnosis.
PROBE = """<script>
window.addEventListener("load", () => {
  const box = el => { if (!el) return null; const r = el.getBoundingClientRect();
                      return {top: r.top, bottom: r.bottom, left: r.left, right: r.right}; };
  const rows = [...document.querySelectorAll("table.students tbody tr")].map(tr => ({
    name: box(tr.querySelector("td.who > a")), score: box(tr.querySelector("td.pts")),
    status: box(tr.querySelector("td.state .pill")), diagnosis: box(tr.querySelector("td.diag strong")),
    text: tr.querySelector("td.who > a").textContent,
    spill: [...tr.cells].filter(td => td.scrollWidth > td.clientWidth + 1).map(td => td.className)}));
  document.body.setAttribute("data-rows", JSON.stringify(rows));
  document.body.setAttribute("data-page-width", document.documentElement.scrollWidth);
  if (window.parent !== window) {
    const data = {};
    for (const a of document.body.attributes) { if (a.name.startsWith("data-")) data[a.name] = a.value; }
    window.parent.postMessage(data, "*");
  }
});
</script>"""
# A Canvas class: download names that are nobody's name, a long roster name.
ROWS = [Row("adamsalice_9001_700001_EnvironmentMap-1", "graded", 100.0, 100.0, {}, [], student_id="S2026001",
            name="Adams, Alice", email="alice.adams@uni.example"),
        Row("bakerbruno_LATE_9002_700002_EnvironmentMap", "graded", 87.02, 100.0, {}, ["v-flipped"],
            first_diagnosis="v-flipped", student_id="S2026002", name="Baker-Featherstonehaugh, Bruno Maximilian",
            email="bruno.baker@uni.example"),
        Row("chenchiara_9003_700003_EnvironmentMap", "build-error", 0.0, 100.0, {}, ["build-error"],
            first_diagnosis="build-error", student_id="S2026003", name="Chen, Chiara", email="chiara.chen@uni.example"),
        Row("evansemi_9005_700005_EnvironmentMap", "timeout", 46.92, 100.0, {}, ["timeout", "crash"],
            first_diagnosis="timeout", student_id="S2026005", name="Evans, Emi", email="emi.evans@uni.example")]


def measured(page: Path, tmp_path: Path, width: int) -> tuple[list[dict], float]:
    copy = tmp_path / f"probe-{width}.html"
    copy.write_text(re.sub(r'<meta http-equiv="Content-Security-Policy"[^>]*>', "", page.read_text())
                    .replace("</body>", PROBE + "</body>"))
    target = framed(copy, width, 2000) if width < MIN_WINDOW else copy
    dom = chromium(tmp_path, "--virtual-time-budget=10000", f"--window-size={max(width, MIN_WINDOW)},2000",
                   "--dump-dom", target.as_uri())
    rows = re.search(r'data-rows="([^"]*)"', dom)
    width_seen = re.search(r'data-page-width="([^"]*)"', dom)
    assert rows and width_seen, "the probe did not run"
    return json.loads(rows[1].replace("&quot;", '"').replace("&amp;", "&")), float(width_seen[1])


def same_line(a: dict, b: dict) -> bool:
    return a["top"] < b["bottom"] and b["top"] < a["bottom"]


@pytest.mark.parametrize("lang", ["en", "ja"])      # Japanese statuses are longer (issue 33: one ran over)
@pytest.mark.parametrize("width", [1280, 390])
def test_name_score_status_and_diagnosis_read_on_one_line(tmp_path, width, lang):
    from grader import i18n
    for r in ROWS:
        (tmp_path / r.student).mkdir()
        (tmp_path / r.student / "report.html").write_text("")
    before = i18n.language()
    i18n.set_language(lang)
    try:
        write_summary(ROWS, tmp_path)
    finally:
        i18n.set_language(before)
    rows, page_width = measured(tmp_path / "summary.html", tmp_path, width)
    assert page_width <= width
    assert [r["text"] for r in rows] == [r.name for r in ROWS]          # the roster's name, not the file's
    for r in rows:
        assert same_line(r["name"], r["score"]) and same_line(r["name"], r["status"]), (width, r)
        assert r["spill"] == [], (width, r)     # no cell's content runs over into the next
        assert max(r[k]["right"] for k in ("name", "score", "status")) <= width, (width, r)
        if r["diagnosis"] is not None:
            assert r["diagnosis"]["right"] <= width, (width, r)
            if width >= 1280:
                assert same_line(r["name"], r["diagnosis"]), r
            else:       # a phone: under the name, not beside it
                assert r["diagnosis"]["top"] >= r["name"]["bottom"] - 1, r
