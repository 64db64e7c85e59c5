"""A `bwrap` that always fails, as in a container without user namespaces
(Gradescope, PrairieLearn): put its folder first on PATH to reach
privilege-drop mode as root. One copy for every test that needs it."""
from __future__ import annotations

from pathlib import Path

SCRIPT = "#!/bin/sh\necho 'bwrap: No permissions to create new namespace' >&2\nexit 1\n"


def write_failing_bwrap(folder: Path) -> Path:
    """Write the failing bwrap into `folder` (made if missing) and return the folder."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "bwrap").write_text(SCRIPT)
    (folder / "bwrap").chmod(0o755)
    return folder
