"""A submission -> a shared library the worker can load (grader/build/shim/submission_abi.h).

build_submission() accepts a folder, a single .cpp file, or an archive of
either (grader/intake.py finds the student's EnvironmentMap.cpp
without trusting the upload), then builds it in steps, each of which can
refuse the submission with its own diagnosis id:

1. include policy, read from the text (refused-include): a submission may
   include the three API headers and the standard library, by name only;
   and the text half of the source policy (refused-source): directives on
   an allow-list (no #line, no line markers, no #ident), pragmas on an
   allow-list, no _Pragma;
2. the student's file is preprocessed (g++ -E) with ONLY the template's
   three API headers visible (a private copy in the build folder; never
   the reference's headers): the files it read (-MD) must be our API
   headers or under the compiler's own system include folders
   (refused-include), and the source policy judges GCC's own tokens
   (grader/build/source_policy.py: no asm, no #line, no pragma or assembly
   attribute off the list: refused-source);
3. it is compiled ALONE to assembly, no LTO; the assembly, read as raw
   text, may not read files or build directives (.incbin, .include,
   .macro, ...);
4. the object is inspected (our own ELF reader, no tool parses it): only
   ordinary sections (no .gnu.lto_*), and undefined symbols only from
   libc/libm/libstdc++/libgcc and the template's EnvironmentMap members
   (em_* -> calls-reference, anything else -> forbidden-object);
5. it is linked with shim.o, loader.o and the reference objects the
   loader needs (rgbe, cross, error: never the lookup), exporting only the
   sub_* entry points.

Steps 2-5 run in a scratch folder outside the project holding copies of
everything they read, under bubblewrap where it works; where it does not
but we are root, as the unprivileged uid/gid BUILD_UID ("privilege-drop"),
once grader/build/compiler.py has made sure that uid can read none of
the grader's, the course's or the uploads' files; otherwise as ourselves
("none"). Always with stdin /dev/null, a scrubbed environment, CPU/memory
limits and a wall-clock deadline.

Builds are cached by content hash under build/submissions/<key>/: the key
covers the student's source, every file of ours that goes into the library,
the flags, the compiler versions and the language (a refusal's message is
stored in it). The cache stores the compiler's own
output with paths made neutral; what the student reads (which file, in
which order, friendly sentences) is worked out on every call
(grader/build/messages.py), so the same source in a .zip and as a loose
file shares one library.

A bad submission never raises: it gives BuildResult(ok=False) with the
reason and a diagnosis_id. Our own sources failing to compile raises
HarnessBuildError.
"""
from __future__ import annotations

import atexit
import functools
import hashlib
import json
import os
import re
import select
import shutil
import signal
import stat
import struct
import subprocess
import tempfile
import threading
import time
from bisect import bisect_right
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from .. import PROJECT_ROOT
from . import source_policy
from ..i18n import _, language, ngettext
from .messages import MAX_COMPILER_OUTPUT_BYTES, MEMORY_LIMIT_BYTES, OUTPUT_STOPPED, describe
from ..intake import MAX_SOURCE_BYTES, SOURCE_NAME, ChosenSource, SubmissionError, select_source as _select_source  # noqa: F401 (re-exported)

TEMPLATE = PROJECT_ROOT / "student_template"
REFERENCE = PROJECT_ROOT / "reference"
SHIM = PROJECT_ROOT / "grader" / "build" / "shim"
DEFAULT_CACHE = PROJECT_ROOT / "build" / "submissions"

CXX, CC = "g++", "gcc"
# No LTO anywhere: an object carrying LTO bytecode would have code the
# student never showed us compiled at link time, outside any check.
CXXFLAGS = ["-std=c++17", "-O2", "-Wall", "-Wextra", "-fPIC", "-fno-lto"]
CFLAGS = ["-std=c11", "-O2", "-Wall", "-Wextra", "-fPIC", "-fno-lto", "-D_POSIX_C_SOURCE=200809L"]
SANITIZE_FLAGS = ["-fsanitize=address,undefined", "-fno-omit-frame-pointer", "-g"]
# Plain messages: no colour, no line wrapping, a bounded number of errors.
DIAGNOSTIC_FLAGS = ["-fdiagnostics-color=never", "-fmessage-length=0", "-fmax-errors=10"]
LINK_FLAGS = ["-fno-lto", "-fno-use-linker-plugin", "-Wl,--no-undefined", "-Wl,-z,noexecstack",
              "-Wl,-z,relro", "-Wl,-z,now"]
LIBRARY_NAME = "submission.so"
STUDENT_OBJECT = "EnvironmentMap.o"
STUDENT_ASSEMBLY = "EnvironmentMap.s"
STUDENT_PREPROCESSED = "EnvironmentMap.ii"
# The only headers a submission sees (copies in the scratch folder's include/).
API_HEADERS = ("EnvironmentMap.h", "Vector3.h", "Color.h")
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
# The uid/gid compilers run as without bubblewrap (root only). Not nobody
# (65534): a privilege-dropped worker runs student code as nobody, and must
# not reach another student's build folder. 65533 is reserved and unused on
# Debian and Ubuntu (policy: 65000-65533 reserved).
BUILD_UID = BUILD_GID = 65533
MAX_ASSEMBLY_BYTES = 64 << 20
# The linked library: copied into every worker's folder and kept in the build
# cache (240 MiB of zeros in .data compiled from a 4 KiB source scored 100).
MAX_LIBRARY_BYTES = 64 << 20
MAX_OUTPUT_FILE_BYTES = 256 << 20   # any file a compiler step writes (ulimit -f)
# Every BuildResult.diagnosis_id a build can give (grader/grading/catalogue.py has each).
DIAGNOSIS_IDS = ("build-error", "no-source", "empty-submission", "unknown-format", "unreadable-archive",
                 "refused-include", "refused-source", "calls-reference", "forbidden-object")

# Re-exported for older callers.
select_source = functools.partial(_select_source, template=TEMPLATE)


class HarnessBuildError(RuntimeError):
    """Our own sources (template, shim, reference) did not compile, or (BuildConfinementError) the
    compiler could not be confined: not the student's fault."""


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
    # Why the build failed, an id of grader/grading/catalogue.py: "build-error" (the
    # compiler's), or a refusal: no-source, empty-submission, unknown-format,
    # unreadable-archive, refused-include, calls-reference, forbidden-object.
    diagnosis_id: str = "build-error"
    isolation: str = ""           # how the compiler ran: bubblewrap, privilege-drop or none ("" when cached)


# ---- include policy, from the text ------------------------------------------------------

