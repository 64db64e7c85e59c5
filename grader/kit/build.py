"""Build the student kit: what students receive, generated from
student_template/ and reference/ (`python -m grader kit`, `make student-kit`).

The kit holds the template, the provided renderer and .hdr reader (reference/
without lookup.c, and envmap.h without the lookup declarations), the maps
and scenes, the figures, and the self-check: in selfcheck/, a copy of the
part of the checkout the grader's self-check entry point needs, at the same
paths (grader.PROJECT_ROOT is selfcheck/ there):

    grader/          the modules grader.kit.selfcheck imports, found by
                     following its imports (grader_modules), and the files
                     they read: the shim and worker C sources the build and
                     the worker compile, the visible rubric (no secret), the
                     diagnosis catalogue (a module), the locale compiled (.mo)
    reference/       the renderer's C and the cut envmap.h (the library the
                     checks trace and resolve with; selfcheck/Makefile builds it)
    student_template/ the API headers and loader the grader builds with
    Cubemap/ scenes/ envmap_test.cfg fixtures/renders/
                     the renders check's inputs and the reference renders
    reference_answers.npz
                     the lookup's answers on the kit's inputs (answers.py)
    requirements-kit.txt, bootstrap.py
                     the packages the first `make selfcheck` installs
                     (environment.py), and what installs them

Pristine copies: a student who edits envmap_test.cfg or a header at the
kit's root (as the handout invites) does not change what is checked, as on
submission. No lookup code, no solution, no hidden check, no secret.
"""
from __future__ import annotations

import json
import modulefinder
import os
import re
import shutil
import stat
import tempfile
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from .. import PROJECT_ROOT
from . import integrity
from ..worker.native import SOURCES as WORKER_SOURCES

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

# The kit's copy of the checkout (grader.PROJECT_ROOT in the kit).
SELFCHECK = "selfcheck"
ENTRY_POINT = "grader.kit.selfcheck"
# What only the speed check's run reaches (the study's chart, its baseline
# timings), which the kit leaves out (grader.kit.NOT_IN_KIT): not followed.
NOT_FOLLOWED = ("grader.study",)
# Files beside the modules that they read (grader-relative): the build's
# shim (grader.build.common._shim_files), the worker's source (grader.worker.native),
# report.html's templates and stylesheet (grader.reports.templating).
# The null submission and reference_submission.c serve only speed.
GRADER_FILES = ("build/shim/shim.cpp", "build/shim/submission_abi.h",
                "reports/templates/report.html", "reports/templates/page.html", "reports/templates/figure.html",
                "reports/templates/report.css",
                *(f"worker/{path.name}" for path in WORKER_SOURCES if path.parent.name == "worker"))
# What the kit's rubric keeps of [grading] (never the secret); [checks] whole.
GRADING_KEYS = ("language",)


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
        " * assignment (docs/assignment.md is the contract), as a C11 library with\n"
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


def grader_modules(entry: str = ENTRY_POINT) -> list[str]:
    """The `grader` modules the kit's entry point imports, directly or not
    (the standard library's modulefinder, which also sees imports inside
    functions), and the check modules grader.checks imports by name. Their
    files, grader-relative, sorted."""
    from ..checks import MODULES
    finder = modulefinder.ModuleFinder(path=[str(PROJECT_ROOT)], excludes=list(NOT_FOLLOWED))
    for name in (entry, *(f"grader.checks.{m}" for m in MODULES)):
        finder.import_hook(name)
    package = PROJECT_ROOT / "grader"
    files = {Path(m.__file__).resolve().relative_to(package).as_posix()
             for name, m in finder.modules.items() if name.split(".")[0] == "grader" and m.__file__}
    return sorted(files)


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)   # a TOML basic string
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise KitError(f"grader/grading/rubric.toml: the kit cannot write the value {value!r}")


