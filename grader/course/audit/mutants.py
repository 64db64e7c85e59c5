"""Single-token mutants of a correct solution, made on C++ tokens.

The tokens come from Pygments' C++ lexer (a dependency of rich, locked in
requirements.lock): it tells comments, string and character literals (raw
strings too), preprocessor lines and numbers apart as the compiler does, so
a `<` in `#include <cmath>`, a `+` in a comment or a string is never
mutated. Pygments yields punctuation one character at a time; adjacent
characters are joined here into C++ punctuators by maximal munch (`>=`,
`&&`, `->`, `::`), as the compiler reads them.

Each mutant changes one token (or deletes one unary minus, or inserts one)
and is identified by the hash of its text: two rules that make the same file
make one mutant.
"""
from __future__ import annotations

import hashlib
import random
import re
from dataclasses import dataclass
from pathlib import Path

from pygments.lexers import CppLexer
from pygments.token import Comment, Keyword, Name, Number, Operator, Punctuation, String

# C++ punctuators made of several characters, longest first (maximal munch).
PUNCTUATORS = sorted({"<<=", ">>=", "<=>", "->*", "...", "::", "->", "++", "--", "<<", ">>", "<=", ">=", "==",
                      "!=", "&&", "||", "+=", "-=", "*=", "/=", "%=", "&=", "|=", "^=", ".*"},
                     key=len, reverse=True)

# Operator kinds (Mutant.operator), the order in which reports list them.
OPERATORS = ("arithmetic", "relation", "logical", "constant", "name", "rounding", "sign")

ARITHMETIC = {"+": ("-",), "-": ("+",), "*": ("/",), "/": ("*",), "+=": ("-=",), "-=": ("+=",),
              "*=": ("/=",), "/=": ("*=",), "++": ("--",), "--": ("++",)}
RELATION = {"<": ("<=", ">"), "<=": ("<", ">="), ">": (">=", "<"), ">=": (">", "<="), "==": ("!=",),
            "!=": ("==",)}
LOGICAL = {"&&": ("||",), "||": ("&&",)}
# Names that differ by these parts are swapped for one another (`ax` -> `ay`,
# `FACE_POS_X` -> `FACE_NEG_X`, `m_FaceWidth` -> `m_FaceHeight`), when the
# new name exists in the file or is one of KNOWN_NAMES, so that most swaps compile.
NAME_GROUPS = (("x", "y", "z"), ("X", "Y", "Z"), ("u", "v"), ("0", "1"), ("POS", "NEG"), ("Width", "Height"),
               ("alpha", "beta"), ("min", "max"))
ROUNDING_GROUP = ("floor", "ceil", "round", "trunc")
# The template's API and the standard functions a swap may land on.
KNOWN_NAMES = frozenset({"FACE_POS_X", "FACE_NEG_X", "FACE_POS_Y", "FACE_NEG_Y", "FACE_POS_Z", "FACE_NEG_Z",
                         "m_FaceWidth", "m_FaceHeight", "min", "max", *ROUNDING_GROUP})
EXPRESSION_KEYWORDS = frozenset({"return", "case", "else", "do"})
CASTS = frozenset({"static_cast", "reinterpret_cast", "const_cast", "dynamic_cast", "template"})
# Tokens after which a `-` is unary and a `-` may be inserted before a name.
UNARY_CONTEXT = frozenset({"(", ",", "=", "return", "?", ":", "+", "-", "*", "/", "<", ">", "<=", ">=", "==",
                           "!=", "&&", "||", "[", "+=", "-=", "*=", "/="})


@dataclass(frozen=True)
class Token:
    start: int
    text: str
    kind: str          # "name", "keyword", "number", "punct"

    @property
    def end(self) -> int:
        return self.start + len(self.text)