# One C++ token or piece of text at a time, so that comments, string and
# character literals, raw strings and numbers (1'000, digit separators) are
# told apart as the compiler does; the order of the alternatives matters.
_TOKEN = re.compile(r"""
    (?P<raw>(?:u8|u|U|L)?R"(?P<delim>[^()\\\s"]{0,16})\((?:.|\n)*?(?:\)(?P=delim)"|\Z))
  | (?P<ident>[A-Za-z_]\w*)
  | (?P<number>\.?[0-9](?:[eEpP][+-]|'[0-9A-Za-z_]|[0-9A-Za-z_.])*)
  | (?P<string>"(?:\\.|[^"\\\n])*"?)
  | (?P<char>'(?:\\.|[^'\\\n])*'?)
  | (?P<block>/\*(?:.|\n)*?(?:\*/|\Z))
  | (?P<line>//[^\n]*)
  | (?P<other>.|\n)
""", re.X)
_SPLICE = re.compile(r"\\[ \t\f\v]*\r?\n")
_DIRECTIVE = re.compile(r"^[ \t\f\v]*(?:#|%:)[ \t\f\v]*(\w*)(.*)$", re.M)
# A header named plainly: letters, digits, _ . + - and / between them.
# (What follows the name is ignored by GCC, with a warning: "#include <cmath>;" is harmless.)
_PLAIN_HEADER = re.compile(r'^(<[\w.+-]+(?:/[\w.+-]+)*>|"[\w.+-]+(?:/[\w.+-]+)*")')
# The argument is looked at up to 300 characters: a longer one is refused.
_HAS_INCLUDE = re.compile(r"\b(__has_(?:include|embed)\w*)[ \t]*(\(([^)\n]{0,300})\))?")
_PRAGMA_FILES = re.compile(r"\b(dependency|pch_preprocess)\b")
_TRIGRAPHS = {"??=": "#", "??/": "\\", "??'": "^", "??(": "[", "??)": "]", "??!": "|", "??<": "{",
              "??>": "}", "??-": "~"}


def _plain_header(argument: str) -> bool:
    match = _PLAIN_HEADER.match(argument)
    if not match:
        return False
    name = match.group(1)[1:-1]
    return ".." not in name.split("/")


def _logical(text: str) -> tuple[str, list[int], list[int]]:
    """The text with line splices removed, and what maps its offsets back to
    physical lines: (text, offsets where a splice was removed, cumulative
    newlines removed there)."""
    out, cuts, removed = [], [], []
    last = total = length = 0
    for match in _SPLICE.finditer(text):
        out.append(text[last:match.start()])
        length += match.start() - last
        total += 1
        cuts.append(length)
        removed.append(total)
        last = match.end()
    out.append(text[last:])
    return "".join(out), cuts, removed


def _blank(text: str) -> str:
    """Comments and raw-string bodies become spaces (newlines kept), so
    neither hides a directive nor fakes one."""
    pieces = []
    for match in _TOKEN.finditer(text):
        kind = match.lastgroup
        piece = match.group(0)
        if kind in ("block", "line"):
            pieces.append(re.sub(r"[^\n]", " ", piece) or " ")
        elif kind == "raw":
            pieces.append(re.sub(r"[^\n]", " ", piece))
        else:
            pieces.append(piece)
    return "".join(pieces)


def _refusals_in(text: str) -> list[tuple[int, str]]:
    # GCC ends a line at \n, \r\n and a lone \r alike, and reads a NUL as
    # a space ("\0#include" and "#\0line" are directives to it).
    logical, cuts, removed = _logical(text.replace("\0", " ").replace("\r\n", "\n").replace("\r", "\n"))
    cleaned = _blank(logical)

    newlines = [m.start() for m in re.finditer("\n", cleaned)]

    def line_of(offset: int) -> int:
        at = bisect_right(cuts, offset)
        return bisect_right(newlines, offset - 1) + (removed[at - 1] if at else 0) + 1

    found: list[tuple[int, str]] = []
    for match in _DIRECTIVE.finditer(cleaned):
        name, rest = match.group(1), match.group(2).strip()
        line = line_of(match.start())
        shown = f"#{name} {rest}".strip()[:120]
        if name in ("include", "include_next", "import"):
            if not _plain_header(rest):
                found.append((line, _("%(shown)s (a header must be named plainly, as in #include <cmath> "
                                      "or #include \"EnvironmentMap.h\": no path from /, no '..', no macro)") % {"shown": shown}))
        elif name == "embed":
            found.append((line, _("%(shown)s (#embed reads a file: not allowed)") % {"shown": shown}))
        elif name == "pragma" and _PRAGMA_FILES.search(rest):
            found.append((line, _("%(shown)s (this pragma reads a file: not allowed)") % {"shown": shown}))
        elif name == "" and rest and not rest.startswith("!"):
            pass  # a null directive or a stray '#': the compiler says what is wrong
    for match in _HAS_INCLUDE.finditer(cleaned):
        if match.group(2) is None or not _plain_header(match.group(3).strip()):
            found.append((line_of(match.start()), _("%(shown)s (only a plain header name "
                                                    "may be tested)") % {"shown": match.group(0)[:80]}))
    for match in re.finditer(r"_Pragma\b[^\n]*", cleaned):
        if _PRAGMA_FILES.search(match.group(0)):
            found.append((line_of(match.start()), _("%(shown)s (this pragma reads a file: "
                                                    "not allowed)") % {"shown": match.group(0)[:80]}))
    for match in re.finditer(r"incbin", cleaned, re.I):  # in strings too: asm(".incbin ...")
        found.append((line_of(match.start()), _("assembler .incbin (it reads a file into the program: "
                                                "not allowed)")))
    return found


# The directives a submission may use (an allow-list; the source policy's
# text half, grader/build/source_policy.py): no #line or GNU linemarker ("# 12
# "file" 1 3"), which would make the compiler quote or attribute lines to
# another file, no #ident, #assert, #include_next, #import, #embed.
_DIRECTIVES = frozenset({"", "include", "define", "undef", "if", "ifdef", "ifndef", "elif", "elifdef",
                         "elifndef", "else", "endif", "error", "warning", "pragma"})


def _constructs_in(text: str) -> list[tuple[int, str]]:
    logical, cuts, removed = _logical(text.replace("\0", " ").replace("\r\n", "\n").replace("\r", "\n"))
    cleaned = _blank(_blank_strings(logical))
    newlines = [m.start() for m in re.finditer("\n", cleaned)]

    def line_of(offset: int) -> int:
        at = bisect_right(cuts, offset)
        return bisect_right(newlines, offset - 1) + (removed[at - 1] if at else 0) + 1

    found = []
    for match in _DIRECTIVE.finditer(cleaned):
        name, rest = match.group(1), match.group(2).strip()
        shown = f"#{name} {rest}".strip()[:120]
        if name not in _DIRECTIVES:
            found.append((line_of(match.start()), _("%(shown)s (the directive #%(name)s is not "
                                                    "allowed in a submission)") % {"shown": shown, "name": name or rest.split()[0]}))
        elif name == "pragma" and not source_policy.pragma_allowed(rest):
            found.append((line_of(match.start()), _("%(shown)s (this pragma is not allowed in a submission)") % {"shown": shown}))
    for match in re.finditer(r"\b_Pragma\b", cleaned):
        found.append((line_of(match.start()), _("_Pragma (not allowed in a submission)")))
    return found


