"""What a submission's code may say, decided on the compiler's own tokens.

The build preprocesses the student's file with g++ -E (in the confined
build, grader/build/__init__.py) and this module reads that output: every macro
expanded, every string concatenated by nothing yet, every digraph, splice
and trigraph already read by GCC itself, every `_Pragma` turned into a
`#pragma` line. So splitting a word across strings or macros, digraphs
(`%:`) or quoting tricks cannot hide what the compiler will compile.

Only the tokens of the student's file are judged. The linemarkers GCC writes
(`# 12 "EnvironmentMap.cpp" 2`) say which file each line comes from: a
marker with flag 1 enters an included header (the system's or our API
headers: trusted, they may use asm), flag 2 returns. A marker without flags
that names another file is a `#line` (or a GNU linemarker) written by the
student: it would make GCC quote a line of any file it can read in its
diagnostics, and is refused. (A forged marker *with* flags, `# 1 "x" 1 3`,
is refused from the text before the compiler runs:
include_policy.refused_directives.)

Refused in the student's tokens (an allow-list: a lookup needs none of it):
- inline assembly: `asm`, `__asm`, `__asm__` (with volatile, goto, labels);
- attributes that write their argument into the assembly or the symbol
  table, or set code-generation options: section, alias, weakref, symver,
  ifunc, target_clones, optimize, target, fentry_name, fentry_section,
  patchable_function_entry (any spelling: __section__, gnu::);
- `#pragma` beyond PRAGMAS (GCC writes the pragmas the compiler acts on
  into -E output; those the preprocessor acts on itself, such as
  `GCC warning`, are refused from the text, and cannot name another file
  once #line is refused);
- `#ident` / `#sccs` (a string into the assembly).
"""
from __future__ import annotations

import re

from bisect import bisect_right

from ..i18n import _
from .include_policy import DIRECTIVE, TRIGRAPHS, blank, logical_lines

ASM_KEYWORDS = frozenset({"asm", "__asm", "__asm__"})
# Attribute names (without the __x__ spelling) whose argument reaches the
# assembler or the linker as text, or which change how code is generated.
ASSEMBLY_ATTRIBUTES = frozenset({"section", "alias", "weakref", "symver", "ifunc", "target_clones",
                                 "optimize", "target", "fentry_name", "fentry_section",
                                 "patchable_function_entry"})
# The pragmas a submission may use: diagnostics and loop hints, packing,
# OpenMP (ignored: the grader builds without -fopenmp) and the standard's
# floating-point pragmas. Each is the pragma's first words.
PRAGMAS = (("GCC", "diagnostic"), ("GCC", "unroll"), ("GCC", "ivdep"), ("GCC", "novector"),
           ("pack",), ("omp",), ("STDC",), ("once",), ("region",), ("endregion",))

_LINEMARKER = re.compile(r'#[ \t]*(\d+)[ \t]+"((?:\\.|[^"\\\n])*)"([ \t\d]*)$')
# GCC writes its linemarkers and pragmas at the start of a line; a '#' token
# of the program at the start of a line gets a space before it (and GCC
# reading the -E output does not take it for a directive either).
_DIRECTIVE_LINE = re.compile(r"#[^\n]*")
# One token of preprocessed C++; raw strings first (they may span lines).
_TOKEN = re.compile(r"""
    (?P<raw>(?:u8|u|U|L)?R"(?P<delim>[^()\\\s"]{0,16})\((?:.|\n)*?\)(?P=delim)")
  | (?P<ident>[A-Za-z_$][\w$]*)
  | (?P<number>\.?[0-9](?:[eEpP][+-]|'[0-9A-Za-z_]|[0-9A-Za-z_.])*)
  | (?P<string>"(?:\\.|[^"\\\n])*"?)
  | (?P<char>'(?:\\.|[^'\\\n])*'?)
  | (?P<digraph><:|:>|<%|%>|%:)
  | (?P<newline>\n)
  | (?P<space>[ \t\f\v\r]+)
  | (?P<other>.)
""", re.X)
_DIGRAPHS = {"<:": "[", ":>": "]", "<%": "{", "%>": "}", "%:": "#"}


def pragma_allowed(text: str) -> bool:
    """Whether a pragma's text (what follows `#pragma`) is on the allow-list."""
    words = re.findall(r"[A-Za-z_]\w*", text)
    return any(tuple(words[:len(allowed)]) == allowed for allowed in PRAGMAS)


def _attribute_name(name: str) -> str:
    return name[2:-2] if name.startswith("__") and name.endswith("__") and len(name) > 4 else name