def tokenize(source: str) -> list[Token]:
    """The code tokens of a C++ source: no comments, literals of text, preprocessor lines or blanks."""
    raw = []
    for start, kind, text in CppLexer().get_tokens_unprocessed(source):
        if not text.strip() or kind in Comment or kind in String:
            continue
        if kind in Number:
            raw.append(Token(start, text, "number"))
        elif kind in Keyword:
            raw.append(Token(start, text, "keyword"))
        elif kind in Name:
            raw.append(Token(start, text, "name"))
        elif kind in Operator or kind in Punctuation:
            for i, ch in enumerate(text):   # Pygments may group characters; split, then munch below
                raw.append(Token(start + i, ch, "punct"))
        else:
            raw.append(Token(start, text, "other"))
    return _munch(raw)


def _munch(tokens: list[Token]) -> list[Token]:
    out, i = [], 0
    while i < len(tokens):
        t = tokens[i]
        if t.kind == "punct":
            for p in PUNCTUATORS:
                n = len(p)
                run = tokens[i:i + n]
                if (len(run) == n and all(r.kind == "punct" for r in run) and "".join(r.text for r in run) == p
                        and all(run[k + 1].start == run[k].end for k in range(n - 1))):
                    out.append(Token(t.start, p, "punct"))
                    i += n
                    break
            else:
                out.append(t)
                i += 1
        else:
            out.append(t)
            i += 1
    return out


@dataclass(frozen=True)
class Mutant:
    solution: str      # the correct solution's name
    operator: str      # one of OPERATORS
    line: int          # 1-based line of the change
    before: str        # the line as it was (stripped)
    after: str         # the line as the mutant has it (stripped)
    source: str        # the mutant's whole text

    @property
    def id(self) -> str:
        return f"{self.solution}-{hashlib.sha256(self.source.encode()).hexdigest()[:10]}"

    @property
    def diff(self) -> str:
        """One line: where, and the line before -> after."""
        return f"{self.solution}:{self.line}: {self.before}  =>  {self.after}"


def _template_brackets(tokens: list[Token]) -> set[int]:
    """Indices of `<` and `>` that are template brackets (static_cast<int>,
    std::array<float, 3>): mutating them only makes a file that does not compile."""
    out = set()
    typeish = {"name", "keyword", "number"}
    for i, t in enumerate(tokens):
        if t.text != "<" or i == 0 or tokens[i - 1].kind != "name" and tokens[i - 1].text not in CASTS:
            continue
        for j in range(i + 1, min(i + 12, len(tokens))):
            u = tokens[j]
            if u.text in (">", ">>"):
                after = tokens[j + 1].text if j + 1 < len(tokens) else ""
                if tokens[i - 1].text in CASTS or after in ("(", "{", "::", ">", ";") or \
                        (j + 1 < len(tokens) and tokens[j + 1].kind == "name"):
                    out.update((i, j))
                break
            if u.kind not in typeish and u.text not in ("::", ",", "*", "&"):
                break
    return out


def _number_variants(text: str) -> list[str]:
    """c + 1, c - 1 and 0 for a literal (its suffix kept; negatives in brackets)."""
    m = re.fullmatch(r"([0-9.]+(?:[eE][+-]?[0-9]+)?)([fFlLuU]*)", text.replace("'", ""))
    if not m:
        return []
    body, suffix = m.groups()
    is_float = any(c in body for c in ".eE")
    try:
        value = float(body) if is_float else int(body)
    except ValueError:
        return []
    out = []
    for v in (value + 1, value - 1, 0):
        if v == value:
            continue
        if is_float:
            s = repr(float(v))
            s = s if any(c in s for c in ".e") else s + ".0"
        else:
            s = str(v)
        s += suffix
        out.append(f"({s})" if v < 0 else s)
    return out


def _name_variants(name: str, names: set[str]) -> list[tuple[str, str]]:
    """(operator, new name) for every name this one can be swapped for."""
    out = []
    groups = [("name", g) for g in NAME_GROUPS] + [("rounding", ROUNDING_GROUP)]
    for operator, group in groups:
        for part in group:
            for m in re.finditer(re.escape(part), name):
                for other in group:
                    if other == part:
                        continue
                    new = name[:m.start()] + other + name[m.end():]
                    if new != name and (new in names or new in KNOWN_NAMES) and (operator, new) not in out:
                        out.append((operator, new))
    return out


