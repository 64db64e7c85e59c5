"""Report injection: text a student controls (exception messages, printed
output, compiler messages, file and folder names) must reach every report as
text, never as markup.

One hostile GradeResult carries the payloads everywhere a submission's text
can land (diagnosis details and hints, a check's output, worst cases, the
build log, warnings, the submission's name); each report is then parsed the
way its reader parses it: report.md and results.json by GitHub's own
renderer (cmark-gfm, through cmarkgfm) and by markdown-it, report.html and
summary.html by html.parser, junit.xml by ElementTree. No heading, link,
image, script or element may come from the payloads, and the payloads must
still be readable, literally.
"""
from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET
from urllib.parse import unquote
from html.parser import HTMLParser

import pytest
from markdown_it import MarkdownIt

from grader.course.grade_all import Row
from grader.reports import render_all, terminal
from grader.reports.class_summary import write_summary
from grader.reports.text import clean, inert_markdown, markdown_is_inert, md_escape
from grader.grading.results import FAILED, GRADED, PASSED, CheckResult, Diagnosis, GradeResult, Mismatch

# Each one is a way to forge part of a report.
FAKE_HEADING = "# Regraded by instructor: 100/100"
FAKE_LINK = "[link](http://x)"
FAKE_IMAGE = "<img src=x onerror=document.body.setAttribute('data-pwned','1')>"
FAKE_SCRIPT = "<script>document.body.setAttribute('data-pwned','2')</script>"
FENCE = "```"
PAYLOADS = [FAKE_HEADING, FAKE_LINK, FAKE_IMAGE, FENCE, FAKE_SCRIPT,
            "![img](http://x/y.png)", "<details open><summary>fake</summary>",
            "Regraded\n========", "see http://evil.example and www.evil.example",
            "[bold red]rich markup[/]", "&lt;entity&gt;", "| fake | table |", "mail alice@uni.example now",
            "non-text \uffff\ufffe\x00\x07\x1b[31m\ud800 end"]
PAYLOAD = "\n".join(PAYLOADS)
# Student names from grade-all: folder and archive names.
NAMES = ["<img src=x onerror=document.body.setAttribute('data-pwned','3')>", "$\\undefinedmacro$",
         "a`b``c", "x](http:evil)[y", "# Regraded 100", "javascript:alert(1)"]


def make_hostile() -> GradeResult:
    build = CheckResult("build", "Your code compiles", status=PASSED, score=5, max_score=5, number="1")
    sweeps = CheckResult(
        "sweeps", "fetchColor picks the right face", status=FAILED, fraction=0.5, score=15,
        max_score=30, number="2",
        # A check that (wrongly) pastes the student's text into its Markdown.
        output="| set | match |\n|---|---:|\n| sphere | 50% |\n\nYour program printed:\n\n" + PAYLOAD,
        diagnoses=[Diagnosis("crash", PAYLOAD, face="+X", hint=PAYLOAD)],
        mismatches=[Mismatch(call=PAYLOAD, expected=(1.0, 2.0, 3.0), got=(float("nan"), 0.5, 1.0),
                             group=PAYLOAD)],
        mismatch_counts={PAYLOAD: 7})
    info = CheckResult("diagnosis", "What fetchColor does", status=FAILED, fraction=0.0, score=0,
                       max_score=0, number="3", output="Recovered: nothing unusual.")
    return GradeResult(submission=NAMES[0] + " " + NAMES[1], status=GRADED, checks=[build, sweeps, info],
                       score=20, max_score=35, build_log=PAYLOAD, warnings=[PAYLOAD],
                       execution_time_s=1.5, isolation="bubblewrap")


# ---- parsing helpers ---------------------------------------------------------

class Page(HTMLParser):
    """Elements, attributes and the text a reader sees."""

    def __init__(self, text: str):
        super().__init__(convert_charrefs=True)
        self.elements: list[tuple[str, dict]] = []
        self.text: list[str] = []
        self.headings: list[str] = []
        self._heading: list[str] | None = None
        self.feed(text)
        self.close()

    def handle_starttag(self, tag, attrs):
        self.elements.append((tag, dict(attrs)))
        if re.fullmatch(r"h[1-6]", tag):
            self._heading = []

    def handle_endtag(self, tag):
        if re.fullmatch(r"h[1-6]", tag) and self._heading is not None:
            self.headings.append("".join(self._heading))
            self._heading = None

    def handle_data(self, data):
        self.text.append(data)
        if self._heading is not None:
            self._heading.append(data)

    def tags(self) -> set[str]:
        return {t for t, _ in self.elements}

    def plain(self) -> str:
        return re.sub(r"\s+", " ", "".join(self.text))


