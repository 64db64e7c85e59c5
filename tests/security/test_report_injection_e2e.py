"""Report injection through the real grader: a submission whose exception
message is a forged report, and a class whose archive and folder names are
markup and mathtext, graded by `grade` and `grade-all` as an instructor
would. The reports are parsed as in test_report_injection.py, and the class
summary is opened in Chromium: nothing the students wrote may run.
"""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

from grader import PROJECT_ROOT
from grader.grading.grade import GradeOptions, grade
from grader.grading.results import GRADED, UNGRADABLE
from project_paths import SUBMISSIONS
from red_team import REDTEAM
from test_report_injection import (FAKE_HEADING, FAKE_LINK, HTML_TAGS, MD_TAGS, Page,
                                   assert_nothing_formed, assert_shown_literally, commonmark, gfm)

THROW = PROJECT_ROOT / "tests" / "submissions" / "hostile" / "throw.cpp"
CORRECT = PROJECT_ROOT / "tests" / "submissions" / "correct" / "axis_table.cpp"
FAKE_IMAGE = "<img src=x onerror=document.body.setAttribute('data-pwned','1')>"
# What the exception says: a forged report, in C++ raw-string form.
MESSAGE = "\n".join([FAKE_HEADING, FAKE_LINK, FAKE_IMAGE, "```", "<script>alert(1)</script>",
                     "nonchar \uffff end"])
ZIP_NAME = "<img src=x onerror=document.body.setAttribute('data-pwned','2')>"
MATH_NAME = "$\\undefinedmacro$"


def hostile_source() -> str:
    text = THROW.read_text()
    assert '"direction too close to +x"' in text
    return text.replace('"direction too close to +x"', f'R"FORGED({MESSAGE})FORGED"')


def run(*args: str, timeout: int = 600) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "grader", *args], cwd=PROJECT_ROOT, capture_output=True,
                          text=True, timeout=timeout)


