"""The Python packages the student kit's self-check installs on first use,
pinned and hashed from the grader's own requirements.lock.

The self-check runs the grader's code (a subset of the `grader` package
copied into the kit), so it needs the third-party packages that code
imports. KIT_PACKAGES names them; write_requirements() takes their pins and
hashes, and those of everything they depend on, from requirements.lock: the
kit installs exactly the versions the grader runs, and there is no second
list of versions to drift. Dependencies are read from the lock's own
"# via" annotations (uv writes them), so a new dependency of numpy or rich
comes along with the next lock.

Left out on purpose (the kit's environment is at most 100 MB): scipy,
scikit-image, matplotlib, Babel and Pillow, which the grader uses elsewhere;
the checks the kit runs use numpy instead (image_metrics) and
OpenImageIO for the arrows picture, and the Japanese catalogue goes into the
kit compiled (grader.i18n.compile_catalogues). Pillow only turns PNGs into
Gradescope's HTML (reports.gradescope_json.png_data_url), which the kit never
writes.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from .. import PROJECT_ROOT

LOCK = PROJECT_ROOT / "requirements.lock"
REQUIREMENTS_NAME = "requirements-kit.txt"

# What the kit's copy of the grader imports (top-level distributions, as in
# requirements.txt); their dependencies follow from the lock.
KIT_PACKAGES = (
    "numpy",            # everything
    "cffi",             # grader.envmap.library, which grader.envmap.oracle and the checks import
    "OpenImageIO",      # grader.envmap.imaging: images in and out; the arrows picture's resizing and text
    "flip-evaluator",   # the render check's FLIP
    "markdown-it-py",   # report.html's tables and summary
    "jinja2",           # report.html's template (with markupsafe, its one dependency)
    "rich",             # the terminal summary (grader.reports.terminal); with pygments, 6.5 MB
)


class LockError(Exception):
    """requirements.lock lacks a package the kit needs, or cannot be read."""


@dataclass(frozen=True)
class LockedPackage:
    name: str               # canonical (PEP 503)
    requirement: str        # the pin line as locked, e.g. "pycparser==3.12 ; implementation_name != 'PyPy'"
    hashes: tuple[str, ...]  # "sha256:..."
    required_by: frozenset[str]   # canonical names of the locked packages that depend on it


def canonical(name: str) -> str:
    """PEP 503's normalised name: "OpenImageIO" -> "openimageio"."""
    return re.sub(r"[-_.]+", "-", name).lower()


def read_lock(lock: Path = LOCK) -> dict[str, LockedPackage]:
    """Every package of a uv/pip-compile lock with hashes, by canonical name."""
    packages = {}
    for block in re.split(r"\n(?=\S)", lock.read_text(encoding="utf-8")):
        m = re.match(r"([A-Za-z0-9][A-Za-z0-9._-]*)==([^\s;\\]+)([^\\\n]*)", block)
        if not m:
            continue
        name = canonical(m[1])
        hashes = tuple(re.findall(r"--hash=(sha256:[0-9a-f]{64})", block))
        # "# via" then either one name on the same line or "#   name" lines.
        via = re.findall(r"#\s+via\s+([^\s#]+)|#\s{3,}([^\s#]+)", block)
        parents = {canonical(a or b) for a, b in via if (a or b) != "-r"}      # "-r requirements.txt": a root
        packages[name] = LockedPackage(name, f"{m[1]}=={m[2]}{m[3].rstrip()}", hashes, frozenset(parents))
    if not packages:
        raise LockError(f"{lock}: no pinned package found")
    return packages


def kit_closure(packages: dict[str, LockedPackage], wanted=KIT_PACKAGES) -> list[LockedPackage]:
    """The wanted packages and all they depend on in the lock, sorted by name;
    LockError names any wanted package the lock does not pin."""
    missing = [w for w in wanted if canonical(w) not in packages]
    if missing:
        raise LockError(f"requirements.lock does not pin {', '.join(missing)}, which the student kit needs: "
                        "add it to requirements.txt and run scripts/lock-requirements.sh")
    chosen = {canonical(w) for w in wanted}
    grew = True
    while grew:
        extra = {p.name for p in packages.values() if p.name not in chosen and p.required_by & chosen}
        chosen |= extra
        grew = bool(extra)
    unhashed = sorted(n for n in chosen if not packages[n].hashes)
    if unhashed:
        raise LockError(f"requirements.lock has no hashes for {', '.join(unhashed)}: "
                        "regenerate it with scripts/lock-requirements.sh")
    return [packages[n] for n in sorted(chosen)]


def minimum_python(packages: list[LockedPackage]) -> tuple[int, int]:
    """The oldest Python every one of `packages` supports: the largest lower
    bound of their Requires-Python, read from this environment's installed
    copies (the locked versions: tests/project/test_lock.py holds the venv to the lock)."""
    from importlib import metadata
    floor = (3, 0)
    for package in packages:
        try:
            installed = metadata.metadata(package.name)
        except metadata.PackageNotFoundError:
            raise LockError(f"{package.name} is not installed here, so its Requires-Python is unknown: "
                            "build the kit in the grader's environment (make venv)") from None
        for major, minor in re.findall(r">=\s*(\d+)\.(\d+)", installed.get("Requires-Python") or ""):
            floor = max(floor, (int(major), int(minor)))
    return floor


def requirements_text(lock: Path = LOCK, wanted=KIT_PACKAGES) -> str:
    """requirements-kit.txt's text: pip's hash-checking format, with the
    oldest Python the packages support in a comment the bootstrap reads."""
    packages = kit_closure(read_lock(lock), wanted)
    lines = ["# The student kit's self-check environment: exactly the grader's versions",
             "# (taken from requirements.lock by grader/kit/environment.py; do not edit).",
             "# Installed by selfcheck/bootstrap.py with pip --require-hashes --only-binary :all:.",
             "# requires-python: >=%d.%d" % minimum_python(packages)]
    for package in packages:
        lines.append(package.requirement + " \\")
        lines.extend(f"    --hash={h}" + (" \\" if i < len(package.hashes) - 1 else "")
                     for i, h in enumerate(package.hashes))
    return "\n".join(lines) + "\n"


def write_requirements(dest_dir: Path, lock: Path = LOCK) -> Path:
    """Write dest_dir/requirements-kit.txt; its path."""
    dest_dir = Path(dest_dir)
    dest_dir.mkdir(parents=True, exist_ok=True)
    path = dest_dir / REQUIREMENTS_NAME
    path.write_text(requirements_text(lock), encoding="utf-8")
    return path
