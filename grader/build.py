"""A submission -> a shared library the worker can load (grader/shim/submission_abi.h).

build_submission() accepts a folder, a single .cpp file, or a .zip / .tar.gz
of either; finds the student's EnvironmentMap.cpp in it;
compiles it alone, with our own copies of everything else (the template's
headers and EnvironmentMapLoader.cpp, the reference C sources, the shim);
and links one library exporting only the sub_* entry points.

Builds are cached by content hash under build/submissions/<key>/: the key
covers the student's source, every file of ours that goes into the library,
the flags and the compiler versions. The cache stores the compiler's own
output with paths made neutral; what the student reads (which file, in
which order, friendly sentences) is worked out on every call, so the same
source in a .zip and as a loose file shares one library.

A bad submission never raises: it gives BuildResult(ok=False) with the
reason. Our own sources failing to compile raises HarnessBuildError.
"""
from __future__ import annotations

import functools
import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import tarfile
import tempfile
import threading
import time
import zipfile
from concurrent.futures import ThreadPoolExecutor
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from . import PROJECT_ROOT

TEMPLATE = PROJECT_ROOT / "student_template"
REFERENCE = PROJECT_ROOT / "reference"
SHIM = PROJECT_ROOT / "grader" / "shim"
DEFAULT_CACHE = PROJECT_ROOT / "build" / "submissions"

CXX, CC = "g++", "gcc"
CXXFLAGS = ["-std=c++17", "-O2", "-Wall", "-Wextra", "-fPIC"]
CFLAGS = ["-std=c11", "-O2", "-Wall", "-Wextra", "-fPIC", "-D_POSIX_C_SOURCE=200809L"]
SANITIZE_FLAGS = ["-fsanitize=address,undefined", "-fno-omit-frame-pointer", "-g"]
# Plain messages: no colour, no line wrapping, a bounded number of errors.
DIAGNOSTIC_FLAGS = ["-fdiagnostics-color=never", "-fmessage-length=0", "-fmax-errors=10"]
MEMORY_LIMIT_BYTES = 2 << 30
LIBRARY_NAME = "submission.so"
STUDENT_OBJECT = "EnvironmentMap.o"
# The members of EnvironmentMap a submission defines; the rest are ours.
STUDENT_MEMBERS = ("fetchColor", "readTexture")
MAX_LOG_LINES = 60
MAX_LOG_CHARS = 6000

SOURCE_NAME = "EnvironmentMap.cpp"
# What a submission may be: it holds one small source file, so anything
# far larger is refused rather than read.
MAX_SOURCE_BYTES = 1 << 20
MAX_MEMBERS = 20000
ARCHIVE_SUFFIXES = (".zip", ".tar.gz", ".tgz", ".tar")
# Folders that hold no submission: version control, macOS archive debris.
SKIPPED_DIRS = ("__MACOSX",)


class HarnessBuildError(RuntimeError):
    """Our own sources (template, shim, reference) did not compile: not the student's fault."""


@dataclass
class BuildResult:
    ok: bool
    library: Path | None
    source: Path                  # the EnvironmentMap.cpp used (a copy in the cache for archives)
    log: str = ""                 # for the student: friendly sentences, then compiler messages, errors first
    errors: list[dict] = field(default_factory=list)    # {file, line, message}, line None when unknown
    warnings: list[dict] = field(default_factory=list)  # the same, for warnings
    notes: list[str] = field(default_factory=list)      # which file was chosen and why, ignored files
    sha256: str = ""              # of the student's source
    cached: bool = False
    source_name: str = SOURCE_NAME  # the source's path inside the submission, as messages show it
    timed_out: bool = False


# ---- finding the student's file -----------------------------------------------

Reader = Callable[[], bytes]   # reads one file of a submission (capped at MAX_SOURCE_BYTES)


class SubmissionError(Exception):
    """The submission holds no usable EnvironmentMap.cpp; the message says why."""


@dataclass
class ChosenSource:
    text: bytes
    name: str                 # path inside the submission, e.g. "src/EnvironmentMap.cpp"
    origin: Path | None       # the file on disk, None when it came out of an archive
    notes: list[str]


