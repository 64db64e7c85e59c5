"""grader/i18n/languages.py: one row per language, and every copy read off it."""
import argparse
import importlib
import re
import shutil
import subprocess

import pytest

from grader import cli, i18n
from grader.i18n import languages
from grader.kit import selfcheck
from project_paths import PROJECT_ROOT


def test_the_codes_and_default_are_the_rows():
    assert i18n.LANGUAGES == languages.CODES == tuple(r.code for r in languages.ROWS)
    assert i18n.DEFAULT == languages.DEFAULT in languages.CODES


def test_each_translated_language_has_its_catalogue_and_no_other_exists():
    translated = {c for c in languages.CODES if c != languages.DEFAULT}
    assert {p.name for p in i18n.LOCALE_DIR.iterdir() if p.is_dir()} == translated
    assert all(i18n.po_path(c).is_file() for c in translated)


def test_the_kit_compiles_a_catalogue_per_translated_language(tmp_path):
    written = i18n.compile_catalogues(tmp_path)
    assert written == [i18n.mo_path(c, tmp_path) for c in languages.CODES if c != languages.DEFAULT]


def _lang_choices(command: str):
    module = importlib.import_module(f"grader.commands.{cli.module_name(command)}")
    parser = argparse.ArgumentParser()
    module.add_arguments(parser)
    return next((a.choices for a in parser._actions if a.dest == "lang"), None)


def test_lang_offers_the_rows_wherever_it_is_an_option():
    offered = {c: _lang_choices(c) for c in cli.COMMANDS}
    with_lang = {c for c, choices in offered.items() if choices is not None}
    assert with_lang == {"grade", "grade-all", "gradescope", "prairielearn"}
    assert all(tuple(offered[c]) == languages.CODES for c in with_lang)


def test_the_kits_selfcheck_takes_each_language_and_no_other(capsys):
    for code in languages.CODES:
        assert selfcheck.parse_args(["--lang", code]).lang == code
    with pytest.raises(SystemExit):
        selfcheck.parse_args(["--lang", "xx"])
    assert "invalid choice" in capsys.readouterr().err


def test_no_module_names_a_language_but_the_table():
    """A language code as a string literal anywhere else in grader/ is a second copy."""
    table = PROJECT_ROOT / "grader" / "i18n" / "languages.py"
    literal = re.compile("|".join(rf"""["']{c}["']""" for c in languages.CODES if c != languages.DEFAULT))
    copies = [f"{p.relative_to(PROJECT_ROOT)}:{n}" for p in (PROJECT_ROOT / "grader").rglob("*.py") if p != table
              for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if literal.search(line)]
    assert copies == []


def test_packages_txt_installs_each_languages_fonts():
    lines = [line.split()[0] for line in (PROJECT_ROOT / "packages.txt").read_text().splitlines()
             if line.strip() and not line.startswith("#")]
    for row in languages.ROWS:
        if row.packages:
            assert "|".join(row.packages) in lines, row.code
        assert bool(row.packages) == bool(row.fonts), row.code


def test_the_font_found_comes_from_one_of_the_rows_packages():
    """Observed on this machine: dpkg says which package the font found belongs to."""
    font = languages.glyph_font("ja")
    if font is None or shutil.which("dpkg") is None:
        pytest.skip("no Japanese font or no dpkg here")
    owner = subprocess.run(["dpkg", "-S", font], capture_output=True, text=True).stdout.split(":")[0]
    assert owner in languages.row("ja").packages
    assert languages.glyph_font(languages.DEFAULT) is None