def _blank_strings(text: str) -> str:
    """String and character literals become spaces, so that "_Pragma" in a
    string is not taken for the operator (comments: _blank)."""
    pieces = []
    for match in _TOKEN.finditer(text):
        piece = match.group(0)
        pieces.append(re.sub(r"[^\n]", " ", piece) if match.lastgroup in ("string", "char") else piece)
    return "".join(pieces)


def refused_constructs(text: bytes) -> list[tuple[int, str]]:
    """(line, what) for each directive outside the allow-list (#line, GNU
    linemarkers, #ident, ...), pragma outside source_policy.PRAGMAS and
    _Pragma in a source, read as the compiler reads it (with trigraphs
    replaced too). The compiler's tokens are judged as well, after -E
    (source_policy.refusals): this half sees what -E does not show."""
    source = text.decode("latin-1")
    found = dict.fromkeys(_constructs_in(source))
    if "??" in source:
        for trigraph, replacement in _TRIGRAPHS.items():
            source = source.replace(trigraph, replacement)
        found.update(dict.fromkeys(_constructs_in(source)))
    return sorted(found)


def refused_directives(text: bytes) -> list[tuple[int, str]]:
    """(line, what) for each line of a source that could make the compiler
    read a file other than a standard or API header: includes by path or by
    macro, #embed, __has_include of a path, file-reading pragmas, .incbin.
    The text is read as the compiler reads it (comments, splices, digraphs)
    and, in case trigraphs are on, once more with them replaced."""
    source = text.decode("latin-1")
    found = dict.fromkeys(_refusals_in(source))
    if "??" in source:
        for trigraph, replacement in _TRIGRAPHS.items():
            source = source.replace(trigraph, replacement)
        found.update(dict.fromkeys(_refusals_in(source)))
    return sorted(found)


# ---- the files of ours that go into every library ----------------------------

def _template_files() -> list[Path]:
    return [TEMPLATE / name for name in API_HEADERS] + [TEMPLATE / "EnvironmentMapLoader.cpp"]


def _reference_files() -> list[Path]:
    return ([REFERENCE / "include" / "envmap.h"] + sorted((REFERENCE / "src").glob("*.h"))
            + [REFERENCE / "src" / name for name in LOADER_REFERENCE_SOURCES])


def _shim_files() -> list[Path]:
    return [SHIM / "shim.cpp", SHIM / "submission_abi.h"]


@functools.lru_cache(maxsize=None)
def compiler_versions() -> str:
    lines = []
    for compiler in (CXX, CC):
        out = subprocess.run([compiler, "--version"], capture_output=True, text=True, check=True,
                             stdin=subprocess.DEVNULL)
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


# ---- the libraries a submission may call -----------------------------------------

_RUNTIME_LIBRARIES = ("libc.so.6", "libm.so.6", "libmvec.so.1", "libstdc++.so.6", "libgcc_s.so.1",
                      "ld-linux-x86-64.so.2", "ld-linux-aarch64.so.1")
_SANITIZER_LIBRARIES = ("libasan.so", "libubsan.so")
# Defined by the linker or the C runtime start files rather than a library.
_LINKER_SYMBOLS = {"_GLOBAL_OFFSET_TABLE_", "__dso_handle", "_DYNAMIC", "__tls_get_addr",
                   "_ITM_registerTMCloneTable", "_ITM_deregisterTMCloneTable", "__gmon_start__"}


@functools.lru_cache(maxsize=None)
def _library_paths(sanitize: bool) -> tuple[Path, ...]:
    paths = []
    for name in _RUNTIME_LIBRARIES + (_SANITIZER_LIBRARIES if sanitize else ()):
        out = subprocess.run([CXX, f"-print-file-name={name}"], capture_output=True, text=True,
                             stdin=subprocess.DEVNULL).stdout.strip()
        if out and os.path.isabs(out) and os.path.isfile(out):
            paths.append(Path(os.path.realpath(out)))
    libgcc = subprocess.run([CXX, "-print-libgcc-file-name"], capture_output=True, text=True,
                            stdin=subprocess.DEVNULL).stdout.strip()
    if libgcc and os.path.isfile(libgcc):
        paths.append(Path(os.path.realpath(libgcc)))
    return tuple(paths)


def _defined_symbols(paths: tuple[Path, ...]) -> set[str]:
    """Global symbols defined by our trusted runtime libraries (nm)."""
    names: set[str] = set()
    for path in paths:
        dynamic = ["-D"] if ".so" in path.name else []
        out = subprocess.run(["nm", *dynamic, "-g", "--defined-only", str(path)], capture_output=True,
                             text=True, stdin=subprocess.DEVNULL).stdout
        for line in out.splitlines():
            parts = line.split()
            if len(parts) >= 3:
                names.add(parts[-1].split("@")[0])
    return names


# ---- running the compiler: sandboxed, limited, stdin /dev/null ------------------

@dataclass
class _Step:
    returncode: int
    output: str
    timed_out: bool = False


# The compiler sees no secrets of ours (no GRADER_SECRET in
# /proc/self/environ for a student's #include to print).
_COMPILER_ENVIRONMENT = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "LC_ALL": "C",
                         **{k: os.environ[k] for k in ("TMPDIR",) if k in os.environ}}


def build_isolation() -> str:
    """How the student's compile and link run here: "bubblewrap",
    "privilege-drop" (no bubblewrap, but we are root: uid/gid BUILD_UID) or
    "none" (no bubblewrap, not root: as ourselves, limits only)."""
    from ..worker.sandbox import sandbox_problem
    if sandbox_problem() is None:
        return "bubblewrap"
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        return "privilege-drop"
    return "none"


def _limited(cmd: list[str], cpu_seconds: int) -> list[str]:
    """cmd under an address-space and a CPU-time limit. The limits are set by
    the shell's ulimit rather than setrlimit in a preexec_fn, which is unsafe
    when threads run (the common objects are compiled in parallel)."""
    # ulimit -f counts 512-byte blocks in dash (Debian's sh), 1 KiB in bash: at most 2x the cap.
    script = (f'ulimit -v {MEMORY_LIMIT_BYTES >> 10} && ulimit -t {cpu_seconds} && '
              f'ulimit -f {MAX_OUTPUT_FILE_BYTES >> 9} && exec "$@"')
    return ["/bin/sh", "-c", script, "sh", *cmd]