def _safe_member(name: str) -> str | None:
    """A member path as a relative POSIX path, or None when it is unsafe
    (absolute, '..') or in a folder that holds no submission."""
    parts = [p for p in name.replace("\\", "/").split("/") if p not in ("", ".")]
    if not parts or name.startswith(("/", "\\")) or ".." in parts or re.match(r"^[A-Za-z]:", name):
        return None
    if any(p in SKIPPED_DIRS or p.startswith(".") for p in parts[:-1]):
        return None
    return "/".join(parts)


def _read_capped(stream, what: str) -> bytes:
    with stream:
        data = stream.read(MAX_SOURCE_BYTES + 1)
    if len(data) > MAX_SOURCE_BYTES:
        raise SubmissionError(f"{what} is larger than {MAX_SOURCE_BYTES >> 20} MiB: not a source file.")
    return data


def _archive_files(path: Path, stack: ExitStack) -> dict[str, Reader]:
    """Regular files of a .zip or tar archive: {relative path: reader}, valid
    until `stack` closes. Nothing is extracted to disk, so no member can land
    outside; symbolic links, devices and unsafe paths are skipped."""
    files: dict[str, Reader] = {}
    try:
        if path.name.lower().endswith(".zip"):
            archive = stack.enter_context(zipfile.ZipFile(path))
            members = archive.infolist()
            if len(members) > MAX_MEMBERS:
                raise SubmissionError(f"{path.name} holds more than {MAX_MEMBERS} files.")
            for info in members:
                is_link = (info.external_attr >> 16) & 0o170000 == 0o120000
                name = _safe_member(info.filename)
                if info.is_dir() or is_link or name is None:
                    continue
                files[name] = functools.partial(lambda i: _read_capped(archive.open(i), i.filename), info)
        else:
            archive = stack.enter_context(tarfile.open(path, "r:*"))
            for count, info in enumerate(archive):
                if count >= MAX_MEMBERS:
                    raise SubmissionError(f"{path.name} holds more than {MAX_MEMBERS} files.")
                name = _safe_member(info.name)
                if info.isreg() and name is not None:
                    files[name] = functools.partial(
                        lambda i: _read_capped(archive.extractfile(i), i.name), info)
    except (OSError, EOFError, zipfile.BadZipFile, tarfile.TarError) as exc:
        raise SubmissionError(f"{path.name} cannot be opened as an archive: {exc}") from None
    return files


def _folder_files(path: Path) -> dict[str, Reader]:
    """Regular files below a folder (symbolic links not followed)."""
    files: dict[str, Reader] = {}
    for dirpath, dirnames, filenames in os.walk(path):
        dirnames[:] = sorted(d for d in dirnames if d not in SKIPPED_DIRS and not d.startswith("."))
        for filename in filenames:
            full = Path(dirpath) / filename
            if full.is_symlink() or not full.is_file():
                continue
            files[full.relative_to(path).as_posix()] = functools.partial(
                lambda f: _read_capped(f.open("rb"), f.name), full)
            if len(files) > MAX_MEMBERS:
                raise SubmissionError(f"{path.name} holds more than {MAX_MEMBERS} files.")
    return files


def _depth_then_name(name: str) -> tuple[int, str]:
    return (name.count("/"), name)