def refusals(preprocessed: str, main: str) -> list[tuple[int, str]]:
    """(line of the student's file, what) for each thing the policy refuses
    in g++ -E output `preprocessed` of the file named `main`."""
    found: list[tuple[int, str]] = []
    stack: list[str] = []          # the included files we are in (empty: the student's own text)
    current, line = main, 1
    at_line_start = True
    position = 0
    # Attribute context: ("gnu", paren depth) after __attribute__, ("std", 0) inside [[ ]].
    attribute: tuple[str, int] | None = None
    previous = ""
    end = len(preprocessed)

    def refuse(what: str) -> None:
        found.append((line, what))

    while position < end:
        if at_line_start:
            directive = _DIRECTIVE_LINE.match(preprocessed, position)
            if directive:
                text = directive.group(0).strip()
                position = directive.end()
                marker = _LINEMARKER.match(text)
                if marker:
                    number, name, flags = int(marker.group(1)), marker.group(2), marker.group(3).split()
                    if "1" in flags:
                        stack.append(name)
                    elif "2" in flags:
                        if stack:
                            stack.pop()
                        else:
                            refuse(_('a line marker returning to "%(name)s" that was never entered') % {"name": name[:80]})
                    elif not stack and name not in (current, main, "<built-in>", "<command-line>"):
                        refuse(_('#line naming another file ("%(name)s"): not allowed') % {"name": name[:80]})
                    current, line = name, number - 1
                elif not stack:
                    body = text[1:].strip()
                    if body.startswith("pragma"):
                        pragma = body[len("pragma"):].strip()
                        if not pragma_allowed(pragma):
                            refuse(_("#pragma %(pragma)s (not allowed in a submission; allowed: %(allowed)s, ...)")
                                   % {"pragma": pragma[:80], "allowed": ", ".join(" ".join(p) for p in PRAGMAS[:4])})
                    elif body.split(None, 1)[:1] in (["ident"], ["sccs"]):
                        refuse(_("#%(body)s (puts text into the assembly: not allowed)") % {"body": body[:80]})
                at_line_start = False
                continue
        if stack:
            # Inside a header (trusted text): straight to the next line GCC
            # begins with '#' (a marker, a pragma); its lines are not counted,
            # the next marker sets the line.
            found_at = preprocessed.find("\n#", position)
            position = end if found_at < 0 else found_at + 1
            at_line_start = True
            continue
        match = _TOKEN.match(preprocessed, position)
        position = match.end()
        kind = match.lastgroup
        token = match.group(0)
        if kind == "newline":
            line += 1
            at_line_start = True
            continue
        if kind == "raw":
            line += token.count("\n")
        if kind == "space" or stack:
            continue
        if kind == "digraph":
            token = _DIGRAPHS[token]
        if kind == "ident":
            if token in ASM_KEYWORDS:
                refuse(_("%(token)s: inline assembly is not allowed in a submission") % {"token": token})
            elif token in ("__attribute__", "__attribute"):
                attribute = ("gnu", 0)
            elif attribute and _attribute_name(token) in ASSEMBLY_ATTRIBUTES:
                refuse(_("the attribute %(token)s (it writes into the assembly or changes code generation: "
                         "not allowed)") % {"token": token})
        elif token == "[" and previous == "[" and attribute is None:
            attribute = ("std", 0)
        elif attribute and attribute[0] == "gnu" and token in "()":
            depth = attribute[1] + (1 if token == "(" else -1)
            attribute = None if depth <= 0 else ("gnu", depth)
        elif attribute and attribute[0] == "std" and token == "]" and previous == "]":
            attribute = None
        previous = token
    return found


# ---- the text half: directives and _Pragma, read before the compiler runs -------------

# The directives a submission may use (an allow-list; the source policy's
# text half, grader/build/source_policy.py): no #line or GNU linemarker ("# 12
# "file" 1 3"), which would make the compiler quote or attribute lines to
# another file, no #ident, #assert, #include_next, #import, #embed.
_DIRECTIVES = frozenset({"", "include", "define", "undef", "if", "ifdef", "ifndef", "elif", "elifdef",
                         "elifndef", "else", "endif", "error", "warning", "pragma"})


def _constructs_in(text: str) -> list[tuple[int, str]]:
    logical, cuts, removed = logical_lines(text.replace("\0", " ").replace("\r\n", "\n").replace("\r", "\n"))
    cleaned = blank(_blank_strings(logical))
    newlines = [m.start() for m in re.finditer("\n", cleaned)]

    def line_of(offset: int) -> int:
        at = bisect_right(cuts, offset)
        return bisect_right(newlines, offset - 1) + (removed[at - 1] if at else 0) + 1

    found = []
    for match in DIRECTIVE.finditer(cleaned):
        name, rest = match.group(1), match.group(2).strip()
        shown = f"#{name} {rest}".strip()[:120]
        if name not in _DIRECTIVES:
            found.append((line_of(match.start()), _("%(shown)s (the directive #%(name)s is not "
                                                    "allowed in a submission)") % {"shown": shown, "name": name or rest.split()[0]}))
        elif name == "pragma" and not pragma_allowed(rest):
            found.append((line_of(match.start()), _("%(shown)s (this pragma is not allowed in a submission)") % {"shown": shown}))
    for match in re.finditer(r"\b_Pragma\b", cleaned):
        found.append((line_of(match.start()), _("_Pragma (not allowed in a submission)")))
    return found


def _blank_strings(text: str) -> str:
    """String and character literals become spaces, so that "_Pragma" in a
    string is not taken for the operator (comments: blank)."""
    pieces = []
    for match in _TOKEN.finditer(text):
        piece = match.group(0)
        pieces.append(re.sub(r"[^\n]", " ", piece) if match.lastgroup in ("string", "char") else piece)
    return "".join(pieces)


def refused_constructs(text: bytes) -> list[tuple[int, str]]:
    """(line, what) for each directive outside the allow-list (#line, GNU
    linemarkers, #ident, ...), pragma outside PRAGMAS and
    _Pragma in a source, read as the compiler reads it (with trigraphs
    replaced too). The compiler's tokens are judged as well, after -E
    (source_policy.refusals): this half sees what -E does not show."""
    source = text.decode("latin-1")
    found = dict.fromkeys(_constructs_in(source))
    if "??" in source:
        for trigraph, replacement in TRIGRAPHS.items():
            source = source.replace(trigraph, replacement)
        found.update(dict.fromkeys(_constructs_in(source)))
    return sorted(found)
