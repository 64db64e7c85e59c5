"""Build the student kit: what students receive, generated from
student_template/ and reference/ (`python -m grader kit`, `make student-kit`).

The kit holds the template, the provided renderer and .hdr reader (reference/
without lookup.c, and envmap.h without the lookup declarations), the maps
and scenes the self-check renders, the figures, and the self-check: a driver
compiled with the student's EnvironmentMap.cpp, a stdlib-only Python script,
and the expected data computed here with the grader's reference
(grader/kit/data.py). No lookup code, no solution, no hidden check, no secret.
"""
from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import stat
import subprocess
import tempfile
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from .. import PROJECT_ROOT

TEMPLATE = PROJECT_ROOT / "student_template"
REFERENCE = PROJECT_ROOT / "reference"
DEFAULT_OUT = PROJECT_ROOT / "build" / "student-kit"

# The renderer and .hdr reader: every reference source but the lookup.
RENDERER_SOURCES = ("cross.c", "error.c", "render.c", "rgbe.c", "scene.c", "internal.h", "scene.h")
LOOKUP_SOURCE = "lookup.c"
# The system's stb_image_write (Debian/Ubuntu libstb-dev), copied into the kit.
STB_CANDIDATES = (Path("/usr/include/stb/stb_image_write.h"), Path("/usr/local/include/stb/stb_image_write.h"),
                  Path("/usr/include/stb_image_write.h"))

# What envmap.h declares for lookup.c, cut out of the kit's copy. Each cut is
# a [start, end) pair of lines of envmap.h; both must be found exactly once,
# so a change to the header that moves them fails loudly here.
HEADER_CUTS = (
    ("/* ---- lookups (lookup.c)", "/* ---- scenes and rendering"),
    ("/* A ready-made em_lookup_fn over a cube map", "#ifdef __cplusplus\n}"),
)
HEADER_NOTE = ("/* ---- lookups ------------------------------------------------------------ */\n\n"
               "/* The environment lookup is yours to write: fetchColor and readTexture in\n"
               " * EnvironmentMap.cpp. The renderer calls it through em_lookup_fn (below). */\n\n")

# Checks the kit cannot run on the student's machine, whatever the rubric says.
GRADER_ONLY_CHECKS = {"speed": "the speed verdict needs the grader's reference timing on a quiet machine"}


class KitError(Exception):
    """The kit cannot be built (a missing file, a header that changed shape)."""


def kit_header(text: str) -> str:
    """envmap.h with the lookup declarations cut out."""
    for start, end in HEADER_CUTS:
        if text.count(start) != 1 or text.count(end) != 1:
            raise KitError(f"reference/include/envmap.h: expected exactly one {start!r} and one {end!r}; "
                           "update HEADER_CUTS in grader/kit/build.py")
        i, j = text.index(start), text.index(end)
        if j <= i:
            raise KitError(f"reference/include/envmap.h: {end!r} comes before {start!r}")
        note = HEADER_NOTE if start.startswith("/* ---- lookups") else ""
        text = text[:i] + note + text[j:]
    return text.replace(
        " * envmap.h - the reference implementation of the cube-map environment-mapping\n"
        " * assignment (../shared/ASSIGNMENT.md is the contract), as a C11 library with\n"
        " * no dependencies beyond libc and libm.",
        " * envmap.h - the provided part of the environment-mapping assignment: the\n"
        " * .hdr reader, cube-map faces, scenes and the ray tracer, in C11 with no\n"
        " * dependencies beyond libc and libm. The lookup is yours (EnvironmentMap.cpp).")


def lookup_names(lookup_source: Path = REFERENCE / "src" / LOOKUP_SOURCE) -> list[str]:
    """The names lookup.c defines (functions, types, the (u, v) table, its
    fields and axis constants): none of them may appear in the kit. Only
    names with an underscore: a plain word like `texel` is everyone's."""
    text = lookup_source.read_text()
    names = set(re.findall(r"^(?:static\s+)?(?:inline\s+)?(?:const\s+)?\w+\s*\**\s*([A-Za-z_]\w*)\s*\(", text, re.M))
    names |= set(re.findall(r"^static\s+const\s+\w+\s+(\w+)\s*\[", text, re.M))
    names |= set(re.findall(r"^typedef\s+(?:struct|enum)\s+(\w+)", text, re.M))
    names |= set(re.findall(r"\b([uv]_(?:axis|sign)|AXIS_[XYZ])\b", text))
    names |= set(re.findall(r"\b(em_\w+|EM_FILTER_\w+)\s*\(", text))
    names |= {"em_filter", "EM_FILTER_BILINEAR", "EM_FILTER_NEAREST", "EM_FILTER_SEAMLESS", "em_cubemap_lookup"}
    # em_* functions the kit's renderer does provide (declared in its envmap.h).
    provided = set(re.findall(r"\b(em_\w+)\s*\(", kit_header((REFERENCE / "include" / "envmap.h").read_text())))
    return sorted(n for n in names - provided if "_" in n)


@dataclass
class Kit:
    folder: Path
    zip_path: Path
    files: list[str] = field(default_factory=list)

    @property
    def size(self) -> int:
        return self.zip_path.stat().st_size


def _stb_header() -> Path:
    for path in STB_CANDIDATES:
        if path.is_file():
            return path
    raise KitError("stb_image_write.h not found: install libstb-dev (Debian/Ubuntu: apt-get install libstb-dev)")


