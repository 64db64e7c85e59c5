"""The pages' template engine: jinja2 with autoescape, once for every page.

Templates and the one stylesheet live in templates/. Every value a template
prints is cleaned (text.clean) and escaped by the engine's finalize hook,
with autoescape on behind it: nothing in a page is escaped by hand. The hook
escapes with the standard library's html.escape rather than markupsafe's
spelling (&quot; and &#x27;, not &#34; and &#39;) so that the pages' bytes
stayed what they were when they were f-strings. HTML made here on purpose (Markdown
rendered with raw HTML off) is passed as markupsafe.Markup and printed as is.
The templates' words go through grader.i18n like the code's (babel.cfg
extracts templates/*.html for the catalogue).
"""
from __future__ import annotations

from html import escape
from pathlib import Path

from jinja2 import Environment, FileSystemBytecodeCache, FileSystemLoader, StrictUndefined, select_autoescape
from markupsafe import Markup

from .. import PROJECT_ROOT
from ..i18n import _, language, ngettext
from .text import clean

TEMPLATES = Path(__file__).resolve().parent / "templates"
STYLESHEET = TEMPLATES / "report.css"
# Compiled templates, kept between processes (each grading of grade-all is
# one): compiling report.html took a tenth of a correct grading's own time.
# Keyed by the template's source, so an edit compiles again.
TEMPLATE_CACHE = PROJECT_ROOT / "build" / "templates"


class _BytecodeCache(FileSystemBytecodeCache):
    """jinja2's cache in TEMPLATE_CACHE, where it can be written; a tree
    that cannot be written (an installed kit, a read-only image) compiles
    each time, as without a cache."""

    def __init__(self, folder: Path):
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError:
            pass
        super().__init__(str(folder))

    def load_bytecode(self, bucket) -> None:
        try:
            super().load_bytecode(bucket)
        except OSError:
            pass

    def dump_bytecode(self, bucket) -> None:
        try:
            super().dump_bytecode(bucket)
        except OSError:
            pass


def _finalize(value: object) -> Markup:
    """Text printed into a page: clean (no control characters, no ANSI
    codes), then escaped, attribute quotes included; our own Markup as is."""
    return value if isinstance(value, Markup) else Markup(escape(clean(str(value)), quote=True))


ENVIRONMENT = Environment(
    loader=FileSystemLoader(TEMPLATES),
    autoescape=select_autoescape(["html"], default_for_string=True),
    finalize=_finalize,
    undefined=StrictUndefined,     # a misspelt name fails the page, never prints nothing
    trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True,
    bytecode_cache=_BytecodeCache(TEMPLATE_CACHE),
)
ENVIRONMENT.globals.update(_=_, ngettext=ngettext, language=language)


def stylesheet() -> str:
    """The pages' one stylesheet (report.css), read at each use so that
    an edit shows without a restart."""
    return STYLESHEET.read_text(encoding="utf-8")


def render_page(name: str, **values: object) -> str:
    return ENVIRONMENT.get_template(name).render(stylesheet=Markup(stylesheet()), **values)
