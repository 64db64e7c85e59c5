"""`python -m grader bundle`: copy the reference sources (and the scene, the
test map and the convention figures, when they exist) into student_template/.

The originals stay the one source of truth: the copies in the template are
regenerated here, never edited, and tests/test_template.py checks that they
are identical to the originals.
"""
from __future__ import annotations

import argparse
import filecmp
import shutil
from dataclasses import dataclass
from pathlib import Path

from .. import PROJECT_ROOT

HELP = "copy the reference sources into student_template/"

TEMPLATE = PROJECT_ROOT / "student_template"


@dataclass(frozen=True)
class BundledFile:
    source: Path        # the original, in the project
    destination: Path   # its copy, in the template


def bundled_files(root: Path = PROJECT_ROOT, template: Path | None = None) -> list[BundledFile]:
    """Every file the template receives from the project, as it is now. The
    reference sources are required; the scene, the test map and the figures
    are copied when they exist."""
    template = template or root / "student_template"
    files = [BundledFile(root / "reference" / "include" / "envmap.h",
                         template / "reference" / "include" / "envmap.h")]
    for pattern in ("*.c", "*.h"):
        for path in sorted((root / "reference" / "src").glob(pattern)):
            files.append(BundledFile(path, template / "reference" / "src" / path.name))
    optional = [
        (root / "envmap_test.cfg", template / "envmap_test.cfg"),
        (root / "Cubemap" / "test_environment_map.hdr", template / "Cubemap" / "test_environment_map.hdr"),
        (root / "docs" / "figures" / "cross_layout.png", template / "figures" / "cross_layout.png"),
        (root / "docs" / "figures" / "face_uv.png", template / "figures" / "face_uv.png"),
    ]
    files += [BundledFile(src, dst) for src, dst in optional if src.is_file()]
    return files


def stale_copies(root: Path = PROJECT_ROOT, template: Path | None = None) -> list[Path]:
    """Copies in the template's reference/ whose original no longer exists."""
    template = template or root / "student_template"
    wanted = {f.destination for f in bundled_files(root, template)}
    copies = sorted(p for p in (template / "reference").rglob("*") if p.is_file())
    return [p for p in copies if p not in wanted]


def differences(root: Path = PROJECT_ROOT, template: Path | None = None) -> list[str]:
    """What `bundle` would change, one line each (empty when up to date)."""
    out = []
    for f in bundled_files(root, template):
        if not f.destination.is_file():
            out.append(f"missing {f.destination.relative_to(root)}")
        elif not filecmp.cmp(f.source, f.destination, shallow=False):
            out.append(f"differs {f.destination.relative_to(root)}")
    out += [f"stale {p.relative_to(root)}" for p in stale_copies(root, template)]
    return out


def bundle(root: Path = PROJECT_ROOT, template: Path | None = None) -> list[str]:
    """Bring the template's copies up to date; returns what changed."""
    changes = differences(root, template)
    for f in bundled_files(root, template):
        f.destination.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(f.source, f.destination)
    for path in stale_copies(root, template):
        path.unlink()
    return changes


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--check", action="store_true",
                        help="change nothing; exit 1 when the template's copies are out of date")


def run(args: argparse.Namespace) -> int:
    if args.check:
        changes = differences()
        for line in changes:
            print(line)
        return 1 if changes else 0
    changes = bundle()
    for line in changes:
        print(line)
    print(f"student_template/ is up to date ({len(bundled_files())} bundled files)")
    return 0
