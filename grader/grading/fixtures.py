"""fixtures/: what the checks compare against, regenerated from the reference
with one command (`make fixtures`), and a manifest that says when they are stale.

fixtures/manifest.json records the SHA-256 of every fixture file and of
everything that determines their content (reference sources, scene files,
maps), with the render settings and GENERATOR_VERSION. Not this module's text:
moving or re-wording it must not stale the fixtures. The grader checks the
manifest at start and refuses stale fixtures with a message naming what
changed (`--allow-stale` overrides).
Everything here is deterministic: two runs write identical bytes.

The manifest also records the environment that made the fixtures: the
versions of the libraries the render comparison depends on (numpy, which
also computes SSIM, flip-evaluator, OpenImageIO) and of the compilers that built
the reference. The render thresholds (SSIM, FLIP) were measured with them:
grading elsewhere adds a warning to the report (environment_warnings), and
`grade --strict` refuses (EnvironmentMismatch). requirements.lock pins them.
"""
from __future__ import annotations

import functools
import hashlib
import io
import json
import os
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import PROJECT_ROOT
from ..envmap import library

FIXTURES = PROJECT_ROOT / "fixtures"
MANIFEST = FIXTURES / "manifest.json"
# Bump when what this module writes changes meaning (its text is not hashed).
GENERATOR_VERSION = 2

# Full renders: small enough to keep in git, large enough that every mistake
# in the zoo moves SSIM well past its threshold (docs/fixtures.md).
RENDER_SIZE = (128, 128)
RENDER_SPP = 4
MAIN_SCENE = PROJECT_ROOT / "envmap_test.cfg"


# What the manifest's "environment" records: Python distributions (by their
# package names) and compilers (by command).
LIBRARIES = ("numpy", "flip-evaluator", "OpenImageIO")
COMPILERS = ("cc", "g++")


class StaleFixtures(Exception):
    pass


class EnvironmentMismatch(StaleFixtures):
    """`--strict`: the libraries or compilers differ from those that made the
    fixtures. A kind of StaleFixtures: the fixtures do not fit this machine."""


@dataclass(frozen=True)
class RenderFixture:
    scene: Path        # scene file (camera, spheres)
    map: Path          # environment map it is rendered with

    @property
    def name(self) -> str:
        return f"{self.scene.stem}--{self.map.stem}"

    @property
    def path(self) -> Path:
        # Raw float32 .npy: exact (RGBE's 0.4% rounding was the largest error
        # a correct submission saw, docs/thresholds.md) and byte-stable
        # (OpenImageIO stamps EXR files with the time).
        return FIXTURES / "renders" / f"{self.name}.npy"

    def load(self) -> np.ndarray:
        """The reference render, (H, W, 3) float32 linear."""
        return np.load(self.path, allow_pickle=False)


def maps() -> list[Path]:
    return sorted((PROJECT_ROOT / "Cubemap").glob("*.hdr"))


def render_fixtures() -> list[RenderFixture]:
    """The main scene with every map in Cubemap/, then every extra scene in
    scenes/ with its own map."""
    out = [RenderFixture(MAIN_SCENE, m) for m in maps()]
    for scene_path in sorted((PROJECT_ROOT / "scenes").glob("*.cfg")):
        out.append(RenderFixture(scene_path, library.Scene.load(scene_path).environment_path))
    return out


def prepared_scene(fixture: RenderFixture) -> library.Scene:
    scene = library.Scene.load(fixture.scene)
    scene.set_resolution(*RENDER_SIZE)
    scene.set_samples(RENDER_SPP)
    return scene


def inputs(project: Path = PROJECT_ROOT) -> list[Path]:
    """The files the fixtures' content depends on (with render_settings()
    and GENERATOR_VERSION, which the manifest records beside them)."""
    ref = sorted((project / "reference").glob("src/*.[ch]")) + [project / "reference" / "include" / "envmap.h"]
    scenes = [project / MAIN_SCENE.name] + sorted((project / "scenes").glob("*.cfg"))
    return ref + scenes + sorted((project / "Cubemap").glob("*.hdr"))


def render_settings() -> dict:
    return {"width": RENDER_SIZE[0], "height": RENDER_SIZE[1], "samples_per_pixel": RENDER_SPP}


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _rel(path: Path, project: Path = PROJECT_ROOT) -> str:
    return path.resolve().relative_to(project.resolve()).as_posix()