def _choose(files: dict[str, Reader], where: str) -> tuple[str, list[str]]:
    """The member to grade and the notes that explain the choice."""
    exact = sorted((n for n in files if n.rsplit("/", 1)[-1] == SOURCE_NAME), key=_depth_then_name)
    if exact:
        notes = []
        if len(exact) > 1:
            same = len({files[n]() for n in exact}) == 1
            notes.append(f"{where} holds {len(exact)} files named {SOURCE_NAME} ({', '.join(exact)}); "
                         f"used {exact[0]}, the one nearest the top (ties: alphabetical order)"
                         + ("; they are identical." if same else "."))
        return exact[0], notes
    other_case = sorted((n for n in files if n.rsplit("/", 1)[-1].lower() == SOURCE_NAME.lower()),
                        key=_depth_then_name)
    if other_case:
        return other_case[0], [f"used {other_case[0]} as {SOURCE_NAME} (the name differs in case)."]
    # A renamed file (e.g. "EnvironmentMap (1).cpp"): the one .cpp that defines fetchColor.
    def defines_fetch_color(name: str) -> bool:
        try:
            return b"EnvironmentMap::fetchColor" in files[name]()
        except SubmissionError:
            return False
    defining = [n for n in sorted(files, key=_depth_then_name)
                if n.endswith(".cpp") and defines_fetch_color(n)]
    if len(defining) == 1:
        return defining[0], [f"no file is named {SOURCE_NAME}; used {defining[0]}, "
                             "the only .cpp file that defines EnvironmentMap::fetchColor."]
    listed = ", ".join(sorted(files)[:10]) or "nothing"
    raise SubmissionError(f"No {SOURCE_NAME} in {where} (it holds: {listed}).")


def _header_notes(files: dict[str, Reader], chosen: str) -> list[str]:
    """Our headers submitted beside the source: used never, reported when changed."""
    folder = chosen.rsplit("/", 1)[0] + "/" if "/" in chosen else ""
    notes = []
    for ours in sorted(TEMPLATE.glob("*.h")):
        theirs = files.get(folder + ours.name)
        if theirs is None:
            continue
        def normal(text: bytes) -> list[bytes]:
            return [line.rstrip() for line in text.replace(b"\r\n", b"\n").strip().split(b"\n")]
        if normal(theirs()) != normal(ours.read_bytes()):
            notes.append(f"submitted {ours.name} differs from ours: ignored "
                         f"(the grader builds with the template's {ours.name}).")
    return notes


_INCLUDE = re.compile(r"^[ \t]*(?:#|%:)[ \t]*(?:include|include_next|import)\b[ \t]*(.*)$", re.M)
_SAFE_HEADER = re.compile(r'^(<[\w.+/-]+>|"[\w.+/-]+")')


def refused_directives(text: bytes) -> list[str]:
    """Lines of a source that could make the compiler read files outside the
    submission (and print them in its messages): includes by absolute or
    '..' path or by macro, and assembler .incbin."""
    source = text.decode("latin-1").replace("\\\r\n", "").replace("\\\n", "")
    refused = []
    for match in _INCLUDE.finditer(source):
        target = _SAFE_HEADER.match(match.group(1))
        name = target.group(1)[1:-1] if target else ""
        if not target or name.startswith("/") or ".." in name.split("/"):
            refused.append(match.group(0).strip())
    refused += [line.strip() for line in source.splitlines() if "incbin" in line.lower()]
    return refused


def select_source(path: Path) -> ChosenSource:
    """Find the student's EnvironmentMap.cpp in a folder, file or archive."""
    if path.is_file() and path.name.lower().endswith(ARCHIVE_SUFFIXES):
        with ExitStack() as stack:
            files = _archive_files(path, stack)
            name, notes = _choose(files, path.name)
            return ChosenSource(files[name](), name, None, notes + _header_notes(files, name))
    if path.is_dir():
        files = _folder_files(path)
        name, notes = _choose(files, f"the folder {path.name}")
        return ChosenSource(files[name](), name, path / name, notes + _header_notes(files, name))
    if path.is_file():
        text = _read_capped(path.open("rb"), path.name)
        notes = [] if path.name == SOURCE_NAME else [f"graded {path.name} as {SOURCE_NAME}."]
        return ChosenSource(text, path.name if path.suffix == ".cpp" else SOURCE_NAME, path, notes)
    raise SubmissionError(f"{path} does not exist.")


# ---- the files of ours that go into every library ----------------------------

def _template_files() -> list[Path]:
    return sorted(TEMPLATE.glob("*.h")) + [TEMPLATE / "EnvironmentMapLoader.cpp"]


def _reference_files() -> list[Path]:
    return [REFERENCE / "include" / "envmap.h"] + sorted((REFERENCE / "src").glob("*.[ch]"))


