"""Our part of every library: the template's loader, the shim and the
reference C the loader needs, compiled once per cache folder (and copied
from the default cache when it holds them under the same key), with the
API headers (EnvironmentMap.h precompiled) and the symbols a submission may
use.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from .. import PROJECT_ROOT
from .compiler import CC, CXX, Deadline, HarnessBuildError, compile_flags, run_compiler, compiler_versions
from .include_policy import API_HEADERS
from .objects import LINKER_SYMBOLS, defined_symbols, runtime_library_paths, object_symbols

TEMPLATE = PROJECT_ROOT / "student_template"
REFERENCE = PROJECT_ROOT / "reference"
SHIM = PROJECT_ROOT / "grader" / "build" / "shim"
DEFAULT_CACHE = PROJECT_ROOT / "build" / "submissions"
# EnvironmentMap.h (with the standard headers it includes) precompiled with the
# student's flags: parsing them was 3/4 of the compile (0.24 of 0.32 s CPU).
# GCC takes it for a source whose first #include is EnvironmentMap.h and the
# flags match, and silently reads the header otherwise (other --flags, another
# first include): the same code either way. Not for sanitizer builds, whose
# debug information would name the common folder instead of the scratch one.
PRECOMPILED_HEADER = "EnvironmentMap.h.gch"
# The reference sources EnvironmentMapLoader.cpp needs (reading a .hdr
# cross); the lookup, renderer and scene parser are never linked.
LOADER_REFERENCE_SOURCES = ("cross.c", "error.c", "rgbe.c")


def _template_files() -> list[Path]:
    return [TEMPLATE / name for name in API_HEADERS] + [TEMPLATE / "EnvironmentMapLoader.cpp"]


def _reference_files() -> list[Path]:
    return ([REFERENCE / "include" / "envmap.h"] + sorted((REFERENCE / "src").glob("*.h"))
            + [REFERENCE / "src" / name for name in LOADER_REFERENCE_SOURCES])


def _shim_files() -> list[Path]:
    return [SHIM / "shim.cpp", SHIM / "submission_abi.h"]


def fingerprint(paths: list[Path], *extra: str) -> str:
    """sha256 over file names and contents (relative to the project) and extra strings."""
    h = hashlib.sha256()
    for path in paths:
        h.update(str(path.relative_to(PROJECT_ROOT)).encode() + b"\0")
        h.update(hashlib.sha256(path.read_bytes()).digest())
    for item in extra:
        h.update(item.encode() + b"\0")
    return h.hexdigest()


def publish(tmp: Path, final: Path) -> None:
    """Atomically move a finished build into the cache; a concurrent twin wins harmlessly."""
    tmp.chmod(0o755)  # mkdtemp makes it private; the sandboxed worker must read it
    try:
        os.rename(tmp, final)
    except OSError:
        if not final.is_dir():
            raise
        shutil.rmtree(tmp, ignore_errors=True)


# ---- our part: template loader, shim and reference, built once per cache -------

_common_lock = threading.Lock()  # threads of one process build our objects once
# Changes whenever what a common folder holds changes (an older one is not reused).
COMMON_LAYOUT = "common-3: scratch copies, allowed and reference symbols, precompiled API header"
COMMON_FILES = ("loader.o", "shim.o", "libreference.a", "exports.map", "allowed-symbols.txt",
                "reference-symbols.txt")


def common_objects(cache_dir: Path, sanitize: bool) -> Path:
    """Our objects, built once per cache: loader.o and shim.o (always linked),
    libreference.a (the reference C the loader needs), exports.map, the API
    headers (include/, with EnvironmentMap.h precompiled) and the symbols a
    submission may use (allowed-symbols.txt). A cache other than
    DEFAULT_CACHE copies them from there when it holds them under the same
    key (the same sources, flags, compilers and runtime libraries): building
    them costs about 3 s of CPU, and test suites make many caches."""
    with _common_lock:
        seed = Path(DEFAULT_CACHE)
        return _build_common_objects(cache_dir, sanitize, seed if Path(cache_dir) != seed else None)


def _build_common_objects(cache_dir: Path, sanitize: bool, seed: Path | None = None) -> Path:
    missing = [str(p.relative_to(PROJECT_ROOT)) for p in _template_files() + _reference_files() + _shim_files()
               if not p.is_file()]
    if missing:
        raise HarnessBuildError(f"the grader's own build inputs are missing: {', '.join(missing)}")
    cxxflags, cflags = compile_flags(sanitize)
    libraries = runtime_library_paths(sanitize)
    key = fingerprint(_template_files() + _reference_files() + _shim_files(),
                       COMMON_LAYOUT, compiler_versions(), *cxxflags, "|", *cflags, "|",
                       *(f"{p}:{p.stat().st_size}:{p.stat().st_mtime_ns}" for p in libraries))
    final = cache_dir / f"common-{key[:24]}"
    if (final / "reference-symbols.txt").is_file():
        return final
    cache_dir.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=".tmp-common-", dir=cache_dir))
    built = seed / final.name if seed is not None else None
    if built is not None and (built / "reference-symbols.txt").is_file():
        # Published folders are complete (publish renames a finished one in).
        try:
            shutil.copytree(built, tmp, dirs_exist_ok=True)
            publish(tmp, final)
        except BaseException:
            shutil.rmtree(tmp, ignore_errors=True)
            raise
        return final
    includes = [f"-I{TEMPLATE}", f"-I{REFERENCE / 'include'}", f"-I{SHIM}"]
    jobs = [[CXX, *cxxflags, *includes, "-c", str(TEMPLATE / "EnvironmentMapLoader.cpp"), "-o", "loader.o"],
            [CXX, *cxxflags, *includes, "-c", str(SHIM / "shim.cpp"), "-o", "shim.o"]]
    reference_objects = []
    for name in LOADER_REFERENCE_SOURCES:
        src = REFERENCE / "src" / name
        jobs.append([CC, *cflags, f"-I{REFERENCE / 'include'}", "-c", str(src), "-o", f"ref_{src.stem}.o"])
        reference_objects.append(f"ref_{src.stem}.o")
    archive = ["ar", "rcs", "libreference.a", *reference_objects]
    with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        steps = list(pool.map(lambda cmd: run_compiler(cmd, tmp, Deadline.of(600)), jobs))
    steps.append(run_compiler(archive, tmp, Deadline.of(600)))
    for cmd, step in zip(jobs + [archive], steps):
        if step.returncode != 0 or step.timed_out:
            shutil.rmtree(tmp, ignore_errors=True)
            raise HarnessBuildError(f"{' '.join(cmd)}\n{step.output}")
    # Only the ABI leaves the library: the reference's em_* symbols inside it
    # can never be confused with the grader's own reference library.
    (tmp / "exports.map").write_text("{\n  global: sub_*;\n  local: *;\n};\n")
    (tmp / "include").mkdir()
    for name in API_HEADERS:
        shutil.copyfile(TEMPLATE / name, tmp / "include" / name)
    if not sanitize:
        pch = [CXX, *cxxflags, f"-I{tmp / 'include'}", "-x", "c++-header", str(tmp / "include" / API_HEADERS[0]),
               "-o", str(tmp / "include" / PRECOMPILED_HEADER)]
        step = run_compiler(pch, tmp, Deadline.of(600))
        if step.returncode != 0 or step.timed_out:
            shutil.rmtree(tmp, ignore_errors=True)
            raise HarnessBuildError(f"{' '.join(pch)}\n{step.output}")
    # What a student's object may leave undefined: the runtime libraries,
    # the linker's own symbols and the template's EnvironmentMap members
    # (loader.o). Never the reference's em_*.
    allowed = defined_symbols(libraries) | LINKER_SYMBOLS
    allowed |= {name for name, bind, defined in object_symbols((tmp / "loader.o").read_bytes())[1]
                if defined and bind != 0 and not name.startswith("em_")}
    (tmp / "allowed-symbols.txt").write_text("\n".join(sorted(allowed)) + "\n")
    # The reference code's own global names: a submission defining one would
    # silently replace it inside the loader.
    ours = {name for obj in reference_objects for name, bind, defined
            in object_symbols((tmp / obj).read_bytes())[1] if defined and bind == 1}
    (tmp / "reference-symbols.txt").write_text("\n".join(sorted(ours)) + "\n")
    publish(tmp, final)
    return final