def mutants_of(source: str, solution: str) -> list[Mutant]:
    """Every single-token mutant of `source`, deduplicated, in source order."""
    tokens = tokenize(source)
    brackets = _template_brackets(tokens)
    names = {t.text for t in tokens if t.kind == "name"}
    lines = source.splitlines()
    seen = {hashlib.sha256(source.encode()).hexdigest()}
    out: list[Mutant] = []

    def add(operator: str, start: int, end: int, new: str) -> None:
        text = source[:start] + new + source[end:]
        digest = hashlib.sha256(text.encode()).hexdigest()
        if digest in seen:
            return
        seen.add(digest)
        line = source.count("\n", 0, start)
        out.append(Mutant(solution, operator, line + 1, lines[line].strip(), text.splitlines()[line].strip(), text))

    for i, t in enumerate(tokens):
        prev = tokens[i - 1].text if i else ""
        pointer = t.text == "*" and i > 0 and tokens[i - 1].kind == "keyword"   # float* p: a declarator
        if t.kind == "punct" and i not in brackets and not pointer:
            if t.text == "-" and prev in UNARY_CONTEXT:
                add("sign", t.start, t.end, "")          # a unary minus dropped
            for table, operator in ((ARITHMETIC, "arithmetic"), (RELATION, "relation"), (LOGICAL, "logical")):
                for new in table.get(t.text, ()):
                    add(operator, t.start, t.end, new)
        elif t.kind == "number":
            for new in _number_variants(t.text):
                add("constant", t.start, t.end, new)
        elif t.kind == "name":
            # A name right after a type or another name is being declared:
            # renaming it only makes a file that does not compile.
            declared = i > 0 and tokens[i - 1].kind in ("name", "keyword") and prev not in EXPRESSION_KEYWORDS
            for operator, new in ([] if declared else _name_variants(t.text, names)):
                add(operator, t.start, t.end, new)
            # Not before an assignment, nor a braced initialiser (-FaceCoord{...} does not compile).
            if prev in UNARY_CONTEXT and (i + 1 >= len(tokens) or tokens[i + 1].text not in ("=", "+=", "-=", "{")):
                if i < 2 or tokens[i - 2].text not in (".", "->", "::") and prev not in ("-",):
                    add("sign", t.start, t.start, "-")   # a minus inserted before a name
    return out


def solution_name(path: Path) -> str:
    """examples/perfect/EnvironmentMap.cpp -> "perfect"; correct/if_chain.cpp -> "if_chain"."""
    path = Path(path)
    return path.parent.name if path.name == "EnvironmentMap.cpp" else path.stem


def solution_source(path: Path) -> Path:
    """The .cpp of a solution given as a file or a folder holding EnvironmentMap.cpp."""
    path = Path(path)
    if path.is_dir():
        return path / "EnvironmentMap.cpp"
    return path


def all_mutants(solutions: list[Path]) -> list[Mutant]:
    """The mutants of every solution, deduplicated across them (two solutions
    with the same text give one set, under the first one's name)."""
    out, seen = [], set()
    for path in solutions:
        for m in mutants_of(solution_source(path).read_text(), solution_name(path)):
            digest = hashlib.sha256(m.source.encode()).hexdigest()
            if digest not in seen:
                seen.add(digest)
                out.append(m)
    return out


def sample(mutants: list[Mutant], n: int | None, seed: int) -> list[Mutant]:
    """n mutants drawn with `seed` (all when n is None or larger), in their original order."""
    if n is None or n >= len(mutants):
        return list(mutants)
    chosen = set(random.Random(seed).sample(range(len(mutants)), n))
    return [m for i, m in enumerate(mutants) if i in chosen]