def _shim_files() -> list[Path]:
    return [SHIM / "shim.cpp", SHIM / "submission_abi.h"]


@functools.lru_cache(maxsize=None)
def compiler_versions() -> str:
    lines = []
    for compiler in (CXX, CC):
        out = subprocess.run([compiler, "--version"], capture_output=True, text=True, check=True)
        lines.append(out.stdout.splitlines()[0])
    return "\n".join(lines)


def _fingerprint(paths: list[Path], *extra: str) -> str:
    """sha256 over file names and contents (relative to the project) and extra strings."""
    h = hashlib.sha256()
    for path in paths:
        h.update(str(path.relative_to(PROJECT_ROOT)).encode() + b"\0")
        h.update(hashlib.sha256(path.read_bytes()).digest())
    for item in extra:
        h.update(item.encode() + b"\0")
    return h.hexdigest()


def _flags(sanitize: bool) -> tuple[list[str], list[str]]:
    extra = SANITIZE_FLAGS if sanitize else []
    return CXXFLAGS + extra + DIAGNOSTIC_FLAGS, CFLAGS + extra + DIAGNOSTIC_FLAGS


# ---- running the compiler under limits -----------------------------------------

@dataclass
class _Step:
    returncode: int
    output: str
    timed_out: bool = False


# The compiler sees no secrets of ours (no GRADER_SECRET in
# /proc/self/environ for a student's #include to print).
_COMPILER_ENVIRONMENT = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "LC_ALL": "C",
                         **{k: os.environ[k] for k in ("TMPDIR",) if k in os.environ}}


def _limited(cmd: list[str], cpu_seconds: int) -> list[str]:
    """cmd under an address-space and a CPU-time limit. The limits are set by
    the shell's ulimit rather than setrlimit in a preexec_fn, which is unsafe
    when threads run (the common objects are compiled in parallel)."""
    script = f'ulimit -v {MEMORY_LIMIT_BYTES >> 10} && ulimit -t {cpu_seconds} && exec "$@"'
    return ["/bin/sh", "-c", script, "sh", *cmd]


def _run(cmd: list[str], cwd: Path, deadline: float) -> _Step:
    """Run one compiler command in its own process group, killed at the deadline."""
    remaining = deadline - time.monotonic()
    if remaining <= 0:
        return _Step(-1, "", timed_out=True)
    cpu = max(1, int(remaining) + 1)
    proc = subprocess.Popen(_limited(cmd, cpu), cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, start_new_session=True,
                            env=_COMPILER_ENVIRONMENT)
    try:
        out, _ = proc.communicate(timeout=remaining)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        return _Step(-1, out.decode("utf-8", "replace"), timed_out=True)
    # cc1plus stopped by the CPU-time limit: "Killed signal terminated program cc1plus".
    text = out.decode("utf-8", "replace")
    if proc.returncode != 0 and "signal terminated program" in text:
        return _Step(proc.returncode, text, timed_out=True)
    return _Step(proc.returncode, text)


def _publish(tmp: Path, final: Path) -> None:
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


def _common_objects(cache_dir: Path, sanitize: bool) -> Path:
    """Our objects, built once per cache: loader.o and shim.o (always linked),
    libreference.a (the reference C; the linker takes what the loader needs),
    and exports.map."""
    with _common_lock:
        return _build_common_objects(cache_dir, sanitize)


