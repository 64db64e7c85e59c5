"""Reports: turn a GradeResult into files a person reads.

write_all(result, out_dir) writes, each atomically:
  report.md     a summary fit for a CI job summary   (markdown.py)
  report.html   one self-contained page with images  (html.py)
  junit.xml     for CI test reporters                 (junit.py)
  results.json  Gradescope's format, written last     (gradescope_json.py)
results.json comes last so that its presence means the set is complete.
The terminal summary is terminal.print_summary. A report never runs a check.

Student-facing reports show visible checks only (see view.py); pass
include_hidden=True for an instructor's copy. results.json always holds
every check: Gradescope hides entries by their visibility.

Text from a submission (its name, exception messages, compiler output,
file names; in the class summary, folder names and shared code) is hostile
and reaches every format as text, never as markup:
  - everywhere: text.clean() drops ANSI codes, control characters, lone
    surrogates and U+FFFE/U+FFFF (so junit.xml stays XML 1.0);
  - Markdown (report.md, results.json, summary.md): plain strings through
    md_escape (no heading, list, link, autolink, image or raw HTML can form;
    e-mail addresses become code spans), logs and code through md_fence
    (a fence longer than any backtick run inside); a check's own Markdown
    output through inert_markdown, which shows it literally when it would
    form anything beyond paragraphs, lists, tables, emphasis and code;
    inside our <details><summary>, HTML escaping (no Markdown there);
  - HTML (report.html, summary.html, audit.html): jinja2 templates
    (templates/, one stylesheet) whose every printed value the engine
    escapes (templating.py); Markdown rendered with raw HTML, links and
    images off; a Content-Security-Policy (default-src 'none'; img-src
    data:; style-src 'unsafe-inline') that forbids any script;
  - charts: names never reach matplotlib's mathtext ($ escaped);
  - the terminal: rich Text objects, never markup strings.
tests/unit/reports/test_report_injection.py parses each output as its reader does
(GitHub's cmark-gfm, markdown-it, html.parser, ElementTree, Chromium).
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from ..grading.results import GradeResult
from . import gradescope_json, html, junit, markdown
from .view import build_view

REPORT_FILES = ("report.md", "report.html", "junit.xml", "results.json")


def write_atomic(path: Path, text: str) -> None:
    """Write to a temporary file beside `path`, then rename it into place:
    a reader (or an interrupted run) never sees half a file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def render_all(result: GradeResult, include_hidden: bool = False) -> dict[str, str]:
    """Every report's text, by file name (nothing is written)."""
    view = build_view(result, include_hidden)
    return {
        "report.md": markdown.render(view),
        "report.html": html.render(view),
        "junit.xml": junit.render(view),
        "results.json": gradescope_json.render(result),
    }


def write_all(result: GradeResult, out_dir: str | os.PathLike,
              include_hidden: bool = False) -> dict[str, Path]:
    """Write every report into out_dir; returns their paths by file name."""
    out = Path(out_dir)
    texts = render_all(result, include_hidden)
    paths = {}
    for name in REPORT_FILES:
        paths[name] = out / name
        write_atomic(paths[name], texts[name])
    return paths
