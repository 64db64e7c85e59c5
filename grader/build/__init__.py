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
("none"). Always with stdin /dev/null, a scrubbed environment, CPU/memory/
descriptor limits, oom_score_adj 1000 in the grading's memory and cpu cgroups
(grader/worker/memory.py), and a deadline in CPU time of the compiler's
processes with the wall clock only as an outer bound (compiler.Deadline).

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
import shutil
import stat
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..i18n import _, language
from ..intake import (MAX_SOURCE_BYTES, SOURCE_NAME, ChosenSource,  # noqa: F401 (re-exported)
                      SubmissionError, select_source as _select_source)
from . import source_policy
from .common import COMMON_FILES, DEFAULT_CACHE, PRECOMPILED_HEADER, TEMPLATE, common_objects, fingerprint, publish
from .compiler import (BUILD_GID, BUILD_UID, LINK_FLAGS, CXX, Deadline, HarnessBuildError,
                       compile_flags, run_compiler, CompilerStep, build_isolation)
from .include_policy import API_HEADERS, make_rule_files, outside_files, refused_directives
from .messages import describe
from .objects import ASSEMBLER_FORBIDDEN, inspect_library, inspect_object
from .source_policy import refused_constructs

LIBRARY_NAME = "submission.so"
STUDENT_OBJECT = "EnvironmentMap.o"
STUDENT_ASSEMBLY = "EnvironmentMap.s"
STUDENT_PREPROCESSED = "EnvironmentMap.ii"
MAX_ASSEMBLY_BYTES = 64 << 20
# The linked library: copied into every worker's folder and kept in the build
# cache (240 MiB of zeros in .data compiled from a 4 KiB source scored 100).
MAX_LIBRARY_BYTES = 64 << 20
# Every BuildResult.diagnosis_id a build can give (grader/grading/catalogue.py has each).
DIAGNOSIS_IDS = ("build-error", "no-source", "empty-submission", "unknown-format", "unreadable-archive",
                 "refused-include", "refused-source", "calls-reference", "forbidden-object")

# The code whose change can change a build's record (its messages are worked
# out on every call: messages.py is not among them).
KEY_SOURCES = [Path(__file__).with_name(name) for name in
               ("__init__.py", "include_policy.py", "source_policy.py", "compiler.py", "objects.py", "common.py")
               ] + [Path(__file__).parent.parent / "intake.py"]

# Re-exported for older callers.
select_source = functools.partial(_select_source, template=TEMPLATE)


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
    stopped_by: str = ""          # a build that timed out: "cpu" (the compiler's CPU time) or "wall" (the outer bound)
    # Why the build failed, an id of grader/grading/catalogue.py: "build-error" (the
    # compiler's), or a refusal: no-source, empty-submission, unknown-format,
    # unreadable-archive, refused-include, calls-reference, forbidden-object.
    diagnosis_id: str = "build-error"
    isolation: str = ""           # how the compiler ran: bubblewrap, privilege-drop or none ("" when cached)


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
                      deadline: Deadline, extra_flags: tuple[str, ...] = (),
                      isolation: str = "none") -> dict:
    """Preprocess (to list the files read), compile to assembly, assemble,
    inspect and link the student's file in a scratch folder; the library
    goes to `out_dir`. Returns the cache record: {ok, timed_out, output,
    refusal} with output's paths neutral."""
    cxxflags, _ = compile_flags(sanitize)
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
              extra_flags: tuple[str, ...], deadline: Deadline, isolation: str) -> dict:
    include = [f"-I{scratch / 'include'}"]
    outputs: list[str] = []

    def neutral(text: str) -> str:
        text = text.replace(f"{scratch}/include/", "").replace(f"{scratch}/", "")
        return re.sub(r"^/usr/bin/ld: ", "ld: ", text, flags=re.M)

    def step(cmd: list[str], keep_output: bool = True) -> CompilerStep:
        done = run_compiler(cmd, scratch, deadline, isolation)
        if keep_output:
            outputs.append(done.output)
        return done

    def failed(done: CompilerStep) -> dict:
        return {"ok": False, "timed_out": done.timed_out, "stopped_by": done.stopped_by,
                "output": neutral("".join(outputs))}

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
        again = run_compiler([CXX, *cxxflags, *extra_flags, *include, "-M", "-MG", "-MF", "deps.txt", SOURCE_NAME],
                     scratch, deadline, isolation)
        listed = _take(scratch, "deps.txt", 1 << 20)
        (scratch / "deps.txt").unlink(missing_ok=True)
        if again.timed_out:
            return failed(again)
    if listed is not None:
        outside = outside_files(make_rule_files(listed.decode("utf-8", "surrogateescape")), scratch)
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
    directive = ASSEMBLER_FORBIDDEN.search(assembly.decode("utf-8", "surrogateescape"))
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

    common = common_objects(cache_dir, sanitize)
    cxxflags = compile_flags(sanitize)[0]   # (`_` is the translation function here)
    # The language too: a refusal's message is cached in the student's language.
    key = fingerprint(KEY_SOURCES, sha, common.name, *cxxflags,
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
        record = _compile_and_link(chosen.text, common, tmp, sanitize, Deadline.of(timeout_s),
                                   tuple(extra_flags), isolation)
        if record["timed_out"]:
            # Not cached: a loaded machine may finish the same build next time.
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            (tmp / "build.json").write_text(json.dumps(record))
            publish(tmp, final)

    if chosen.origin is None and final.is_dir():
        result.source = final / SOURCE_NAME
    result.ok = bool(record["ok"])
    result.timed_out = bool(record["timed_out"])
    result.stopped_by = record.get("stopped_by", "")
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