def visible_rubric(rubric: dict) -> str:
    """rubric.toml for the kit: the course's language and every check's
    table (points, partial credit, settings), no secret. A check that is not
    visible cannot ship (its code would): KitError."""
    hidden = [n for n, e in rubric.get("checks", {}).items() if e.get("visibility", "visible") != "visible"]
    if hidden:
        raise KitError(f"grader/grading/rubric.toml: {', '.join(hidden)} {'is' if len(hidden) == 1 else 'are'} not visible; "
                       "the kit runs the grader's own check code and cannot leave one out: make them visible "
                       "for the kit, or build it from a rubric without them")
    lines = ["# The course's rubric as the self-check uses it (written by grader/kit/build.py):",
             "# the visible checks' points and settings; no secret."]
    grading = {k: v for k, v in rubric.get("grading", {}).items() if k in GRADING_KEYS}
    lines += ["", "[grading]"] + [f"{k} = {_toml_value(v)}" for k, v in grading.items()]
    for name, entry in rubric.get("checks", {}).items():
        lines += ["", f"[checks.{name}]"] + [f"{k} = {_toml_value(v)}" for k, v in entry.items()]
    return "\n".join(lines) + "\n"


def _copy(src: Path, dest: Path) -> None:
    dest.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(src, dest)


def write_selfcheck(root: Path, artifacts: Path) -> None:
    """The kit's copy of the checkout under `root` (selfcheck/): the grader's
    modules and files, the renderer, the template's API, the render inputs
    and reference renders, the recorded answers."""
    from ..grading import fixtures
    from .. import i18n
    from ..build.include_policy import API_HEADERS
    from ..grading.score import load_rubric
    from . import answers, environment
    package = PROJECT_ROOT / "grader"
    for rel in grader_modules() + list(GRADER_FILES):
        _copy(package / rel, root / "grader" / rel)
    (root / "grader" / "grading" / "rubric.toml").write_text(visible_rubric(load_rubric()))
    i18n.compile_catalogues(root / i18n.LOCALE_DIR.relative_to(PROJECT_ROOT))   # .mo only: the kit has no Babel
    (root / "reference" / "include").mkdir(parents=True)
    (root / "reference" / "include" / "envmap.h").write_text(kit_header((REFERENCE / "include" / "envmap.h").read_text()))
    for name in RENDERER_SOURCES:
        _copy(REFERENCE / "src" / name, root / "reference" / "src" / name)
    for name in (*API_HEADERS, "EnvironmentMapLoader.cpp"):
        _copy(TEMPLATE / name, root / "student_template" / name)
    fixtures.check_stale()          # the kit's renders must be the reference's of today
    for fixture in fixtures.render_fixtures():
        for path in (fixture.scene, fixture.map, fixture.path):
            _copy(path, root / Path(os.path.normpath(path)).relative_to(PROJECT_ROOT))
    answers.record(root / answers.ANSWERS, artifacts)
    environment.write_requirements(root)      # what bootstrap.py installs on first use


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
    from ..envmap import library

    out = Path(out)
    zip_path = Path(zip_path) if zip_path else out.with_suffix(".zip")
    library.ensure_built()
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
        # The scene, the maps and scenes to render and play with, the figures.
        shutil.copyfile(PROJECT_ROOT / "envmap_test.cfg", staging / "envmap_test.cfg")
        for folder, pattern in (("Cubemap", "*.hdr"), ("scenes", "*.cfg")):
            (staging / folder).mkdir(exist_ok=True)
            for path in sorted((PROJECT_ROOT / folder).glob(pattern)):
                shutil.copyfile(path, staging / folder / path.name)
        (staging / "figures").mkdir(exist_ok=True)
        for name in ("cross_layout.png", "face_uv.png"):
            shutil.copyfile(PROJECT_ROOT / "docs" / "figures" / name, staging / "figures" / name)
        write_selfcheck(staging / SELFCHECK, Path(tmp) / "recording")
        integrity.write_manifest(staging / SELFCHECK)     # last: what the self-check compares
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