def _build_common_objects(cache_dir: Path, sanitize: bool) -> Path:
    cxxflags, cflags = _flags(sanitize)
    key = _fingerprint(_template_files() + _reference_files() + _shim_files(),
                       compiler_versions(), *cxxflags, "|", *cflags)
    final = cache_dir / f"common-{key[:24]}"
    if (final / "exports.map").is_file():
        return final
    cache_dir.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=".tmp-common-", dir=cache_dir))
    deadline = time.monotonic() + 600
    includes = [f"-I{TEMPLATE}", f"-I{REFERENCE / 'include'}", f"-I{SHIM}"]
    jobs = [[CXX, *cxxflags, *includes, "-c", str(TEMPLATE / "EnvironmentMapLoader.cpp"), "-o", "loader.o"],
            [CXX, *cxxflags, *includes, "-c", str(SHIM / "shim.cpp"), "-o", "shim.o"]]
    reference_objects = []
    for src in sorted((REFERENCE / "src").glob("*.c")):
        jobs.append([CC, *cflags, f"-I{REFERENCE / 'include'}", "-c", str(src), "-o", f"ref_{src.stem}.o"])
        reference_objects.append(f"ref_{src.stem}.o")
    archive = ["ar", "rcs", "libreference.a", *reference_objects]
    with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        steps = list(pool.map(lambda cmd: _run(cmd, tmp, deadline), jobs))
    steps.append(_run(archive, tmp, deadline))
    for cmd, step in zip(jobs + [archive], steps):
        if step.returncode != 0 or step.timed_out:
            shutil.rmtree(tmp, ignore_errors=True)
            raise HarnessBuildError(f"{' '.join(cmd)}\n{step.output}")
    # Only the ABI leaves the library: the reference's em_* symbols inside it
    # can never be confused with the grader's own reference library.
    (tmp / "exports.map").write_text("{\n  global: sub_*;\n  local: *;\n};\n")
    _publish(tmp, final)
    return final


# ---- the student's part ------------------------------------------------------------

def _compile_and_link(source: bytes, common: Path, build_dir: Path, sanitize: bool,
                      deadline: float, extra_flags: tuple[str, ...] = ()) -> dict:
    """Compile the student's file alone, then link it with our objects. Returns
    the cache record: {ok, timed_out, output} with output's paths neutral."""
    cxxflags, _ = _flags(sanitize)
    (build_dir / SOURCE_NAME).write_bytes(source)
    compile_cmd = [CXX, *cxxflags, *extra_flags, f"-I{TEMPLATE}", f"-I{REFERENCE / 'include'}",
                   "-c", SOURCE_NAME, "-o", STUDENT_OBJECT]
    link_cmd = [CXX, *cxxflags, "-shared", "-o", LIBRARY_NAME, STUDENT_OBJECT,
                str(common / "shim.o"), str(common / "loader.o"), str(common / "libreference.a"),
                "-Wl,--no-undefined",
                f"-Wl,--version-script={common / 'exports.map'}", "-lm"]
    # The student's file is compiled in the sandbox where this machine has
    # one: a compiler reading hostile source sees nothing of ours but headers.
    from .worker.sandbox import compiler_command, sandbox_problem
    if sandbox_problem() is None:
        compile_cmd = compiler_command(compile_cmd, [TEMPLATE, REFERENCE / "include"], build_dir)
    outputs = []
    ok = timed_out = False
    for cmd in (compile_cmd, link_cmd):
        step = _run(cmd, build_dir, deadline)
        outputs.append(step.output)
        if step.timed_out:
            timed_out = True
            break
        if step.returncode != 0:
            break
    else:
        ok = (build_dir / LIBRARY_NAME).is_file()
    output = "".join(outputs)
    for prefix in (build_dir, common, TEMPLATE, REFERENCE / "include", REFERENCE / "src", SHIM):
        output = output.replace(f"{prefix}/", "")
    output = re.sub(r"^/usr/bin/ld: ", "ld: ", output, flags=re.M)
    return {"ok": ok, "timed_out": timed_out, "output": output}


