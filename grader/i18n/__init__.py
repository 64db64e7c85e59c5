"""The language students read: one setting per course, gettext catalogues.

Student-facing words are written in English in the code, marked with `_()`
(translated where they are used) or `N_()` (marked only: tables built at
import, translated where they are shown). The Japanese words are in
grader/i18n/locale/ja/LC_MESSAGES/grader.po, kept in the repository; the grader
reads it with Babel and compiles it in memory on first use, so a fresh
clone and the Gradescope and PrairieLearn bundles need no build step and no
committed .mo. The student kit's copy of the grader has no Babel: the kit's
build writes compiled .mo files into that copy (compile_catalogues), and a
grader.mo beside (or instead of) the .po is read with the standard library's
gettext. Fuzzy and empty entries are not used (they fall back to English),
and tests/unit/i18n/test_i18n.py fails while any remain.
docs/glossary_ja.md says how to update the catalogue and which words to use.

The language is process-wide, set by grader.grading.grade.grade() for each
submission from (first found) GradeOptions.lang, the GRADER_LANG environment
variable (what `--lang` of grade-all, gradescope and prairielearn sets, so
their worker processes see it) and the rubric's grading.language.
"""
from __future__ import annotations

import ast
import gettext
import io
import os
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path

from .languages import CODES as LANGUAGES, DEFAULT  # one row per language
DOMAIN = "grader"
LOCALE_DIR = Path(__file__).resolve().parent / "locale"
ENV = "GRADER_LANG"


class UnknownLanguage(ValueError):
    """A language the grader has no catalogue for."""


def check_language(lang: str) -> str:
    if lang not in LANGUAGES:
        raise UnknownLanguage(f"language {lang!r} is not one of {', '.join(LANGUAGES)}")
    return lang


_current = DEFAULT


def set_language(lang: str) -> None:
    """Make `lang` the language of everything a student reads from now on."""
    global _current
    _current = check_language(lang)


def choose(option: str | None, rubric: dict) -> str:
    """The language of one run: --lang, then GRADER_LANG, then the rubric."""
    return check_language(option or os.environ.get(ENV) or rubric.get("grading", {}).get("language") or DEFAULT)


def override_from_command_line(lang: str | None) -> None:
    """`--lang` of commands whose grading runs deeper down (or in workers)."""
    if lang:
        os.environ[ENV] = check_language(lang)


def language() -> str:
    return _current


def po_path(lang: str, locale_dir: Path = LOCALE_DIR) -> Path:
    return locale_dir / lang / "LC_MESSAGES" / f"{DOMAIN}.po"


def mo_path(lang: str, locale_dir: Path = LOCALE_DIR) -> Path:
    return po_path(lang, locale_dir).with_suffix(".mo")


def compiled(lang: str) -> bytes:
    """The .mo of `lang`, compiled from its .po with Babel (fuzzy entries left out)."""
    from babel.messages.mofile import write_mo
    from babel.messages.pofile import read_po
    with po_path(lang).open("rb") as f:
        catalog = read_po(f, locale=lang, domain=DOMAIN)
    buf = io.BytesIO()
    write_mo(buf, catalog, use_fuzzy=False)
    return buf.getvalue()


def compile_catalogues(dest_locale_dir: Path) -> list[Path]:
    """Write every translated language's grader.mo under dest_locale_dir
    (<lang>/LC_MESSAGES/grader.mo), compiled with Babel from this grader's
    .po: what a copy of the grader without Babel (the student kit's) reads.
    Never into the grader's own locale/: a .mo there would be read instead of
    the .po and could go stale."""
    dest_locale_dir = Path(dest_locale_dir)
    if dest_locale_dir.resolve() == LOCALE_DIR:
        raise ValueError(f"{dest_locale_dir} is the grader's own catalogue folder: compile into a copy "
                         "(the grader reads its .po directly)")
    written = []
    for lang in LANGUAGES:
        if lang == DEFAULT:
            continue
        path = mo_path(lang, dest_locale_dir)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(compiled(lang))
        written.append(path)
    return written


@lru_cache(maxsize=None)
def translations(lang: str) -> gettext.NullTranslations:
    """The catalogue of `lang` (English: the ids): a compiled grader.mo where
    one is present (the student kit's copy, written by compile_catalogues;
    read with the standard library), else the .po compiled with Babel (the
    grader, whose locale/ holds no .mo)."""
    if check_language(lang) == DEFAULT:
        return gettext.NullTranslations()
    mo = mo_path(lang)
    if mo.is_file():
        with mo.open("rb") as f:
            return gettext.GNUTranslations(f)
    return gettext.GNUTranslations(io.BytesIO(compiled(lang)))


def _(message: str) -> str:
    """`message` in the current language."""
    return translations(_current).gettext(message)


def ngettext(singular: str, plural: str, n: int) -> str:
    return translations(_current).ngettext(singular, plural, n)


def N_(message: str) -> str:
    """Marks `message` for the catalogue without translating it (yet)."""
    return message


class Translated(Mapping):
    """A table of marked words (N_) that reads out in the current language:
    module-level tables keep their shape and their readers stay as they are."""

    def __init__(self, table: dict):
        self._table = dict(table)

    def __getitem__(self, key):
        return _(self._table[key])

    def __iter__(self):
        return iter(self._table)

    def __len__(self):
        return len(self._table)

    def msgid(self, key) -> str:
        return self._table[key]


def and_list(items: list[str]) -> str:
    """"a, b and c" in the current language."""
    items = [str(i) for i in items]
    if len(items) <= 1:
        return "".join(items)
    return _("%(items)s and %(last)s") % {"items": ", ".join(items[:-1]), "last": items[-1]}


# The marking functions and how many leading string arguments are messages.
MARKERS = {"_": 1, "N_": 1, "ngettext": 2}


def extract_python(fileobj, keywords, comment_tags, options):
    """Babel extraction method for the grader (babel.cfg): every call of a
    MARKERS function with literal strings, read from the syntax tree (so
    calls inside f-strings count too, and `_(table[key])` is not mistaken
    for a message), and the first docstring line of every @check function
    (the check's title, grader.checks.check)."""
    source = fileobj.read()
    tree = ast.parse(source.decode(options.get("encoding", "utf-8")) if isinstance(source, bytes) else source)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in MARKERS:
            n = MARKERS[node.func.id]
            args = node.args[:n]
            if len(args) == n and all(isinstance(a, ast.Constant) and isinstance(a.value, str) for a in args):
                texts = tuple(a.value for a in args)
                found.append((node.lineno, node.func.id, texts[0] if n == 1 else texts, []))
        elif isinstance(node, ast.FunctionDef) and any(_is_check_decorator(d) for d in node.decorator_list):
            doc = ast.get_docstring(node)
            if doc:
                found.append((node.body[0].lineno, None, doc.strip().splitlines()[0], ["check title"]))
    yield from sorted(found, key=lambda f: (f[0], str(f[2])))


def _is_check_decorator(node) -> bool:
    func = node.func if isinstance(node, ast.Call) else node
    return getattr(func, "id", None) == "check" or getattr(func, "attr", None) == "check"