def _write_atomic(path: Path, data: bytes) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".tmp-")
    with os.fdopen(fd, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def generate(progress=print) -> dict:
    """Regenerate every fixture and the manifest; returns the manifest."""
    files: list[Path] = []
    for fixture in render_fixtures():
        cube = library.CubeMap.load_cross(fixture.map)
        image = prepared_scene(fixture).render(cube, "bilinear")
        buffer = io.BytesIO()
        np.save(buffer, np.ascontiguousarray(image, np.float32), allow_pickle=False)
        _write_atomic(fixture.path, buffer.getvalue())
        files.append(fixture.path)
        progress(f"  rendered {_rel(fixture.path)}")
    manifest = {
        "generator_version": GENERATOR_VERSION,
        "environment": environment(),
        "inputs": {_rel(p): _sha256(p) for p in inputs()},
        "files": {_rel(p): _sha256(p) for p in files},
        "render": render_settings(),
    }
    _write_atomic(MANIFEST, (json.dumps(manifest, indent=2, sort_keys=True) + "\n").encode())
    return manifest


def check_stale(project: Path = PROJECT_ROOT) -> None:
    """Raise StaleFixtures naming what changed since `make fixtures` last ran."""
    manifest_path = project / MANIFEST.relative_to(PROJECT_ROOT)
    if not manifest_path.exists():
        raise StaleFixtures("fixtures/manifest.json is missing: run `make fixtures`.")
    manifest = json.loads(manifest_path.read_text())
    problems = []
    if manifest.get("generator_version") != GENERATOR_VERSION:
        problems.append("the fixture generator changed")
    if manifest.get("render") != render_settings():
        problems.append("the render size or samples per pixel changed")
    recorded = manifest.get("inputs", {})
    current = {_rel(p, project): _sha256(p) for p in inputs(project)}
    for name in sorted(set(recorded) | set(current)):
        if name not in current:
            problems.append(f"{name} was removed")
        elif name not in recorded:
            problems.append(f"{name} is new")
        elif recorded[name] != current[name]:
            problems.append(f"{name} changed")
    for name, digest in sorted(manifest.get("files", {}).items()):
        path = project / name
        if not path.exists():
            problems.append(f"fixture {name} is missing")
        elif _sha256(path) != digest:
            problems.append(f"fixture {name} was edited by hand")
    if problems:
        raise StaleFixtures("Fixtures are stale: " + "; ".join(problems)
                            + ". Run `make fixtures` to regenerate them (or pass --allow-stale).")


# ---- the environment the fixtures were made in ---------------------------------------


def _library_version(name: str) -> str:
    from importlib import metadata
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return "not installed"


@functools.lru_cache(maxsize=None)
def _compiler_version(command: str) -> str:
    """The first line of `command --version` (e.g. "gcc (Debian 12.2.0-14) 12.2.0")."""
    try:
        done = subprocess.run([command, "--version"], capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return "not found"
    lines = done.stdout.strip().splitlines()
    return lines[0].strip() if done.returncode == 0 and lines else "not found"


def environment() -> dict:
    """What fixtures/manifest.json records about this machine."""
    return {"libraries": {name: _library_version(name) for name in LIBRARIES},
            "compilers": {command: _compiler_version(command) for command in COMPILERS}}


def environment_warnings(project: Path = PROJECT_ROOT) -> list[str]:
    """One sentence per library or compiler whose version differs from the
    one the fixtures were made with (empty when they match, or when there is
    no manifest: check_stale reports that). For the report's warnings."""
    try:
        recorded = json.loads((project / MANIFEST.relative_to(PROJECT_ROOT)).read_text()).get("environment")
    except (OSError, ValueError):
        return []
    if not isinstance(recorded, dict):
        return ["fixtures/manifest.json does not record the library and compiler versions the fixtures were "
                "made with: run `make fixtures` to record them."]
    out = []
    for kind, current in (("libraries", lambda n: _library_version(n)), ("compilers", _compiler_version)):
        for name, then in sorted(dict(recorded.get(kind) or {}).items()):
            now = current(name)
            if now != then:
                out.append(f"{name} is {now!r} here but the fixtures were made with {then!r}: render scores "
                           "may differ slightly (`make venv` installs the locked versions; `make fixtures` "
                           "re-records them).")
    return out


def check_environment(project: Path = PROJECT_ROOT) -> None:
    """Raise EnvironmentMismatch when environment_warnings() has anything to say."""
    problems = environment_warnings(project)
    if problems:
        raise EnvironmentMismatch("Grading environment differs from the one that made the fixtures: "
                                  + " ".join(problems) + " (--strict refuses; grade without it to only warn.)")