def _visible_rubric(rubric: dict) -> dict:
    """The visible checks' points and partial-credit rules (no secret, no
    hidden check), in the rubric's order (the order checks run in: later
    ones use read_texture's finding), as the kit scores them."""
    from ..checks import all_checks
    titles = {name: c.title for name, c in all_checks().items()}
    out = []
    for name, entry in rubric.get("checks", {}).items():
        if entry.get("visibility", "visible") != "visible" or name in GRADER_ONLY_CHECKS:
            continue
        out.append({"name": name, "points": float(entry.get("points", 0)),
                    "partial": entry.get("partial", "fraction"), "title": titles.get(name, name)})
    return out


def _catalogue() -> dict:
    from ..diagnoses import CATALOGUE, CONSEQUENCES, KINDS
    # What the self-check can find: not the build's or the speed check's entries.
    entries = {i: {"kind": e.kind, "title": e.title, "explanation": e.explanation, "what_to_do": e.what_to_do}
               for i, e in CATALOGUE.items() if e.kind not in ("build", "speed")}
    return {"entries": entries, "consequences": sorted(CONSEQUENCES),
            "kinds": {k: v for k, v in KINDS.items() if k not in ("build", "speed")}}


def _copy_template(dest: Path) -> list[Path]:
    """student_template/ as it is in git terms: no build outputs."""
    skip_dirs = {"build", "__pycache__"}
    skip_files = {"envmap", "envmap.exe", "out.png", "out.hdr"}
    copied = []
    for src in sorted(TEMPLATE.rglob("*")):
        rel = src.relative_to(TEMPLATE)
        if any(part in skip_dirs for part in rel.parts) or src.name in skip_files or not src.is_file():
            continue
        target = dest / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(src, target)
        copied.append(target)
    return copied


def build_kit(out: Path = DEFAULT_OUT, zip_path: Path | None = None) -> Kit:
    """Write the kit into `out` (replaced) and `out`.zip; returns both."""
    from .. import reference
    from ..score import load_rubric
    from .data import dump, write_data

    out = Path(out)
    zip_path = Path(zip_path) if zip_path else out.with_suffix(".zip")
    rubric = load_rubric()
    reference.ensure_built()
    with tempfile.TemporaryDirectory(prefix=".kit-", dir=out.parent if out.parent.exists() else None) as tmp:
        staging = Path(tmp) / out.name
        staging.mkdir(parents=True)
        _copy_template(staging)
        renderer = staging / "renderer"
        (renderer / "include").mkdir(parents=True)
        (renderer / "src").mkdir(parents=True)
        (renderer / "include" / "envmap.h").write_text(kit_header((REFERENCE / "include" / "envmap.h").read_text()))
        for name in RENDERER_SOURCES:
            shutil.copyfile(REFERENCE / "src" / name, renderer / "src" / name)
        (staging / "third_party").mkdir()
        shutil.copyfile(_stb_header(), staging / "third_party" / "stb_image_write.h")
        # The scene, the maps and scenes the self-check renders, the figures.
        shutil.copyfile(PROJECT_ROOT / "envmap_test.cfg", staging / "envmap_test.cfg")
        for folder, pattern in (("Cubemap", "*.hdr"), ("scenes", "*.cfg")):
            (staging / folder).mkdir(exist_ok=True)
            for path in sorted((PROJECT_ROOT / folder).glob(pattern)):
                shutil.copyfile(path, staging / folder / path.name)
        (staging / "figures").mkdir(exist_ok=True)
        for name in ("cross_layout.png", "face_uv.png"):
            shutil.copyfile(PROJECT_ROOT / "docs" / "figures" / name, staging / "figures" / name)
        # The self-check's expected data.
        data_dir = staging / "selfcheck" / "data"
        checks = write_data(data_dir, staging / "Cubemap" / "test_environment_map.hdr")
        manifest = {"format": 1, "rubric": _visible_rubric(rubric), "diagnoses": _catalogue(),
                    "grader_only": GRADER_ONLY_CHECKS, "checks": checks}
        dump(manifest, data_dir / "manifest.json")
        files = sorted(p.relative_to(staging).as_posix() for p in staging.rglob("*") if p.is_file())
        if out.exists():
            shutil.rmtree(out)
        out.parent.mkdir(parents=True, exist_ok=True)
        shutil.move(str(staging), str(out))
    write_zip(out, zip_path)
    return Kit(out, zip_path, files)


def write_zip(folder: Path, zip_path: Path) -> None:
    """A reproducible zip of folder (fixed times, sorted names), under one
    top-level folder named like the kit."""
    zip_path.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(dir=zip_path.parent, prefix=".kit-", suffix=".zip")
    os.close(fd)
    tmp = Path(name)
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED, compresslevel=9) as z:
        for path in sorted(p for p in folder.rglob("*") if p.is_file()):
            info = zipfile.ZipInfo(f"{folder.name}/{path.relative_to(folder).as_posix()}", date_time=(2026, 1, 1, 0, 0, 0))
            info.external_attr = (0o644 | stat.S_IFREG) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, path.read_bytes(), compresslevel=9)
    tmp.chmod(0o644)   # mkstemp makes it private; the kit is for handing out
    os.replace(tmp, zip_path)
