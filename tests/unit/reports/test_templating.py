"""The pages' template engine keeps compiled templates between processes
(templating.TEMPLATE_CACHE) and works where that folder cannot be written."""
from __future__ import annotations

from pathlib import Path

from jinja2 import Environment, FileSystemLoader

from grader.reports import templating


def _environment(cache_folder: Path) -> Environment:
    return Environment(loader=FileSystemLoader(templating.TEMPLATES), autoescape=True,
                       bytecode_cache=templating._BytecodeCache(cache_folder))


def test_a_compiled_template_is_kept_and_read_back(tmp_path: Path):
    first = _environment(tmp_path / "cache")
    first.get_template("figure.html")
    kept = list((tmp_path / "cache").iterdir())
    assert len(kept) == 1
    # A second process (a new environment) loads it instead of compiling.
    second = _environment(tmp_path / "cache")
    compiled = []
    second.compile = lambda *a, **k: compiled.append(a) or Environment.compile(second, *a, **k)
    second.get_template("figure.html")
    assert not compiled


def test_a_folder_that_cannot_be_made_only_costs_the_compilation(tmp_path: Path):
    (tmp_path / "a file").write_text("")
    _environment(tmp_path / "a file" / "cache").get_template("figure.html")
