"""Counting the words a student meets on a report (issue 19, item 9).

"Visible words" are what a student reads without opening anything:
- report.md: the Markdown outside every <details> block (collapsed on
  GitHub and in any CommonMark viewer), <summary> lines included;
- report.html: the text of <body> outside collapsed <details> (a <details>
  without `open` shows only its <summary>), images' alt text and the
  attributes not counted;
- Gradescope: the top-level `output` and each visible test's name (each
  test's own output is its panel of details);
- PrairieLearn: `message`, `output` and each test's name.
Code is not words: fenced blocks, `code spans`, <code>, <pre>. Table markup
(pipes, alignment rows) is not words. A word is a whitespace-separated
token holding at least one letter, so numbers ("86.98", "21041"), marks
("/", "·", "✅") and the formulas' punctuation are not words.

Used by tests/grading/test_report_words.py and by hand:
    .venv/bin/python tests/helpers/report_words.py out/<submission>/
"""
from __future__ import annotations

import json
import re
import sys
from html.parser import HTMLParser
from pathlib import Path

_FENCE = re.compile(r"^(`{3,}|~{3,})[^\n]*\n.*?^\1[ \t]*$", re.M | re.S)
_CODE_SPAN = re.compile(r"(`+)(?:(?!\1).)+?\1", re.S)
_ALIGN_ROW = re.compile(r"^\s*\|?(?:\s*:?-+:?\s*\|)+\s*:?-*:?\s*$", re.M)
_TAG = re.compile(r"</?[a-zA-Z][^>]*>")


def words(text: str) -> list[str]:
    """Whitespace tokens that hold a letter, Markdown emphasis and escapes removed."""
    text = re.sub(r"\\(.)", r"\1", text)
    text = re.sub(r"[*_|#>]+", " ", text)
    return [t for t in text.split() if any(ch.isalpha() for ch in t)]


def _without_details(md: str) -> str:
    """Markdown with each <details> block replaced by its <summary>."""
    out, depth, i = [], 0, 0
    for m in re.finditer(r"<details[^>]*>|</details>|<summary>(.*?)</summary>", md, re.S):
        if depth == 0:
            out.append(md[i:m.start()])
        if m.group(0).startswith("<details"):
            depth += 1
        elif m.group(0) == "</details>":
            depth = max(0, depth - 1)
        elif depth == 1:
            out.append("\n" + (m.group(1) or "") + "\n")
        i = m.end()
    if depth == 0:
        out.append(md[i:])
    return "".join(out)


def markdown_words(md: str) -> list[str]:
    text = _without_details(md)
    text = _FENCE.sub(" ", text)
    text = _CODE_SPAN.sub(" ", text)
    text = _ALIGN_ROW.sub(" ", text)
    text = _TAG.sub(" ", text)
    return words(text)


class _VisibleText(HTMLParser):
    """Collects the text a browser shows: each open element records whether
    its content is hidden (inside <head>, code, or a collapsed <details>,
    whose <summary> alone stays visible)."""
    SKIP = {"head", "style", "script", "code", "pre", "title"}
    VOID = {"img", "br", "hr", "meta", "link", "input", "source", "wbr"}

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack: list[tuple[str, bool, bool]] = []   # (tag, it is hidden, its content is hidden)
        self.parts: list[str] = []

    def handle_starttag(self, tag, attrs):
        if tag in self.VOID:
            return
        parent = self.stack[-1] if self.stack else ("", False, False)
        if tag == "summary" and parent[0] == "details":
            hidden = parent[1]                     # shown when its details is
        else:
            hidden = parent[2] or tag in self.SKIP
        content_hidden = hidden or (tag == "details" and "open" not in dict(attrs))
        self.stack.append((tag, hidden, content_hidden))

    def handle_endtag(self, tag):
        if tag in self.VOID or tag not in (t for t, _, _ in self.stack):
            return
        while self.stack and self.stack.pop()[0] != tag:
            pass

    def handle_data(self, data):
        if not (self.stack and self.stack[-1][2]):
            self.parts.append(data)


def html_words(page: str) -> list[str]:
    parser = _VisibleText()
    parser.feed(page)
    parser.close()
    return words(" ".join(parser.parts))


def gradescope_words(data: dict) -> list[str]:
    out = list(markdown_words(data.get("output", "")) if data.get("output_format", "md") == "md"
               else html_words(data.get("output", "")))
    for test in data.get("tests", []):
        if test.get("visibility", "visible") == "visible":
            out += words(test.get("name", ""))
    return out


def prairielearn_words(data: dict) -> list[str]:
    out = words(data.get("message", "")) + words(data.get("output", ""))
    for test in data.get("tests", []):
        out += words(test.get("name", ""))
    return out


def folder_counts(folder: Path) -> dict[str, int]:
    """Visible words of each student-facing file in a report folder."""
    folder = Path(folder)
    counts = {"report.md": len(markdown_words((folder / "report.md").read_text())),
              "report.html": len(html_words((folder / "report.html").read_text()))}
    gs = folder / "results.json"
    if gs.exists():
        counts["results.json"] = len(gradescope_words(json.loads(gs.read_text())))
    return counts


if __name__ == "__main__":
    for arg in sys.argv[1:]:
        print(arg, folder_counts(Path(arg)))
