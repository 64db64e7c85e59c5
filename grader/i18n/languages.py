"""The languages students can read, one row each: the one place a language is
named. Everything else is read off these rows and held to them by
tests/unit/i18n/test_languages.py: `--lang`'s choices (grade, grade-all,
gradescope, prairielearn, the kit's self-check), the rubric's
grading.language, the catalogues compiled into the student kit
(grader.i18n.compile_catalogues), the fonts the pictures are captioned with
and packages.txt's font line.

A new language: a row here, its catalogue (locale/<code>/LC_MESSAGES/grader.po,
docs/glossary_ja.md says how), and packages.txt's line if it names packages.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Language:
    code: str                      # --lang, the rubric's grading.language, GRADER_LANG, locale/<code>/
    name: str                      # in its own words
    # Font files with its glyphs, the first found captions the pictures (arrows,
    # the speed chart); () when the Latin fonts suffice.
    fonts: tuple[str, ...] = ()
    # Debian/Ubuntu packages, alternatives, one of which installs one of `fonts`
    # (packages.txt's line "a|b").
    packages: tuple[str, ...] = ()


ROWS = (
    Language("en", "English"),     # the catalogue's ids: no catalogue of its own
    Language("ja", "日本語",
             fonts=("/usr/share/fonts/opentype/ipafont-gothic/ipag.ttf",
                    "/usr/share/fonts/truetype/fonts-japanese-gothic.ttf",
                    "/usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc",
                    "/usr/share/fonts/opentype/noto/NotoSansCJKjp-Regular.otf"),
             packages=("fonts-ipafont-gothic", "fonts-noto-cjk")),
)
CODES = tuple(row.code for row in ROWS)
DEFAULT = "en"


def row(code: str) -> Language:
    return next(r for r in ROWS if r.code == code)


def glyph_font(code: str) -> str | None:
    """The path of a font with `code`'s glyphs on this machine: None when the
    Latin fonts suffice or none of its fonts is installed (DejaVu has no
    Japanese glyphs: its captions would be tofu boxes)."""
    return next((f for f in row(code).fonts if Path(f).is_file()), None)