def _run(cmd: list[str], cwd: Path, deadline: float, isolation: str = "trusted") -> _Step:
    """Run one compiler command in its own process group, killed at the
    deadline. isolation: "trusted" (our own sources), or how a student's
    file is built (build_isolation(); the scratch folder `cwd` is all of
    ours it may see)."""
    remaining = deadline - time.monotonic()
    if remaining <= 0:
        return _Step(-1, "", timed_out=True)
    cpu = max(1, int(remaining) + 1)
    env = dict(_COMPILER_ENVIRONMENT)
    drop: dict = {}
    if isolation == "bubblewrap":
        from ..worker.sandbox import compiler_command
        cmd = compiler_command(cmd, [], cwd)
    elif isolation == "privilege-drop":
        # No bubblewrap, but root: the compiler runs as BUILD_UID, in a scratch
        # folder only it (and root) can enter; its temporary files go there too.
        drop = {"user": BUILD_UID, "group": BUILD_GID, "extra_groups": []}
        env = {"PATH": "/usr/bin:/bin", "LC_ALL": "C", "TMPDIR": str(cwd / "tmp"), "HOME": str(cwd)}
    elif isolation == "none":
        env["TMPDIR"] = str(cwd / "tmp")
    proc = subprocess.Popen(_limited(cmd, cpu), cwd=cwd, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            start_new_session=True, env=env, **drop)
    out, ended = _read_capped(proc, remaining)
    if ended != "exited":
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        proc.stdout.close()
        text = out.decode("utf-8", "replace")
        if ended == "timeout":
            return _Step(-1, text, timed_out=True)
        return _Step(-1, f"{text}\n{OUTPUT_STOPPED}\n")
    # cc1plus stopped by the CPU-time limit: "Killed signal terminated program cc1plus".
    text = out.decode("utf-8", "replace")
    if proc.returncode != 0 and "signal terminated program" in text:
        return _Step(proc.returncode, text, timed_out=True)
    return _Step(proc.returncode, text)


def _read_capped(proc: subprocess.Popen, timeout: float) -> tuple[bytes, str]:
    """proc's output (at most MAX_COMPILER_OUTPUT_BYTES) and how reading
    ended: "exited", "timeout" or "overflow" (it printed more; the caller
    kills it). communicate() would hold all of it in our memory."""
    end = time.monotonic() + timeout
    fd = proc.stdout.fileno()
    chunks, size = [], 0
    while True:
        left = end - time.monotonic()
        if left <= 0:
            return b"".join(chunks), "timeout"
        ready, _, _ = select.select([fd], [], [], left)
        if not ready:
            continue
        chunk = os.read(fd, 1 << 16)
        if not chunk:
            break
        chunks.append(chunk)
        size += len(chunk)
        if size > MAX_COMPILER_OUTPUT_BYTES:
            return b"".join(chunks)[:MAX_COMPILER_OUTPUT_BYTES], "overflow"
    proc.stdout.close()
    try:
        proc.wait(timeout=max(0.0, end - time.monotonic()))
    except subprocess.TimeoutExpired:
        return b"".join(chunks), "timeout"
    return b"".join(chunks), "exited"


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
# Changes whenever what a common folder holds changes (an older one is not reused).
COMMON_LAYOUT = "common-3: scratch copies, allowed and reference symbols, precompiled API header"
COMMON_FILES = ("loader.o", "shim.o", "libreference.a", "exports.map", "allowed-symbols.txt",
                "reference-symbols.txt")


def _common_objects(cache_dir: Path, sanitize: bool) -> Path:
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
    cxxflags, cflags = _flags(sanitize)
    libraries = _library_paths(sanitize)
    key = _fingerprint(_template_files() + _reference_files() + _shim_files(),
                       COMMON_LAYOUT, compiler_versions(), *cxxflags, "|", *cflags, "|",
                       *(f"{p}:{p.stat().st_size}:{p.stat().st_mtime_ns}" for p in libraries))
    final = cache_dir / f"common-{key[:24]}"
    if (final / "reference-symbols.txt").is_file():
        return final
    cache_dir.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=".tmp-common-", dir=cache_dir))
    built = seed / final.name if seed is not None else None
    if built is not None and (built / "reference-symbols.txt").is_file():
        # Published folders are complete (_publish renames a finished one in).
        try:
            shutil.copytree(built, tmp, dirs_exist_ok=True)
            _publish(tmp, final)
        except BaseException:
            shutil.rmtree(tmp, ignore_errors=True)
            raise
        return final
    deadline = time.monotonic() + 600
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
        steps = list(pool.map(lambda cmd: _run(cmd, tmp, deadline), jobs))
    steps.append(_run(archive, tmp, deadline))
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
        step = _run(pch, tmp, deadline)
        if step.returncode != 0 or step.timed_out:
            shutil.rmtree(tmp, ignore_errors=True)
            raise HarnessBuildError(f"{' '.join(pch)}\n{step.output}")
    # What a student's object may leave undefined: the runtime libraries,
    # the linker's own symbols and the template's EnvironmentMap members
    # (loader.o). Never the reference's em_*.
    allowed = _defined_symbols(libraries) | _LINKER_SYMBOLS
    allowed |= {name for name, bind, defined in _object_symbols((tmp / "loader.o").read_bytes())[1]
                if defined and bind != 0 and not name.startswith("em_")}
    (tmp / "allowed-symbols.txt").write_text("\n".join(sorted(allowed)) + "\n")
    # The reference code's own global names: a submission defining one would
    # silently replace it inside the loader.
    ours = {name for obj in reference_objects for name, bind, defined
            in _object_symbols((tmp / obj).read_bytes())[1] if defined and bind == 1}
    (tmp / "reference-symbols.txt").write_text("\n".join(sorted(ours)) + "\n")
    _publish(tmp, final)
    return final


# ---- reading the student's object (hostile bytes: bounds-checked, no tool) --------

class _BadObject(Exception):
    pass


def _object_symbols(data: bytes) -> tuple[list[str], list[tuple[str, int, bool]], list[int]]:
    """(section names, [(symbol name, binding, defined)], section flags) of
    an ELF64 little-endian relocatable object."""
    sections, symbols, flags, _ = _parse_elf(data, 1)
    return sections, [(name, bind, defined) for name, bind, defined, _ in symbols], flags


def _library_imports(data: bytes) -> tuple[list[str], list[str]]:
    """(DT_NEEDED libraries, undefined dynamic symbols) of an ELF64 shared object."""
    _, symbols, _, needed = _parse_elf(data, 3)
    return needed, sorted({name for name, _, defined, table in symbols if table == 11 and not defined})


