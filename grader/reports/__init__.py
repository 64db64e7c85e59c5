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
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from ..results import GradeResult
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
