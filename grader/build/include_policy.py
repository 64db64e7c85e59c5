"""What a submission may make the compiler read: the three API headers and
the standard library, by name only. Judged twice: from the text before any
compiler runs (includes by path or macro, #embed, __has_include, file-reading
pragmas; read as the compiler reads it: comments, splices, digraphs,
trigraphs), and from the files the preprocessor actually read (-MD).
The text reader here is shared with the source policy's text half.
"""
from __future__ import annotations

import functools
import os
import re
import subprocess
from bisect import bisect_right
from pathlib import Path

from ..i18n import _
from ..intake import SOURCE_NAME
from .compiler import CXX

# The only headers a submission sees (copies in the scratch folder's include/).
API_HEADERS = ("EnvironmentMap.h", "Vector3.h", "Color.h")


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
DIRECTIVE = re.compile(r"^[ \t\f\v]*(?:#|%:)[ \t\f\v]*(\w*)(.*)$", re.M)
# A header named plainly: letters, digits, _ . + - and / between them.
# (What follows the name is ignored by GCC, with a warning: "#include <cmath>;" is harmless.)
_PLAIN_HEADER = re.compile(r'^(<[\w.+-]+(?:/[\w.+-]+)*>|"[\w.+-]+(?:/[\w.+-]+)*")')
# The argument is looked at up to 300 characters: a longer one is refused.
_HAS_INCLUDE = re.compile(r"\b(__has_(?:include|embed)\w*)[ \t]*(\(([^)\n]{0,300})\))?")
_PRAGMA_FILES = re.compile(r"\b(dependency|pch_preprocess)\b")
TRIGRAPHS = {"??=": "#", "??/": "\\", "??'": "^", "??(": "[", "??)": "]", "??!": "|", "??<": "{",
              "??>": "}", "??-": "~"}


def _plain_header(argument: str) -> bool:
    match = _PLAIN_HEADER.match(argument)
    if not match:
        return False
    name = match.group(1)[1:-1]
    return ".." not in name.split("/")


def logical_lines(text: str) -> tuple[str, list[int], list[int]]:
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


def blank(text: str) -> str:
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
    logical, cuts, removed = logical_lines(text.replace("\0", " ").replace("\r\n", "\n").replace("\r", "\n"))
    cleaned = blank(logical)

    newlines = [m.start() for m in re.finditer("\n", cleaned)]

    def line_of(offset: int) -> int:
        at = bisect_right(cuts, offset)
        return bisect_right(newlines, offset - 1) + (removed[at - 1] if at else 0) + 1

    found: list[tuple[int, str]] = []
    for match in DIRECTIVE.finditer(cleaned):
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


def refused_directives(text: bytes) -> list[tuple[int, str]]:
    """(line, what) for each line of a source that could make the compiler
    read a file other than a standard or API header: includes by path or by
    macro, #embed, __has_include of a path, file-reading pragmas, .incbin.
    The text is read as the compiler reads it (comments, splices, digraphs)
    and, in case trigraphs are on, once more with them replaced."""
    source = text.decode("latin-1")
    found = dict.fromkeys(_refusals_in(source))
    if "??" in source:
        for trigraph, replacement in TRIGRAPHS.items():
            source = source.replace(trigraph, replacement)
        found.update(dict.fromkeys(_refusals_in(source)))
    return sorted(found)


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


def make_rule_files(text: str) -> list[str]:
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


def outside_files(deps: list[str], scratch: Path) -> list[str]:
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