def gfm(markdown: str) -> Page:
    """What GitHub shows (cmark-gfm with its extensions; raw HTML kept, as
    GitHub's sanitiser keeps <details> and <summary>)."""
    cmarkgfm = pytest.importorskip("cmarkgfm", reason="pip install cmarkgfm (GitHub's renderer)")
    from cmarkgfm.cmark import Options
    return Page(cmarkgfm.github_flavored_markdown_to_html(markdown, options=Options.CMARK_OPT_UNSAFE))


def commonmark(markdown: str) -> Page:
    return Page(MarkdownIt("commonmark", {"html": True}).enable(["table", "strikethrough"]).render(markdown))


def assert_nothing_formed(page: Page, where: str, allowed_tags: set[str]):
    extra = page.tags() - allowed_tags
    assert not extra, f"{where}: elements from student text: {extra}"
    for tag, attrs in page.elements:
        assert not [a for a in attrs if a.startswith("on")], f"{where}: event handler on <{tag}>"
        assert tag != "a", f"{where}: a link was formed: {attrs}"
        assert tag != "img" or attrs.get("src", "").startswith("data:image/png;base64,"), where
    assert not [h for h in page.headings if "Regraded" in h or "fake" in h], (where, page.headings)


def assert_shown_literally(page: Page, where: str, *fragments: str):
    text = page.plain()
    for fragment in fragments:
        assert re.sub(r"\s+", " ", fragment) in text, f"{where}: {fragment!r} is not shown as text"


MD_TAGS = {"h1", "h2", "h3", "h4", "p", "strong", "em", "code", "pre", "ul", "li", "table", "thead",
           "tbody", "tr", "th", "td", "details", "summary", "blockquote", "hr", "ol"}
LITERAL = [FAKE_HEADING, FAKE_LINK, FAKE_IMAGE, FAKE_SCRIPT]


# ---- report.md --------------------------------------------------------------

@pytest.mark.parametrize("render", [gfm, commonmark], ids=["github", "commonmark"])
def test_report_md_forms_nothing_from_student_text(render):
    md = render_all(make_hostile())["report.md"]
    page = render(md)
    assert_nothing_formed(page, "report.md", MD_TAGS)
    assert_shown_literally(page, "report.md", *LITERAL)
    # Our own headings, and no others.
    assert page.headings[0].startswith("Environment mapping: <img src=x")
    assert not [h for h in page.headings[1:] if "img" in h or "undefinedmacro" in h]


def test_report_md_raw_html_is_only_ours():
    md = render_all(make_hostile())["report.md"]
    tokens = MarkdownIt("commonmark", {"html": True}).enable("table").parse(md)
    html_blocks = [t.content.strip() for t in tokens if t.type == "html_block"]
    inline_html = [c.content for t in tokens if t.type == "inline" for c in t.children or []
                   if c.type == "html_inline"]
    assert inline_html == []
    for block in html_blocks:
        assert re.fullmatch(r"(<details><summary>[^<>]*</summary>|</details>)", block), block


def test_the_fence_of_a_log_is_longer_than_any_backtick_run_in_it():
    result = make_hostile()
    result.build_log = "a ```` b\n`````\nc"
    md = render_all(result)["report.md"]
    fences = [t for t in MarkdownIt("commonmark").parse(md) if t.type == "fence"]
    assert any(f.content == "a ```` b\n`````\nc\n" for f in fences)


# ---- results.json -------------------------------------------------------------

@pytest.mark.parametrize("render", [gfm, commonmark], ids=["github", "commonmark"])
def test_results_json_outputs_form_nothing(render):
    data = json.loads(render_all(make_hostile())["results.json"])
    assert data["output_format"] == "md"       # rendered as Markdown by Gradescope: inert Markdown
    outputs = {"output": data["output"]}
    outputs.update({f"test {t['name']}": t["output"] for t in data["tests"]})
    for where, text in outputs.items():
        assert all(t["output_format"] == "md" for t in data["tests"])
        assert_nothing_formed(render(text), where, MD_TAGS)
    assert_shown_literally(render(outputs["test fetchColor picks the right face"]), "sweeps",
                           *LITERAL)
    assert "\uffff" not in json.dumps(data, ensure_ascii=False)