def build_submission(path, *, cache_dir=None, sanitize=False, timeout_s=60,
                     extra_flags: tuple[str, ...] = ()) -> BuildResult:
    """Build a submission (folder, .cpp, .zip, .tar.gz) into a loadable library.

    extra_flags: appended to the student file's compile flags only (e.g. -O0,
    -ffast-math, to measure how builds differ; docs/thresholds.md).
    Never raises for a bad submission; see the module docstring."""
    path = Path(path)
    cache_dir = Path(cache_dir) if cache_dir is not None else DEFAULT_CACHE
    try:
        chosen = select_source(path)
    except SubmissionError as exc:
        return BuildResult(ok=False, library=None, source=path, log=str(exc),
                           errors=[{"file": None, "line": None, "message": str(exc)}])
    sha = hashlib.sha256(chosen.text).hexdigest()
    result = BuildResult(ok=False, library=None, source=chosen.origin or path, sha256=sha,
                         notes=list(chosen.notes), source_name=chosen.name)
    refused = refused_directives(chosen.text)
    if refused:
        message = (f"{chosen.name} may include headers by name only (e.g. <cmath>, \"EnvironmentMap.h\"); "
                   f"refused: {'; '.join(refused[:3])}")
        result.log, result.errors = message, [{"file": chosen.name, "line": None, "message": message}]
        return result

    common = _common_objects(cache_dir, sanitize)
    cxxflags, _ = _flags(sanitize)
    key = _fingerprint([Path(__file__)], sha, common.name, *cxxflags, *extra_flags)
    final = cache_dir / key[:32]
    record_path = final / "build.json"
    if record_path.is_file():
        record = json.loads(record_path.read_text())
        result.cached = True
    else:
        tmp = Path(tempfile.mkdtemp(prefix=".tmp-", dir=cache_dir))
        record = _compile_and_link(chosen.text, common, tmp, sanitize, time.monotonic() + timeout_s,
                                   tuple(extra_flags))
        if record["timed_out"]:
            # Not cached: a loaded machine may finish the same build next time.
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            (tmp / "build.json").write_text(json.dumps(record))
            _publish(tmp, final)

    if chosen.origin is None and final.is_dir():
        result.source = final / SOURCE_NAME
    result.ok = bool(record["ok"])
    result.timed_out = bool(record["timed_out"])
    result.library = final / LIBRARY_NAME if result.ok else None
    _describe(result, record["output"], timeout_s)
    return result


# ---- what the student reads -------------------------------------------------------

_DIAGNOSTIC = re.compile(r"^(?P<file>[^:\s][^:]*):(?P<line>\d+):(?:\d+:)? "
                         r"(?P<kind>fatal error|error|warning|note): (?P<message>.*)$")
_CONTEXT = re.compile(r"^(In file included from |\s+from |[^:\s][^:]*: (In |At global scope)|"
                      r"ld: [^:]+: in function )")
_LINK_ERROR = re.compile(r"multiple definition of|undefined reference to|^collect2: error")
_LINK_DEFINITION = re.compile(r"multiple definition of `(?:[\w:<>]+::)?EnvironmentMap::(\w+)")
_LINK_UNDEFINED = re.compile(r"undefined reference to `([^']+)'")
_COMPILE_REDEFINITION = re.compile(r"redefinition of '[^']*EnvironmentMap::(\w+)\(")
_TYPE_REDEFINITION = re.compile(r"redefinition of '(?:class|struct) (EnvironmentMap|Vector3|Color)'")
_NO_DECLARATION = re.compile(r"no declaration matches '[^']*EnvironmentMap::(\w+)\(")
_MISSING_HEADER = re.compile(r"fatal error: ([^:]+): No such file or directory")


