"""What the class's files share (the gradebook, the LMS files, the summary):
the status of a roster's student who handed in nothing, spreadsheet cells
safe from formulas, and files replaced whole or not at all."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

MISSING = "no-submission"     # a roster's student with nothing in the class folder


def cell(text: str) -> str:
    """A spreadsheet cell from a name a student chose: a leading =, +, - or @
    would be read as a formula by Excel or LibreOffice (CSV injection)."""
    return "'" + text if text[:1] in ("=", "+", "-", "@", "\t", "\r") else text


def write_text_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.chmod(tmp, 0o644)
    os.replace(tmp, path)