# ---- report.html --------------------------------------------------------------

HTML_TAGS = {"html", "head", "meta", "title", "style", "body", "main", "header", "div", "p", "span", "h1",
             "h2", "h3", "section", "table", "thead", "tbody", "tr", "th", "td", "strong", "em", "code",
             "pre", "details", "summary", "article", "ul", "li", "footer", "figure", "figcaption", "img"}


def test_report_html_forms_nothing_and_shows_everything():
    page_text = render_all(make_hostile())["report.html"]
    page = Page(page_text)
    assert_nothing_formed(page, "report.html", HTML_TAGS)
    assert_shown_literally(page, "report.html", *LITERAL, NAMES[0], NAMES[1])
    csp = [a["content"] for t, a in page.elements if t == "meta" and a.get("http-equiv") == "Content-Security-Policy"]
    assert csp and "default-src 'none'" in csp[0] and "script-src" not in csp[0]
    assert "\uffff" not in page_text and "\x00" not in page_text


# ---- junit.xml -----------------------------------------------------------------

XML_CHAR = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def test_junit_stays_valid_xml_with_the_text_intact():
    text = render_all(make_hostile())["junit.xml"]
    assert not XML_CHAR.search(text)
    root = ET.fromstring(text.encode("utf-8"))
    failure = root.find(".//testcase[@classname='envmap.sweeps']/failure")
    assert FAKE_IMAGE in failure.text and FAKE_HEADING in failure.text and "non-text" in failure.text
    assert root.find(".//property[@name='isolation']").get("value") == "bubblewrap"
    assert "<img" in root.find(".//property[@name='submission']").get("value")


# ---- the terminal ------------------------------------------------------------------

def test_terminal_shows_rich_markup_literally():
    text = terminal.summary_text(make_hostile(), width=200)
    assert "[bold red]rich markup[/]" in text and FAKE_HEADING in text


# ---- the class summary -----------------------------------------------------------

def class_rows():
    return [Row(name, "graded", 10.0 * i, 40.0, {"build": 5.0}, ["crash"],
                {"ns_per_lookup": 30.0 + i, "uniform_smooth_rms": 0.01})
            for i, name in enumerate(NAMES)] + [
        Row("erin", "ungradable", 0.0, 0.0, error="RuntimeError: " + PAYLOAD)]


def test_class_summary_with_hostile_names(tmp_path):
    rows = class_rows()
    for r in rows:
        (tmp_path / r.student).mkdir()
        (tmp_path / r.student / "report.html").write_text("")
    write_summary(rows, tmp_path)     # $\undefinedmacro$ once crashed the chart
    page = Page((tmp_path / "summary.html").read_text())
    extra = page.tags() - HTML_TAGS - {"a"}
    assert not extra, extra
    images = [a for t, a in page.elements if t == "img"]
    assert len(images) == 2 and all(a["src"].startswith("data:image/png;base64,") for a in images)
    assert not [a for _, attrs in page.elements for a in attrs if a.startswith("on")]
    assert_shown_literally(page, "summary.html", *NAMES, FAKE_HEADING, FAKE_LINK)
    # One link per student, in the gradebook and the list, each to a report
    # inside the results folder (the name percent-encoded).
    links = [a["href"] for t, a in page.elements if t == "a"]
    assert len(links) == 2 * len(rows)
    for href in links:
        assert re.fullmatch(r"[A-Za-z0-9%._~-]+/report\.html", href), href
    assert not [h for h in page.headings if "Regraded" in h]


# Template source in a name: the class page is a jinja2 template, and a name
# must be a value it prints, never source it runs ({{ 7*7 }} would say 49).
TEMPLATE_SYNTAX = "<script>alert(1)</script> {{ 7*7 }} {% print 6*7 %} </style>\nsecond line"