def _friendly(output: str) -> list[str]:
    """Sentences for the mistakes a student is likely to make, one each."""
    found: list[str] = []

    def say(sentence: str) -> None:
        if sentence not in found:
            found.append(sentence)

    for name in _LINK_DEFINITION.findall(output) + _COMPILE_REDEFINITION.findall(output):
        if name not in STUDENT_MEMBERS:
            say(f"{SOURCE_NAME} must not define {name}: it is provided "
                f"({'inline in EnvironmentMap.h' if name == 'faceAddress' else 'EnvironmentMapLoader.cpp'}). "
                "Delete your definition.")
    for name in _TYPE_REDEFINITION.findall(output):
        say(f"{SOURCE_NAME} must not define {name} again: include \"{name}.h\" instead.")
    for name in _NO_DECLARATION.findall(output):
        if name in STUDENT_MEMBERS:
            say(f"{name} must keep the signature EnvironmentMap.h declares; the header cannot change.")
        else:
            say(f"EnvironmentMap::{name} is not declared in EnvironmentMap.h, which you cannot change: "
                "write helpers as free functions in your file (e.g. in an anonymous namespace).")
    if "virtual memory exhausted" in output or "out of memory allocating" in output:
        say(f"The compiler ran out of memory (the limit is {MEMORY_LIMIT_BYTES >> 30} GiB).")
    for header in _MISSING_HEADER.findall(output):
        say(f"{SOURCE_NAME} includes \"{header}\", which the grader does not have: a submission is "
            f"{SOURCE_NAME} alone, built with the template's headers (EnvironmentMap.h, Vector3.h, "
            "Color.h) and the C++ standard library.")
    for symbol in dict.fromkeys(_LINK_UNDEFINED.findall(output)):
        member = re.match(r"EnvironmentMap::(\w+)\(", symbol)
        if member and member.group(1) in STUDENT_MEMBERS:
            say(f"{SOURCE_NAME} must define {member.group(1)} "
                f"(the function {symbol}); it is missing.")
        else:
            say(f"{symbol} is declared but never defined: define it in {SOURCE_NAME}.")
    return found


def _blocks(output: str) -> list[tuple[str, list[str]]]:
    """Group compiler output into (kind, lines): each error or warning with
    its context lines before it and its source excerpt and notes after it."""
    blocks: list[tuple[str, list[str]]] = []
    pending: list[str] = []
    for line in output.splitlines():
        match = _DIAGNOSTIC.match(line)
        if match and match.group("kind") != "note":
            blocks.append(("warning" if match.group("kind") == "warning" else "error", pending + [line]))
            pending = []
        elif _LINK_ERROR.search(line):
            blocks.append(("error", pending + [line]))
            pending = []
        elif _CONTEXT.match(line) or not blocks:
            pending.append(line)
        else:
            # A note or source excerpt: it belongs, with any context before
            # it, to the diagnostic it explains.
            blocks[-1][1].extend(pending + [line])
            pending = []
    if pending:
        blocks.append(("error", pending))
    return blocks


def _trim(lines: list[str]) -> str:
    if len(lines) > MAX_LOG_LINES:
        lines = lines[:MAX_LOG_LINES] + [f"... ({len(lines) - MAX_LOG_LINES} more lines)"]
    text = "\n".join(lines)
    if len(text) > MAX_LOG_CHARS:
        text = text[:MAX_LOG_CHARS] + "\n... (trimmed)"
    return text


def _describe(result: BuildResult, output: str, timeout_s: float) -> None:
    """Fill log, errors and warnings from the cached compiler output. The
    log's first line is the headline: a friendly sentence when one applies,
    else the first error with its file and line."""
    name = result.source_name
    # The student's file, wherever it was in the submission, was compiled as SOURCE_NAME.
    output = re.sub(rf"(?<![\w/.]){re.escape(SOURCE_NAME)}(?=:)", name, output)
    for line in output.splitlines():
        match = _DIAGNOSTIC.match(line)
        if match and match.group("kind") in ("error", "fatal error", "warning"):
            entry = {"file": match.group("file"), "line": int(match.group("line")),
                     "message": match.group("message")}
            (result.warnings if match.group("kind") == "warning" else result.errors).append(entry)
    sentences = [s.replace(SOURCE_NAME, name, 1) for s in _friendly(output)]
    if result.timed_out:
        sentences.insert(0, f"The build took longer than {timeout_s:g} s and was stopped.")
    if not result.ok:
        if not sentences and not result.errors:
            sentences = ["The build failed; the compiler's messages follow."]
        result.errors[:0] = [{"file": name, "line": None, "message": s} for s in sentences]
        if not sentences:
            first = result.errors[0]
            sentences = [f"{first['file']}:{first['line']}: error: {first['message']}"]
    blocks = _blocks(output)
    ordered = [l for kind, lines in blocks if kind == "error" for l in lines] + \
              [l for kind, lines in blocks if kind == "warning" for l in lines]
    result.log = _trim(sentences + ([""] if sentences and ordered else []) + ordered)
