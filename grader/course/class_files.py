"""What the class's files share (the gradebook, the LMS files, the summary):
the status of a roster's student who handed in nothing, why an entry of the
class folder was skipped, spreadsheet cells safe from formulas, and files
replaced whole or not at all."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from ..i18n import N_, Translated

MISSING = "no-submission"     # a roster's student with nothing in the class folder
# Why an entry of the class folder is not a submission, by key. summary.json
# keeps the key ("why", with the file's "suffix") and the sentence in English
# ("reason", which the command prints); the class page says it in its
# language (skip_reason_text). grade_all's _skip_reason decides which.
SKIP_REASONS = Translated({
    "results-folder": N_("the results folder (--out) sits among the submissions"),
    "hidden": N_("a hidden file or folder (its name starts with a dot)"),
    "link": N_("a symbolic link (not followed: hand in the folder or file itself)"),
    "special": N_("neither a file nor a folder"),
    "file": N_("a %(suffix)s file, not a submission (expected a folder, an archive or a .cpp per student)"),
    "no-extension": N_("a file without an extension, not a submission (expected a folder, an archive or a .cpp "
                       "per student)"),
})


def skip_reason_text(entry: dict) -> str:
    """A skipped entry's reason in the current language (an entry without a
    known key, from an older grader's summary.json: as it was written)."""
    why = entry.get("why")
    if why not in SKIP_REASONS:
        return str(entry.get("reason", ""))
    return SKIP_REASONS[why] % {"suffix": str(entry.get("suffix", ""))}


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