def test_class_summary_prints_template_syntax_and_closing_tags_as_text(tmp_path):
    folder = "x" + TEMPLATE_SYNTAX.replace("/", "")      # a folder's name: no slash
    rows = [Row(folder, "ungradable", 0.0, 0.0, error="RuntimeError: " + TEMPLATE_SYNTAX,
                name=TEMPLATE_SYNTAX, student_id="id" + TEMPLATE_SYNTAX),
            Row("ok", "graded", 10.0, 10.0, {"build": 10.0}, name="y" + TEMPLATE_SYNTAX)]
    for r in rows:
        (tmp_path / r.student).mkdir()
        (tmp_path / r.student / "report.html").write_text("")
    write_summary(rows, tmp_path)
    raw = (tmp_path / "summary.html").read_text()
    # Markup only as escaped text: one </style>, where the stylesheet ends; no script.
    assert raw.count("</style>") == 1 and raw.index("</style>") > raw.index("<style>") + 1000
    assert "<script" not in raw and "&lt;script&gt;alert(1)&lt;/script&gt;" in raw and "&lt;/style&gt;" in raw
    # Nothing evaluated: the expressions are there as typed, their values nowhere.
    assert raw.count("{{ 7*7 }}") >= 5 and raw.count("{% print 6*7 %}") >= 5
    page = Page(raw.split("</style>", 1)[1])      # the page's text, after the stylesheet
    assert not re.search(r"\b(?:49|42)\b", page.plain())
    assert not page.tags() - HTML_TAGS - {"a"}
    # Each field reads as it was, its newline included: the students table's name, id and folder lines, the
    # first diagnosis column's error, the callout of ungradable students.
    texts = "".join(page.text)
    for shown in ("id" + TEMPLATE_SYNTAX, folder, "y" + TEMPLATE_SYNTAX, "RuntimeError: " + TEMPLATE_SYNTAX):
        assert shown in texts, shown
    links = [a["href"] for t, a in page.elements if t == "a"]
    assert all(re.fullmatch(r"[A-Za-z0-9%._~-]+/report\.html", h) for h in links), links
    assert sorted(unquote(h) for h in links) == sorted(2 * [folder + "/report.html", "ok/report.html"])


def test_class_summary_md_links_only_to_reports(tmp_path):
    rows = class_rows()
    for r in rows:
        (tmp_path / r.student).mkdir()
        (tmp_path / r.student / "report.html").write_text("")
    write_summary(rows, tmp_path)
    md = (tmp_path / "summary.md").read_text()
    for render in (gfm, commonmark):
        page = render(md)
        links = [a.get("href", "") for t, a in page.elements if t == "a"]
        assert len(links) == len(rows)
        assert all(re.fullmatch(r"[A-Za-z0-9%._~-]+/report\.html", h) for h in links), links
        assert not page.tags() & {"script", "h3", "h4"}
        assert sorted(a["src"] for t, a in page.elements if t == "img") == [
            "summary_histogram.png", "summary_speed_accuracy.png"]
        assert [h for h in page.headings if "Regraded" in h] == []
        assert_shown_literally(page, "summary.md", *NAMES)


# ---- the helpers ------------------------------------------------------------------

def test_clean_leaves_only_xml_characters():
    assert not XML_CHAR.search(clean("a\uffff\ufffe\ud800\x00\x08\x0b\x1f\x7f b"))


@pytest.mark.parametrize("render", [gfm, commonmark], ids=["github", "commonmark"])
@pytest.mark.parametrize("payload", PAYLOADS)
def test_md_escape_is_inert_for_every_payload(payload, render):
    for markdown in (md_escape(payload, line_start=True), "- " + md_escape(payload, line_start=True),
                     "| a |\n|---|\n| " + md_escape(payload) + " |", "x " + md_escape(payload)):
        page = render(markdown)
        assert page.tags() <= {"p", "ul", "li", "table", "thead", "tbody", "tr", "th", "td", "code"}, (
            markdown, page.tags())
        assert clean(payload).replace("\n", " ").strip()[:8] in page.plain()


def test_grader_markdown_stays_markdown_and_anything_else_becomes_text():
    table = "4 of 6 faces.\n\n| face | match |\n|---|---:|\n| +X | 0% |\n\n- **+X**: `u` runs the wrong way"
    assert inert_markdown(table) == table
    for payload in (FAKE_HEADING, FAKE_LINK, FAKE_IMAGE, FENCE + "\nx", "see http://x.org", "a@b.org"):
        shown = inert_markdown(table + "\n\n" + payload)
        assert shown.startswith("```") and payload in shown


def test_same_hostile_result_same_reports():
    assert render_all(make_hostile()) == render_all(make_hostile())


