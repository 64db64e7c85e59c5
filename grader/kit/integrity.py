"""The kit's own files as built: a list of their digests, written by the kit
build into selfcheck/ and compared by the self-check before it grades. A
student who edits the kit's copy of the grader, its rubric or its recorded
answers would otherwise get a score the grader never gives (a hidden check
is a full score; issue 20's red team): the self-check then says what changed
and gives no score. It guards against edits, not against a student who
edits this check too: the score that counts is always the grader's.

Line ends are compared as LF, so that a kit checked out through git with
CRLF conversion (Windows, core.autocrlf) is not taken for an edited one.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

from .. import in_build_output

MANIFEST = "kit_files.json"
# Made by running the self-check: Python's caches (and the reference's
# build outputs, in_build_output: the grader's build package is the kit's own).
GENERATED = ("__pycache__",)


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes().replace(b"\r\n", b"\n")).hexdigest()


def _files(root: Path) -> dict[str, str]:
    return {p.relative_to(root).as_posix(): _digest(p) for p in sorted(root.rglob("*"))
            if p.is_file() and p.name != MANIFEST
            and not any(part in GENERATED for part in p.relative_to(root).parts)
            and not in_build_output(p.relative_to(root).parts)}


def write_manifest(root: Path) -> None:
    (root / MANIFEST).write_text(json.dumps(_files(root), indent=0, sort_keys=True) + "\n")


def changed_files(root: Path) -> list[str]:
    """The kit's files under `root` that differ from the build's list, were
    added or are missing (sorted); ["kit_files.json"] when the list itself is gone."""
    try:
        built = json.loads((root / MANIFEST).read_text())
    except (OSError, ValueError):
        return [MANIFEST]
    now = _files(root)
    return sorted(name for name in built.keys() | now.keys() if built.get(name) != now.get(name))


def edited_api_files(kit: Path, root: Path) -> list[str]:
    """The provided files in the kit's folder `kit` (its API headers and
    loader) that differ from the course's copies under `root`
    (student_template/): grading compiles EnvironmentMap.cpp with the
    course's, so an edit there builds with `make` but not when graded."""
    from ..build.include_policy import API_HEADERS
    return [name for name in (*API_HEADERS, "EnvironmentMapLoader.cpp")
            if (kit / name).is_file() and _digest(kit / name) != _digest(root / "student_template" / name)]