def _parse_elf(data: bytes, e_type_wanted: int) -> tuple[list[str], list[tuple[str, int, bool, int]],
                                                         list[int], list[str]]:
    """Sections, symbols (name, binding, defined, table type), section flags
    and DT_NEEDED names of an ELF64 little-endian file, every offset checked."""
    try:
        if data[:4] != b"\x7fELF" or data[4] != 2 or data[5] != 1:
            raise _BadObject("not a 64-bit little-endian ELF object")
        e_type, = struct.unpack_from("<H", data, 16)
        if e_type != e_type_wanted:
            raise _BadObject("not a relocatable object" if e_type_wanted == 1 else "not a shared object")
        shoff, = struct.unpack_from("<Q", data, 0x28)
        shentsize, shnum, shstrndx = struct.unpack_from("<HHH", data, 0x3A)
        if shentsize != 64:
            raise _BadObject("unexpected section header size")

        def header(i: int) -> tuple:
            if not 0 <= i or shoff + 64 * (i + 1) > len(data):
                raise _BadObject("section header out of bounds")
            return struct.unpack_from("<IIQQQQIIQQ", data, shoff + 64 * i)
        if shoff and shnum == 0:
            shnum = header(0)[5]
        if shstrndx == 0xFFFF:
            shstrndx = header(0)[6]
        if shnum > 1 << 20:
            raise _BadObject("too many sections")
        headers = [header(i) for i in range(shnum)]

        def body(h: tuple) -> bytes:
            offset, size = h[4], h[5]
            if h[1] == 8:  # SHT_NOBITS
                return b""
            if offset + size > len(data):
                raise _BadObject("section out of bounds")
            return data[offset:offset + size]

        def string(table: bytes, at: int) -> str:
            if at >= len(table):
                raise _BadObject("name out of bounds")
            end = table.find(b"\0", at)
            return table[at:end if end >= 0 else len(table)].decode("utf-8", "surrogateescape")

        def linked(h: tuple) -> bytes:
            return body(headers[h[6]]) if h[6] < shnum else b""

        names_table = body(headers[shstrndx]) if shnum else b""
        sections = [string(names_table, h[0]) for h in headers]
        symbols, needed = [], []
        for h in headers:
            if h[1] in (2, 11):  # SHT_SYMTAB, SHT_DYNSYM
                table, strings = body(h), linked(h)
                for at in range(24, len(table) - 23, 24):  # entry 0 is the null symbol
                    st_name, st_info, _, st_shndx, _, _ = struct.unpack_from("<IBBHQQ", table, at)
                    kind = st_info & 0xF
                    if st_name == 0 or kind in (3, 4):  # STT_SECTION, STT_FILE
                        continue
                    symbols.append((string(strings, st_name), st_info >> 4, st_shndx != 0, h[1]))
            elif h[1] == 6:  # SHT_DYNAMIC: (d_tag, d_val) pairs, DT_NEEDED = 1
                table, strings = body(h), linked(h)
                for at in range(0, len(table) - 15, 16):
                    tag, value = struct.unpack_from("<qQ", table, at)
                    if tag == 0:
                        break
                    if tag == 1:
                        needed.append(string(strings, value))
        return sections, symbols, [h[2] for h in headers], needed
    except (struct.error, IndexError, ValueError) as exc:
        raise _BadObject(f"malformed object ({exc})") from None


# What a built library may need at run time (sanitized builds: also these prefixes).
RUNTIME_NEEDED = ("libstdc++.so.6", "libm.so.6", "libmvec.so.1", "libgcc_s.so.1", "libc.so.6",
                  "ld-linux-x86-64.so.2", "ld-linux-aarch64.so.1")
SANITIZER_NEEDED = ("libasan.so", "libubsan.so")


def inspect_library(data: bytes, allowed: set[str], sanitize: bool) -> tuple[str, str] | None:
    """The linked library, checked as the worker will load it: it needs only
    the runtime libraries and imports only what they (and the linker) define."""
    try:
        needed, undefined = _library_imports(data)
    except _BadObject as exc:
        return "forbidden-object", _("The library built from %(source)s could not be checked: %(why)s.") % {"source": SOURCE_NAME, "why": exc}
    odd = [n for n in needed if n not in RUNTIME_NEEDED and not (sanitize and n.startswith(SANITIZER_NEEDED))]
    unknown = [n for n in undefined if n not in allowed]
    if odd or unknown:
        return "forbidden-object", (_("The library built from %(source)s needs %(names)s, "
                                      "which is neither the C/C++ runtime nor the grader's own code.") % {"source": SOURCE_NAME, "names": _listed(odd + unknown)})
    return None


# Sections g++ writes for ordinary C++ (with -g and sanitizers too).
_ORDINARY_SECTION = re.compile(r"""^(
    | \.(text|data|bss|rodata|tdata|tbss|ldata|lbss|lrodata)(\..+)?
    | \.data\.rel\.ro(\..+)? | \.data\.rel(\..+)?
    | \.(init_array|fini_array|preinit_array|ctors|dtors)(\.\d+)?
    | \.eh_frame | \.gcc_except_table(\..+)?
    | \.comment | \.note\.GNU-stack | \.note\.gnu\.property
    | \.group | \.symtab | \.strtab | \.shstrtab | \.symtab_shndx
    | \.debug_\w+ | \.zdebug_\w+
    | \.rela?\.(text|data|bss|rodata|tdata|ldata|lrodata|init_array|fini_array|preinit_array|ctors|dtors
               |eh_frame|gcc_except_table|debug_\w+|data\.rel\.ro|data\.rel)(\..+)?
)$""", re.X)
# Assembler directives that read files or build other directives out of
# text (which would get past any check of the source).
_ASSEMBLER_FORBIDDEN = re.compile(r"\.(incbin|include|macro|irpc?|rept|altmacro|purgem|exitm)\b", re.I)


def _listed(names, limit: int = 5) -> str:
    """Names from the object (the student's: any length, any characters),
    shortened for a message."""
    names = list(names)
    shown = [repr(n[:80] + "...") if len(n) > 80 else (n if n.isprintable() else repr(n)) for n in names[:limit]]
    return ", ".join(shown) + (_(" and %(count)d more") % {"count": len(names) - limit} if len(names) > limit else "")


def _demangle(names: list[str]) -> list[str]:
    """C++ names as the source spells them; only short printable ones are
    given to c++filt (a hostile mangled name could make a demangler recurse
    for long), in a limited process."""
    if not all(len(n) <= 200 and n.isprintable() for n in names):
        return names
    try:
        done = subprocess.run(_limited(["c++filt"], 5), input="\n".join(names), capture_output=True,
                              text=True, timeout=5)
        shown = done.stdout.splitlines()
        return shown if len(shown) == len(names) and done.returncode == 0 else names
    except (OSError, subprocess.SubprocessError):
        return names


