"""Compiler messages -> what the student reads (grader/build/__init__.py's log).

The compiler's output is cached with paths made neutral; this module turns
it, on every call, into friendly sentences for the common mistakes, then the
compiler's messages, errors first, trimmed.
"""
from __future__ import annotations

import re

from ..i18n import N_, _

SOURCE_NAME = "EnvironmentMap.cpp"
# The members of EnvironmentMap a submission defines; the rest are ours.
STUDENT_MEMBERS = ("fetchColor", "readTexture")
MEMORY_LIMIT_BYTES = 2 << 30
MAX_LOG_LINES = 60
# One compiler run's messages kept; past this it is stopped (a macro repeating
# a #pragma warning printed a gigabyte into the grader's memory and cache).
MAX_COMPILER_OUTPUT_BYTES = 4 << 20
# The marker build.py puts into the (cached) compiler output, in English;
# shown in the student's language (describe).
OUTPUT_STOPPED_TEXT = N_("(the grader stopped the compiler: it printed more than %(mib)d MiB of messages)")
OUTPUT_STOPPED = OUTPUT_STOPPED_TEXT % {"mib": MAX_COMPILER_OUTPUT_BYTES >> 20}
MAX_LOG_CHARS = 6000


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
            where = _("inline in EnvironmentMap.h") if name == "faceAddress" else "EnvironmentMapLoader.cpp"
            say(_("%(source)s must not define %(name)s: it is provided (%(where)s). Delete your definition.")
                % {"source": SOURCE_NAME, "name": name, "where": where})
    for name in _TYPE_REDEFINITION.findall(output):
        say(_("%(source)s must not define %(name)s again: include \"%(name)s.h\" instead.")
            % {"source": SOURCE_NAME, "name": name})
    for name in _NO_DECLARATION.findall(output):
        if name in STUDENT_MEMBERS:
            say(_("%(name)s must keep the signature EnvironmentMap.h declares; the header cannot change.")
                % {"name": name})
        else:
            say(_("EnvironmentMap::%(name)s is not declared in EnvironmentMap.h, which you cannot change: "
                  "write helpers as free functions in your file (e.g. in an anonymous namespace).")
                % {"name": name})
    if OUTPUT_STOPPED in output:
        say(_("The compiler printed more than %(mib)d MiB of messages and was "
              "stopped: far more than any program needs (a macro that repeats a warning?).")
            % {"mib": MAX_COMPILER_OUTPUT_BYTES >> 20})
    if "virtual memory exhausted" in output or "out of memory allocating" in output:
        say(_("The compiler ran out of memory (the limit is %(gib)d GiB).") % {"gib": MEMORY_LIMIT_BYTES >> 30})
    for header in _MISSING_HEADER.findall(output):
        # The student's file first: describe() renames the first EnvironmentMap.cpp.
        say(_("%(source)s includes \"%(header)s\", which the grader does not have: a submission is "
              "%(source)s alone, built with the template's headers (EnvironmentMap.h, Vector3.h, "
              "Color.h) and the C++ standard library.") % {"source": SOURCE_NAME, "header": header})
    for symbol in dict.fromkeys(_LINK_UNDEFINED.findall(output)):
        member = re.match(r"EnvironmentMap::(\w+)\(", symbol)
        if member and member.group(1) in STUDENT_MEMBERS:
            say(_("%(source)s must define %(name)s (the function %(symbol)s); it is missing.")
                % {"source": SOURCE_NAME, "name": member.group(1), "symbol": symbol})
        else:
            say(_("%(symbol)s is declared but never defined: define it in %(source)s.")
                % {"symbol": symbol, "source": SOURCE_NAME})
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
        lines = lines[:MAX_LOG_LINES] + [_("... (%(count)d more lines)") % {"count": len(lines) - MAX_LOG_LINES}]
    text = "\n".join(lines)
    if len(text) > MAX_LOG_CHARS:
        text = text[:MAX_LOG_CHARS] + "\n" + _("... (trimmed)")
    return text


def _stopped(stopped_by: str, timeout_s: float) -> str:
    """Which of the build's two bounds stopped it, with the number that
    applied (compiler.Deadline): its CPU time is the source's doing; the
    wall-clock bound is reached only when the machine was too busy."""
    if stopped_by == "wall":
        from ..worker.process import wall_bound
        return _("The build was stopped after waiting %(wall)s s for the machine, which was too busy: the compiler "
                 "had used less than its %(seconds)s s of processor time, so this is not your code's doing. "
                 "Submit again later; if it happens again, tell your instructor.") % {
                     "wall": f"{wall_bound(timeout_s):g}", "seconds": f"{timeout_s:g}"}
    return _("The compiler used more than %(seconds)s s of processor time on this file and was stopped. "
             "Something in it makes compiling take that long (for example deep template or constexpr "
             "recursion, or a large table computed at compile time): make it simpler.") % {
                 "seconds": f"{timeout_s:g}"}


def describe(result, output: str, timeout_s: float) -> None:
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
        sentences.insert(0, _stopped(result.stopped_by, timeout_s))
    if not result.ok:
        if not sentences and not result.errors:
            sentences = [_("The build failed; the compiler's messages follow.")]
        result.errors[:0] = [{"file": name, "line": None, "message": s} for s in sentences]
        if not sentences:
            first = result.errors[0]
            sentences = [f"{first['file']}:{first['line']}: error: {first['message']}"]
    blocks = _blocks(output.replace(OUTPUT_STOPPED, _(OUTPUT_STOPPED_TEXT) % {"mib": MAX_COMPILER_OUTPUT_BYTES >> 20}))
    ordered = [l for kind, lines in blocks if kind == "error" for l in lines] + \
              [l for kind, lines in blocks if kind == "warning" for l in lines]
    result.log = _trim(sentences + ([""] if sentences and ordered else []) + ordered)