@pytest.fixture(scope="module")
def graded(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("forged")
    source = tmp / "forged" / "EnvironmentMap.cpp"
    source.parent.mkdir()
    source.write_text(hostile_source(), encoding="utf-8")
    out = tmp / "out"
    done = run("grade", str(source.parent), "--out", str(out), "--quick")
    assert done.returncode == 0, done.stdout + done.stderr
    return out


def test_a_forged_exception_message_is_a_diagnosis_shown_as_text(graded):
    data = json.loads((graded / "results.json").read_text())
    assert "exception" in {d["id"] for d in data["extra_data"]["diagnoses"]}
    assert data["score"] < data["extra_data"]["max_score"]
    md = (graded / "report.md").read_text()
    for render in (gfm, commonmark):
        page = render(md)
        assert_nothing_formed(page, "report.md", MD_TAGS)
        assert_shown_literally(page, "report.md", FAKE_HEADING, FAKE_LINK, FAKE_IMAGE)
        for text in [data["output"]] + [t["output"] for t in data["tests"]]:
            assert_nothing_formed(render(text), "results.json", MD_TAGS)
    page = Page((graded / "report.html").read_text())
    assert_nothing_formed(page, "report.html", HTML_TAGS)
    assert_shown_literally(page, "report.html", FAKE_HEADING, FAKE_IMAGE)
    junit = (graded / "junit.xml").read_text()
    ET.fromstring(junit.encode())                      # still XML
    assert "\uffff" not in junit and FAKE_HEADING in junit


@pytest.fixture(scope="module")
def graded_class(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("names")
    folder = tmp / "class"
    folder.mkdir()
    with zipfile.ZipFile(folder / f"{ZIP_NAME}.zip", "w") as z:
        z.writestr("EnvironmentMap.cpp", CORRECT.read_text())
    (folder / MATH_NAME).mkdir()
    (folder / MATH_NAME / "EnvironmentMap.cpp").write_text(hostile_source(), encoding="utf-8")
    out = tmp / "out"
    done = run("grade-all", str(folder), "--out", str(out), "--jobs", "2", "--quick")
    # $\undefinedmacro$ once crashed the chart, and the zip's name ran as script.
    assert done.returncode == 0, done.stdout + done.stderr
    return out


# slow: a whole-class grading (grade-all)
@pytest.mark.slow
def test_grade_all_with_markup_and_mathtext_names(graded_class):
    page = Page((graded_class / "summary.html").read_text())
    extra = page.tags() - HTML_TAGS - {"a"}
    assert not extra, extra
    assert not [a for _, attrs in page.elements for a in attrs if a.startswith("on")]
    assert_shown_literally(page, "summary.html", ZIP_NAME, MATH_NAME)
    links = sorted(a["href"] for t, a in page.elements if t == "a")
    assert len(links) == 4 and all(link.endswith("/report.html") and "<" not in link for link in links)
    for student in (ZIP_NAME, MATH_NAME):
        assert (graded_class / student / "report.html").is_file()
    # Both appear on the chart only if the speed check timed them; either way the PNG was drawn.
    assert (graded_class / "summary_speed_accuracy.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# slow: headless Chromium on a graded class
@pytest.mark.browser
@pytest.mark.slow
@pytest.mark.skipif(shutil.which("chromium") is None, reason="chromium is not installed")
def test_no_name_runs_as_script_in_a_browser(graded_class, tmp_path):
    from test_report_html_browser import probe
    for page in (graded_class / "summary.html", graded_class / MATH_NAME / "report.html"):
        dom = probe(page, tmp_path)
        assert "data-pwned" not in dom.body, page
        assert dom.body["data-scripts"] == "1" and dom.body["data-handlers"] == "0", page


# ---- the first red-team round (tests/submissions/redteam/) ------------------------
# - terminal_escapes: an exception's text reached the terminal summary with
#   its ANSI escapes (cursor up, erase line: the score line can be
#   overwritten), and right-to-left overrides reached every report. Now
#   diagnosis details are clean()ed in the view, and clean() removes bidi
#   controls (grader/reports/view.py, text.py).
# - grade-all: a submission named summary.html.zip (or gradebook.csv.zip, ...)
#   became a folder where the class summary goes, and grade-all stopped with a
#   traceback after grading everyone; a name near the 255-byte limit made the
#   temporary folder's name too long and the student "ungradable". Now class
#   files' names are kept free and temporary names are cut short
#   (grader/course/grade_all.py). A file name that is not UTF-8 (a Shift-JIS zip
#   unpacked on Linux: no malice needed) stopped grade-all at the gradebook
#   (UnicodeEncodeError); names are now made text first.

RED_TEAM = {"redteam": {"terminal_escapes"}}   # and grade-all's names, made here
SYNTAX_ERROR = SUBMISSIONS / "wrong" / "syntax-error.cpp"

@pytest.mark.slow
@pytest.mark.sandbox
def test_escapes_in_an_exception_reach_no_terminal_and_no_report(tmp_path):
    from grader.reports.terminal import print_summary
    from rich.console import Console
    import io
    result = grade(REDTEAM / "terminal_escapes.cpp", tmp_path,
                   GradeOptions(allow_stale=True, quick=True, only=("fetch_sweep",)))
    assert result.status == GRADED and "exception" in {d.id for d in result.diagnoses}
    assert any("001 / 001 :erocS" in d.detail for d in result.diagnoses)   # the text itself is kept, as data
    screen = io.StringIO()
    print_summary(result, Console(file=screen, force_terminal=True, width=120))
    shown = screen.getvalue()
    assert "001 / 001 :erocS" in shown
    # Rich's own colours are escapes too: none may come from the submission's text.
    assert "\x1b[2A" not in shown and "\x1b[2K" not in shown and "\x1b]0;" not in shown and "\x1b[8m" not in shown
    assert "\u202e" not in shown
    for name in ("report.md", "report.html", "results.json", "junit.xml"):
        text = (tmp_path / name).read_text()
        assert "\x1b" not in text and "\u202e" not in text and "\\u202e" not in text, name


# ---- the worker: tricks that must not blame the grader or hang it ------------------


# ---- grade-all: names a student chooses -------------------------------------------

@pytest.mark.slow
@pytest.mark.sandbox
def test_grade_all_survives_names_of_class_files_and_long_names(tmp_path):
    from grader.course.grade_all import grade_all
    klass = tmp_path / "class"
    klass.mkdir()
    long_name = "b" * 246                               # 250 bytes with .cpp: a legal file name
    for name in ("alice.cpp", "summary.html.cpp", "gradebook.csv.cpp", f"{long_name}.cpp"):
        shutil.copyfile(SYNTAX_ERROR, klass / name)
    import os
    shutil.copyfile(SYNTAX_ERROR, klass / os.fsdecode(b"sj\x83e\x83X\x83g.cpp"))   # Shift-JIS, not UTF-8
    (klass / "summary.json").mkdir()                   # a folder, as an unzipped upload would be
    shutil.copyfile(SYNTAX_ERROR, klass / "summary.json" / "EnvironmentMap.cpp")
    out = tmp_path / "out"
    rows = grade_all(klass, out, 1, {"quick": True, "allow_stale": True}, progress=False)
    assert len(rows) == 6
    assert all(r.status == "build-error" for r in rows), [(r.student[:20], r.status, r.error) for r in rows]
    assert UNGRADABLE not in (out / "gradebook.csv").read_text()
    for name in ("gradebook.csv", "summary.json", "summary.html", "summary.md"):
        assert (out / name).is_file(), name
    # The class's own summary data, not a student's folder in its place.
    assert {"skipped", "roster", "similarity"} <= set(json.loads((out / "summary.json").read_text()))
    assert (out / long_name / "results.json").is_file()
    assert (out / "summary.html_" / "results.json").is_file()
    assert "sj\ufffde\ufffdX\ufffdg" in (out / "gradebook.csv").read_text(encoding="utf-8")