def inspect_object(data: bytes, allowed: set[str], loader_names: frozenset[str] = frozenset()
                   ) -> tuple[str, str] | None:
    """(diagnosis id, message) when the student's object is refused, else None.
    `allowed`: what it may leave undefined; `loader_names`: global names of
    the reference code linked for the loader, which it may not define."""
    name = SOURCE_NAME
    try:
        sections, symbols, flags = _object_symbols(data)
    except _BadObject as exc:
        return "forbidden-object", _("The compiled %(source)s could not be checked: %(why)s.") % {"source": name, "why": exc}
    # SHF_WRITE | SHF_EXECINSTR: code that can be rewritten while it runs; no compiler makes it.
    writable_code = sorted({n for n, f in zip(sections, flags) if f & 0x1 and f & 0x4})
    if writable_code:
        return "forbidden-object", (
            _("%(source)s makes sections that are both writable and executable "
              "(%(sections)s): remove the asm or attributes that "
              "create them.") % {"source": name, "sections": _listed(writable_code, 3)})
    lto = [s for s in sections if "lto" in s.lower()]
    if lto:
        return "forbidden-object", (
            _("%(source)s carries link-time-optimisation sections (%(sections)s): "
              "code the grader cannot see in your source. The grader builds without LTO; "
              "remove the asm or attributes that create these sections.") % {"source": name, "sections": _listed(sorted(set(lto)), 3)})
    odd = sorted({s for s in sections if not _ORDINARY_SECTION.match(s)})
    if odd:
        return "forbidden-object", (
            _("%(source)s puts code or data in sections a C++ compiler does not make "
              "(%(sections)s). Remove the section attributes or asm "
              "that create them.") % {"source": name, "sections": _listed(odd)})
    undefined = sorted({s for s, _, defined in symbols if not defined})
    reference = [s for s in undefined if s.startswith("em_")]
    if reference:
        return "calls-reference", (
            ngettext("%(source)s calls %(names)s: this is a function of the grader's "
                     "reference solution, which is not part of your program. fetchColor and readTexture must "
                     "compute their answers with your own code.",
                     "%(source)s calls %(names)s: these are functions of the grader's "
                     "reference solution, which is not part of your program. fetchColor and readTexture must "
                     "compute their answers with your own code.", len(reference)) % {"source": name, "names": _listed(reference)})
    replaced = sorted({s for s, bind, defined in symbols if defined and bind == 1 and s in loader_names})
    if replaced:
        return "forbidden-object", (
            _("%(source)s defines %(names)s, which the grader's own loader code defines: "
              "yours would replace it. Rename your function or make it static.") % {"source": name, "names": _listed(replaced)})
    unknown = [s for s in undefined if s not in allowed]
    if unknown:
        shown = _demangle(unknown[:5])
        return "forbidden-object", (
            ngettext("%(source)s uses %(names)s, which is neither in the C/C++ standard library nor in "
                     "EnvironmentMap.h: define it in your file, or use only the standard library.",
                     "%(source)s uses %(names)s, which are neither in the C/C++ standard library nor in "
                     "EnvironmentMap.h: define it in your file, or use only the standard library.",
                     len(unknown)) % {"source": name, "names": _listed(shown + unknown[5:])})
    return None


# ---- what the preprocessor read -----------------------------------------------------

@functools.lru_cache(maxsize=None)
def _system_include_dirs() -> tuple[str, ...]:
    done = subprocess.run([CXX, "-std=c++17", "-E", "-x", "c++", "-v", "/dev/null"], capture_output=True,
                          text=True, stdin=subprocess.DEVNULL)
    text = done.stderr
    if "search starts here:" not in text:
        return ()
    block = text.split("#include <...> search starts here:", 1)[-1].split("End of search list.", 1)[0]
    return tuple(os.path.realpath(line.strip()) for line in block.splitlines() if line.strip())


def _dependencies(text: str) -> list[str]:
    """File names from a make rule written by -M (escaped spaces, splices)."""
    text = text.replace("\\\n", " ").replace("$$", "$")
    body = text.split(": ", 1)[1] if ": " in text else ""
    names, current, i = [], "", 0
    while i < len(body):
        c = body[i]
        if c == "\\" and i + 1 < len(body) and body[i + 1] in " #\\":
            current += body[i + 1]
            i += 2
            continue
        if c.isspace():
            if current:
                names.append(current)
            current = ""
        else:
            current += c
        i += 1
    if current:
        names.append(current)
    return names


def _outside_files(deps: list[str], scratch: Path) -> list[str]:
    """The files the preprocessor read that are neither the source, our API
    headers, nor under the compiler's system include folders."""
    allowed_dirs = _system_include_dirs()
    ours = {str(scratch / "include" / name) for name in API_HEADERS}
    bad = []
    for dep in deps:
        path = dep if os.path.isabs(dep) else str(scratch / dep)
        if dep == SOURCE_NAME or path in ours:
            continue
        if not os.path.lexists(path) and not os.path.isabs(dep) and ".." not in dep.split("/"):
            continue  # not found (-MG): the compiler says so itself
        # Under a system include folder, also when it is a link to elsewhere in /usr.
        real, plain = os.path.realpath(path), os.path.normpath(path)
        if any(real == d or real.startswith(d + "/") for d in allowed_dirs):
            continue
        if real.startswith("/usr/") and any(plain.startswith(d + "/") for d in allowed_dirs):
            continue
        bad.append(dep)
    return bad


# ---- the student's part ------------------------------------------------------------

def _enterable_by_others(folder: Path) -> bool:
    """Whether a user that is neither owner nor group can pass through every
    folder from / down to `folder` (the search bit for others)."""
    folder = folder.resolve()
    return all(os.stat(p).st_mode & stat.S_IXOTH for p in [folder, *folder.parents])


@functools.lru_cache(maxsize=None)
def _scratch_parent() -> str | None:
    """Where privilege-drop scratch folders go. The temporary folder, unless
    BUILD_UID cannot enter it (a TMPDIR that is 0700, such as pytest's or a
    private one under /root): then a folder of our own in /tmp, root's, 0711,
    made once per process. Without this the compiler could not read the
    source and the student would be told their code did not compile."""
    if _enterable_by_others(Path(tempfile.gettempdir())):
        return None
    own = Path(tempfile.mkdtemp(prefix="envmap-builds-", dir="/tmp"))
    own.chmod(0o711)
    atexit.register(shutil.rmtree, own, True)
    if not _enterable_by_others(own):
        raise HarnessBuildError(f"no folder the build user can enter: {own} and the temporary folder are closed to it")
    return str(own)


