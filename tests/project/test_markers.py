"""The markers tests/conftest.py gives by name must name real tests: a
renamed test would otherwise slip back into `make test-fast` unnoticed."""
from __future__ import annotations

import subprocess
import sys

from conftest import MODULE_MARKERS, PROJECT_ROOT, TEST_MARKERS


def collected(expression: str, *paths: str) -> set[str]:
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "--collect-only", "-p", "no:xdist",
                          "-m", expression, *paths], cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=300)
    assert run.returncode in (0, 5), run.stdout[-3000:] + run.stderr[-3000:]
    return {line.strip() for line in run.stdout.splitlines() if "::" in line}


def cases(node: str, among: set[str]) -> set[str]:
    """The collected tests a name stands for."""
    return {n for n in among if n == node or ("[" not in node and n.startswith(node + "["))}


def test_every_named_test_exists_and_test_fast_leaves_it_out():
    """A name without [case] stands for every case of the test; with it, for that case."""
    files = sorted({f"tests/{name.split('::')[0]}.py" for name in TEST_MARKERS})
    everything = collected("", *files)
    fast = collected("not slow and not sanitizer and not browser", *files)

    for name in TEST_MARKERS:
        module, test = name.split("::")
        node = f"tests/{module}.py::{test}"
        assert cases(node, everything), f"{name} is not a test (renamed?)"
        assert not cases(node, fast), f"{name} still runs in test-fast"
    assert fast, "the fast set of those files is empty: the expression is wrong"


def test_every_module_named_exists():
    for module in MODULE_MARKERS:
        assert (PROJECT_ROOT / "tests" / f"{module}.py").is_file(), module


def makefile_expression(target: str) -> str:
    """The -m expression the Makefile's target gives pytest, $(FAST) filled in."""
    import re
    text = (PROJECT_ROOT / "Makefile").read_text()
    fast = re.search(r"^FAST = (.+)$", text, re.M).group(1)
    recipe = re.search(rf"^{re.escape(target)}:.*\n\t(.+)$", text, re.M).group(1)
    return re.search(r'-m "([^"]+)"', recipe).group(1).replace("$(FAST)", fast)


def test_make_test_runs_the_representative_tests_and_test_fast_does_not():
    from conftest import REPRESENTATIVE
    files = sorted({f"tests/{name.split('::')[0]}.py" for name in REPRESENTATIVE})
    everything = collected("", *files)
    tier = collected(makefile_expression("test"), *files)
    fast = collected(makefile_expression("test-fast"), *files)
    assert fast < tier < everything, "make test should run more than test-fast and less than test-all"
    for name in REPRESENTATIVE:
        module, test = name.split("::")
        found = cases(f"tests/{module}.py::{test}", everything)
        assert found, f"{name} is not a test (renamed?)"
        assert found <= tier, f"{name} is representative but make test leaves it out"
        assert not found & fast, f"{name} runs in test-fast already: it need not be named representative"