def hostile_summary_data() -> dict:
    """grade-all's summary data (skipped entries, roster, similarity): file
    names, roster entries and the students' own code."""
    return {
        "skipped": [{"entry": FAKE_IMAGE + ".rar", "reason": "a .rar file " + FAKE_LINK},
                    {"entry": "a`b``c.txt", "reason": FAKE_HEADING}],
        "roster": {"file": "roster <b>.csv", "columns": {}, "students": 3, "matched": 2,
                   "unmatched": [FAKE_HEADING, FAKE_IMAGE],
                   "missing": [{"id": "42", "name": FAKE_SCRIPT, "email": "x@y.org"}]},
        "similarity": {"tool": "copydetect", "boilerplate": "student_template/EnvironmentMap.cpp",
                       "compared": 2, "min_listed": 0.5,
                       "pairs": [{"a": NAMES[0], "b": NAMES[1], "similarity": 0.93, "share_a": 0.93,
                                  "share_b": 0.9, "shared_tokens": 400,
                                  "passages": [{"a_lines": [1, 3], "b_lines": [2, 4], "a_text": PAYLOAD,
                                                "b_text": "````\n" + FAKE_SCRIPT + "\n```"}]}],
                       "not_compared": [{"student": FAKE_HEADING, "reason": FAKE_LINK}]},
    }


def test_class_summary_data_sections_stay_text(tmp_path):
    rows = class_rows()
    write_summary(rows, tmp_path, data=hostile_summary_data())
    md = (tmp_path / "summary.md").read_text()
    for page, where in ((Page((tmp_path / "summary.html").read_text()), "summary.html"),
                        (gfm(md), "summary.md on GitHub"), (commonmark(md), "summary.md")):
        # summary.html collapses its own sections: the points table, the one cluster, its one passage.
        ours = 3 if where == "summary.html" else 0
        assert not page.tags() & {"script", "b", "h4"}, (where, page.tags())
        assert len([t for t, _ in page.elements if t == "details"]) == ours, where
        assert [a for t, a in page.elements if t == "a"] == [], where      # no report folders here
        assert not [a for _, attrs in page.elements for a in attrs if a.startswith("on")], where
        assert not [h for h in page.headings if "Regraded" in h], where
        assert_shown_literally(page, where, FAKE_IMAGE + ".rar", "roster <b>.csv", FAKE_SCRIPT,
                               FAKE_HEADING, "Most similar pairs")
        assert "93%" in page.plain()
    # The shared passages are code blocks that end where they should.
    fences = [t for t in MarkdownIt("commonmark").parse(md) if t.type == "fence"]
    assert [f.info for f in fences] == ["cpp", "cpp"]
    assert fences[1].content == "````\n" + FAKE_SCRIPT + "\n```\n"


def test_class_summary_is_deterministic(tmp_path):
    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
        write_summary(class_rows(), tmp_path / folder, data=hostile_summary_data())
    for name in ("summary.md", "summary.html", "summary_histogram.png", "summary_speed_accuracy.png"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes(), name


def test_grade_all_progress_bar_shows_names_as_text(capsys):
    """rich reads "[...]" in a string as markup: a folder named "[/x]" raised
    MarkupError in grade-all's progress bar, before the gradebook was written."""
    from grader.course.grade_all import _Progress
    with _Progress(True, 3, 0) as advance:
        for name in ("[/oops]", "[bold red]x[/]", "[link=http://evil]y"):
            advance(name)
    assert "[link=http://evil]y" in capsys.readouterr().err   # the last name, as it is


def test_a_long_message_is_shown_shortened():
    result = make_hostile()
    result.checks[1].diagnoses = [Diagnosis("exception", "uncaught exception: " + "A" * 60000 + " END")]
    result.warnings = ["W" * 60000]
    for name, text in render_all(result).items():
        if name != "results.json":      # extra_data keeps every detail for the instructor
            assert "A" * 5000 not in text and "W" * 5000 not in text, name
            assert "characters left out" in text and " END" in text, name


def test_the_gradebook_page_shows_the_roster_columns(tmp_path):
    rows = class_rows()
    rows[0].student_id, rows[0].name, rows[0].email = "s42", FAKE_SCRIPT, "ada@uni.example"
    write_summary(rows, tmp_path)
    page = Page((tmp_path / "summary.html").read_text())
    assert "script" not in page.tags()
    assert_shown_literally(page, "summary.html", "s42", FAKE_SCRIPT, "ada@uni.example")