def _scratch(common: Path, source: bytes, isolation: str) -> Path:
    """A fresh folder outside the project holding copies of everything the
    student's build reads: the source, include/ (the API headers) and our
    objects. In privilege-drop mode it belongs to BUILD_UID, mode 0700, in a
    folder BUILD_UID can enter (_scratch_parent)."""
    parent = _scratch_parent() if isolation == "privilege-drop" else None
    scratch = Path(tempfile.mkdtemp(prefix="envmap-build-", dir=parent))
    try:
        (scratch / "include").mkdir()
        (scratch / "tmp").mkdir()
        for name in API_HEADERS:
            shutil.copyfile(common / "include" / name, scratch / "include" / name)
        if (common / "include" / PRECOMPILED_HEADER).is_file():
            shutil.copyfile(common / "include" / PRECOMPILED_HEADER, scratch / "include" / PRECOMPILED_HEADER)
        for name in COMMON_FILES:
            shutil.copyfile(common / name, scratch / name)
        (scratch / SOURCE_NAME).write_bytes(source)
        if isolation == "privilege-drop":
            for path in [scratch, *scratch.rglob("*")]:
                os.lchown(path, BUILD_UID, BUILD_GID)
            scratch.chmod(0o700)
    except BaseException:
        shutil.rmtree(scratch, ignore_errors=True)
        raise
    return scratch


