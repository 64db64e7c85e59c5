"""grader/build/objects.py: the runtime-library list is one row, read by both
walls (the symbols a student's object may import, the libraries the linked
library may need) and held beside the worker's preload list."""
import re

import pytest

from grader.build import objects
from project_paths import PROJECT_ROOT


def _verdict(monkeypatch, needed, sanitize=False):
    monkeypatch.setattr(objects, "_library_imports", lambda data: (list(needed), []))
    return objects.inspect_library(b"", set(), sanitize=sanitize)


@pytest.mark.parametrize("library", objects.RUNTIME_LIBRARIES)
def test_the_linked_library_may_need_each_runtime_library(monkeypatch, library):
    assert _verdict(monkeypatch, [library]) is None


def test_any_other_library_is_refused_by_name(monkeypatch):
    kind, words = _verdict(monkeypatch, ["libstdc++.so.6", "libz.so.1"])
    assert kind == "forbidden-object" and "libz.so.1" in words and "libstdc++" not in words


def test_sanitizer_runtimes_only_in_sanitized_builds(monkeypatch):
    assert _verdict(monkeypatch, ["libasan.so.8"], sanitize=True) is None
    assert _verdict(monkeypatch, ["libasan.so.8"])[0] == "forbidden-object"


def test_the_symbols_allowed_are_read_from_the_same_row(monkeypatch):
    asked = []

    class Done:
        stdout = ""
    monkeypatch.setattr(objects.subprocess, "run", lambda cmd, **kw: asked.append(cmd[-1]) or Done())
    objects.runtime_library_paths.cache_clear()
    try:
        objects.runtime_library_paths(True)
    finally:
        objects.runtime_library_paths.cache_clear()
    assert asked == [f"-print-file-name={n}" for n in objects.RUNTIME_LIBRARIES + objects.SANITIZER_LIBRARIES] \
        + ["-print-libgcc-file-name"]


def test_the_worker_preloads_only_runtime_libraries():
    """worker.c's preload_runtime list (C, so a copy) names libraries of the row."""
    source = (PROJECT_ROOT / "grader" / "worker" / "worker.c").read_text()
    body = re.search(r"preload_runtime\(void\)\s*\{(.*?)\n\}", source, re.S).group(1)
    preloaded = re.findall(r'"([^"]+\.so[^"]*)"', body)
    assert preloaded and set(preloaded) <= set(objects.RUNTIME_LIBRARIES)