def _take(scratch: Path, name: str, limit: int = 256 << 20) -> bytes | None:
    """A file the build wrote, read without following links, or None."""
    try:
        fd = os.open(scratch / name, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return None
    with os.fdopen(fd, "rb") as f:
        if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
            return None
        return f.read(limit)


def _refusal(diagnosis_id: str, message: str, line: int | None = None) -> dict:
    return {"ok": False, "timed_out": False, "output": "",
            "refusal": {"diagnosis_id": diagnosis_id, "message": message, "line": line}}


def _compile_and_link(source: bytes, common: Path, out_dir: Path, sanitize: bool,
                      deadline: float, extra_flags: tuple[str, ...] = (),
                      isolation: str = "none") -> dict:
    """Preprocess (to list the files read), compile to assembly, assemble,
    inspect and link the student's file in a scratch folder; the library
    goes to `out_dir`. Returns the cache record: {ok, timed_out, output,
    refusal} with output's paths neutral."""
    cxxflags, _ = _flags(sanitize)
    scratch = _scratch(common, source, isolation)
    try:
        return _build_in(scratch, common, out_dir, cxxflags, tuple(extra_flags), deadline, isolation)
    finally:
        # A compiler killed at the deadline inside bubblewrap dies a moment
        # later (its pid namespace goes with bwrap): it may still write here.
        for _ in range(20):
            shutil.rmtree(scratch, ignore_errors=True)
            if not scratch.exists():
                break
            time.sleep(0.1)


def _build_in(scratch: Path, common_dir: Path, out_dir: Path, cxxflags: list[str],
              extra_flags: tuple[str, ...], deadline: float, isolation: str) -> dict:
    include = [f"-I{scratch / 'include'}"]
    outputs: list[str] = []

    def neutral(text: str) -> str:
        text = text.replace(f"{scratch}/include/", "").replace(f"{scratch}/", "")
        return re.sub(r"^/usr/bin/ld: ", "ld: ", text, flags=re.M)

    def step(cmd: list[str], keep_output: bool = True) -> _Step:
        done = _run(cmd, scratch, deadline, isolation)
        if keep_output:
            outputs.append(done.output)
        return done

    def failed(done: _Step) -> dict:
        return {"ok": False, "timed_out": done.timed_out, "output": neutral("".join(outputs))}

    # 1. Preprocess, listing the files the preprocessor actually read (-MD):
    # each must be an API header or a system header, whatever the outcome.
    # (-fno-working-directory: with -g, GCC would name the scratch folder in a marker.)
    done = step([CXX, *cxxflags, *extra_flags, *include, "-E", "-fno-working-directory", "-MD", "-MF",
                 "deps.txt", SOURCE_NAME, "-o", STUDENT_PREPROCESSED])
    if done.timed_out:
        return failed(done)
    listed = _take(scratch, "deps.txt", 1 << 20)
    (scratch / "deps.txt").unlink(missing_ok=True)
    if listed is None and done.returncode != 0:
        # A fatal error left no list: ask the preprocessor alone (-MG:
        # missing headers are listed, not fatal) before any of its messages
        # is shown.
        again = _run([CXX, *cxxflags, *extra_flags, *include, "-M", "-MG", "-MF", "deps.txt", SOURCE_NAME],
                     scratch, deadline, isolation)
        listed = _take(scratch, "deps.txt", 1 << 20)
        (scratch / "deps.txt").unlink(missing_ok=True)
        if again.timed_out:
            return failed(again)
    if listed is not None:
        outside = _outside_files(_dependencies(listed.decode("utf-8", "surrogateescape")), scratch)
        if outside:
            shown = ", ".join(neutral(o) for o in outside[:3])
            return _refusal("refused-include", _("%(source)s makes the compiler read %(shown)s: a submission "
                                                 "may include only the C++ standard library and the template's "
                                                 "headers (EnvironmentMap.h, Vector3.h, Color.h).") % {"source": SOURCE_NAME, "shown": shown})
    if done.returncode != 0:
        return failed(done)
    # 2. The source policy, on the compiler's own tokens (no asm, #line,
    # pragmas beyond the allow-list...); then compile the source itself, not
    # the -E output: a '#' a macro puts at the start of an output line can
    # read as a line marker there (hiding what follows from the policy as
    # from the compiler), but in the source it is a stray '#', an error.
    preprocessed = _take(scratch, STUDENT_PREPROCESSED, MAX_ASSEMBLY_BYTES + 1) or b""
    if len(preprocessed) > MAX_ASSEMBLY_BYTES:
        return _refusal("forbidden-object", _("%(source)s preprocesses to more than "
                                              "%(mib)d MiB: far more than a lookup needs.") % {"source": SOURCE_NAME, "mib": MAX_ASSEMBLY_BYTES >> 20})
    refused = source_policy.refusals(preprocessed.decode("utf-8", "surrogateescape"), SOURCE_NAME)
    if refused:
        line, what = refused[0]
        more = _(" (and %(count)d more)") % {"count": len(refused) - 1} if len(refused) > 1 else ""
        return _refusal("refused-source", _("%(source)s line %(line)s: %(what)s%(more)s.") % {"source": SOURCE_NAME, "line": line, "what": what, "more": more}, line)
    (scratch / STUDENT_PREPROCESSED).unlink(missing_ok=True)
    done = step([CXX, *cxxflags, *extra_flags, *include, "-S", SOURCE_NAME, "-o", STUDENT_ASSEMBLY])
    if done.timed_out or done.returncode != 0:
        return failed(done)
    # 3. The assembly may not read files or build directives (a second wall:
    # searched as raw text, strings included, so no quoting can hide one).
    assembly = _take(scratch, STUDENT_ASSEMBLY, MAX_ASSEMBLY_BYTES + 1) or b""
    if len(assembly) > MAX_ASSEMBLY_BYTES:
        return _refusal("forbidden-object", _("%(source)s compiles to more than "
                                              "%(mib)d MiB of assembly: far more than "
                                              "a lookup needs (a huge table?).") % {"source": SOURCE_NAME, "mib": MAX_ASSEMBLY_BYTES >> 20})
    directive = _ASSEMBLER_FORBIDDEN.search(assembly.decode("utf-8", "surrogateescape"))
    if directive:
        return _refusal("forbidden-object", _("%(source)s contains the assembler directive "
                                              "%(directive)s, which reads a file or builds "
                                              "hidden code: not allowed in a submission.") % {"source": SOURCE_NAME, "directive": directive.group(0)})
    done = step([CXX, *cxxflags, "-c", STUDENT_ASSEMBLY, "-o", STUDENT_OBJECT])
    if done.timed_out or done.returncode != 0:
        return failed(done)
    # 4. What the object holds and calls.
    allowed = set((common_dir / "allowed-symbols.txt").read_text().split())
    loader_names = frozenset((common_dir / "reference-symbols.txt").read_text().split())
    problem = inspect_object(_take(scratch, STUDENT_OBJECT) or b"", allowed, loader_names)
    if problem:
        return _refusal(*problem)
    # 5. Link with our objects only, as we made them.
    for name in COMMON_FILES:
        if _take(scratch, name) != (common_dir / name).read_bytes():
            return _refusal("forbidden-object", _("The build of %(source)s changed the grader's own "
                                                  "files (%(name)s).") % {"source": SOURCE_NAME, "name": name})
    done = step([CXX, *cxxflags, "-shared", "-o", LIBRARY_NAME, STUDENT_OBJECT, "shim.o", "loader.o",
                 "libreference.a", *LINK_FLAGS, "-Wl,--version-script=exports.map", "-lm"])
    if done.timed_out or done.returncode != 0:
        return failed(done)
    library = _take(scratch, LIBRARY_NAME, MAX_LIBRARY_BYTES + 1)
    if not library:
        return failed(done)
    if len(library) > MAX_LIBRARY_BYTES:
        return _refusal("forbidden-object", _("%(source)s links into a library of more than "
                                              "%(mib)d MiB: far more than a lookup needs "
                                              "(a huge array with an initial value, or in a data section?).") % {"source": SOURCE_NAME, "mib": MAX_LIBRARY_BYTES >> 20})
    problem = inspect_library(library, allowed, sanitize="-fsanitize=address,undefined" in cxxflags)
    if problem:
        return _refusal(*problem)
    (out_dir / LIBRARY_NAME).write_bytes(library)
    (out_dir / LIBRARY_NAME).chmod(0o755)
    return {"ok": True, "timed_out": False, "output": neutral("".join(outputs))}


def build_submission(path, *, cache_dir=None, sanitize=False, timeout_s=60,
                     extra_flags: tuple[str, ...] = ()) -> BuildResult:
    """Build a submission (folder, .cpp, .zip, .tar.gz) into a loadable library.

    extra_flags: appended to the student file's compile flags only (e.g. -O0,
    -ffast-math, to measure how builds differ; docs/thresholds.md).
    Never raises for a bad submission; see the module docstring."""
    path = Path(path)
    cache_dir = Path(cache_dir) if cache_dir is not None else DEFAULT_CACHE
    try:
        chosen = _select_source(path, TEMPLATE)
    except SubmissionError as exc:
        return BuildResult(ok=False, library=None, source=path, log=str(exc),
                           errors=[{"file": None, "line": None, "message": str(exc)}],
                           diagnosis_id=exc.diagnosis_id)
    sha = hashlib.sha256(chosen.text).hexdigest()
    result = BuildResult(ok=False, library=None, source=chosen.origin or path, sha256=sha,
                         notes=list(chosen.notes), source_name=chosen.name)
    refused = refused_directives(chosen.text)
    if refused:
        lines = "; ".join(_("line %(line)d: %(what)s") % {"line": line, "what": what} for line, what in refused[:3])
        message = _("%(source)s may include only the C++ standard library and the template's headers "
                    "(EnvironmentMap.h, Vector3.h, Color.h), by name. Refused: %(lines)s") % {"source": chosen.name, "lines": lines}
        result.log = message
        result.errors = [{"file": chosen.name, "line": refused[0][0], "message": message}]
        result.diagnosis_id = "refused-include"
        return result
    refused = refused_constructs(chosen.text)
    if refused:
        lines = "; ".join(_("line %(line)d: %(what)s") % {"line": line, "what": what} for line, what in refused[:3])
        message = _("%(source)s uses what a submission may not (no inline assembly, #line, _Pragma or "
                    "pragmas beyond %(pragmas)s, ...). Refused: %(lines)s") % {"source": chosen.name, "pragmas": ", ".join(" ".join(p) for p in source_policy.PRAGMAS[:3]), "lines": lines}
        result.log = message
        result.errors = [{"file": chosen.name, "line": refused[0][0], "message": message}]
        result.diagnosis_id = "refused-source"
        return result

    common = _common_objects(cache_dir, sanitize)
    cxxflags = _flags(sanitize)[0]   # (`_` is the translation function here)
    here = Path(__file__).parent
    # The language too: a refusal's message is cached in the student's language.
    key = _fingerprint([Path(__file__), here.parent / "intake.py", here / "source_policy.py"], sha, common.name, *cxxflags,
                       *extra_flags, language())
    final = cache_dir / key[:32]
    record_path = final / "build.json"
    if record_path.is_file():
        record = json.loads(record_path.read_text())
        result.cached = True
    else:
        isolation = result.isolation = build_isolation()
        if isolation == "privilege-drop":
            # Nothing of ours readable by the compiler's uid, or nothing built.
            from .compiler import ensure_confined
            ensure_confined(path, cache_dir)
        tmp = Path(tempfile.mkdtemp(prefix=".tmp-", dir=cache_dir))
        (tmp / SOURCE_NAME).write_bytes(chosen.text)
        record = _compile_and_link(chosen.text, common, tmp, sanitize, time.monotonic() + timeout_s,
                                   tuple(extra_flags), isolation)
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
    refusal = record.get("refusal")
    if refusal:
        message = refusal["message"].replace(SOURCE_NAME, chosen.name, 1)
        result.diagnosis_id = refusal["diagnosis_id"]
        result.log = message
        result.errors = [{"file": chosen.name, "line": refusal.get("line"), "message": message}]
        return result
    describe(result, record["output"], timeout_s)
    return result
