"""The RGBE reader and the cross cutter under AddressSanitizer and UBSan.

reference/fuzz/corpus_driver.c runs each file of the fuzz seed corpus (and
the real probes) through the fuzz harness without libFuzzer; any
out-of-bounds access, use of freed memory, leak, undefined behaviour or
broken promise of envmap.h aborts it with a report.
"""
from __future__ import annotations

import fcntl
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from grader import PROBES as PROBE_DIR
from grader import PROJECT_ROOT

pytestmark = [pytest.mark.sanitizer, pytest.mark.slow]   # AddressSanitizer builds and fuzzing

FUZZ = PROJECT_ROOT / "reference" / "fuzz"
DRIVER = PROJECT_ROOT / "build" / "asan" / "rgbe_corpus_driver"
PROBES = sorted(PROBE_DIR.glob("*.hdr"))
SANITIZER_ENV = {
    **os.environ,
    "ASAN_OPTIONS": "abort_on_error=1:detect_leaks=1",
    "UBSAN_OPTIONS": "print_stacktrace=1:halt_on_error=1",
}
REPORT_MARKERS = ("ERROR: AddressSanitizer", "ERROR: LeakSanitizer", "runtime error:", "broken promise")


def _compiler_with_sanitizers(tmp: Path) -> str | None:
    """The first of clang, gcc whose -fsanitize=address,undefined builds and runs."""
    source = tmp / "probe.c"
    source.write_text("int main(void) { return 0; }\n")
    for cc in ("clang", "gcc"):
        if shutil.which(cc) is None:
            continue
        binary = tmp / f"probe_{cc}"
        built = subprocess.run([cc, "-fsanitize=address,undefined", "-o", str(binary), str(source)],
                               capture_output=True)
        if built.returncode == 0 and subprocess.run([str(binary)], env=SANITIZER_ENV).returncode == 0:
            return cc
    return None


@pytest.fixture(scope="module")
def sanitizer_cc(tmp_path_factory) -> str:
    cc = _compiler_with_sanitizers(tmp_path_factory.mktemp("cc"))
    if cc is None:
        pytest.skip("no C compiler with working -fsanitize=address,undefined (tried clang, gcc)")
    return cc


@pytest.fixture(scope="module")
def driver(sanitizer_cc) -> Path:
    DRIVER.parent.mkdir(parents=True, exist_ok=True)
    # pytest-xdist workers share build/: one builds while the others wait
    with open(DRIVER.parent / ".rgbe_corpus_driver.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        built = subprocess.run(["make", "-s", "-C", str(FUZZ), "driver", f"SANITIZER_CC={sanitizer_cc}"],
                               capture_output=True, text=True)
    assert built.returncode == 0, built.stdout + built.stderr
    return DRIVER


def _run(driver: Path, *inputs) -> subprocess.CompletedProcess:
    return subprocess.run([str(driver), *map(str, inputs)], capture_output=True, text=True,
                          env=SANITIZER_ENV, timeout=300)


def test_sanitizers_are_live(sanitizer_cc, tmp_path):
    """A control: the same compiler and options do catch a read past a heap block."""
    source = tmp_path / "overflow.c"
    source.write_text("#include <stdlib.h>\nint main(int c, char **v) { (void)v;\n"
                      "  char *p = malloc(4); int x = p[c + 3]; free(p); return x; }\n")
    binary = tmp_path / "overflow"
    subprocess.run([sanitizer_cc, "-g", "-fsanitize=address,undefined", "-o", str(binary), str(source)],
                   check=True)
    run = subprocess.run([str(binary)], capture_output=True, text=True, env=SANITIZER_ENV)
    assert run.returncode != 0 and "heap-buffer-overflow" in run.stderr


def test_seed_corpus_runs_clean_under_sanitizers(driver):
    seeds = sorted(p for p in (FUZZ / "corpus").iterdir() if p.is_file())
    assert len(seeds) >= 30, "the seed corpus is missing (make -C reference/fuzz seeds)"
    run = _run(driver, *seeds)
    report = run.stdout + run.stderr
    assert run.returncode == 0 and not any(m in report for m in REPORT_MARKERS), report[-4000:]
    assert f"{len(seeds)} inputs" in run.stdout


@pytest.mark.skipif(not PROBES, reason=f"no probes in {PROBE_DIR}")
def test_real_probes_run_clean_under_sanitizers(driver):
    run = _run(driver, *PROBES)
    report = run.stdout + run.stderr
    assert run.returncode == 0 and not any(m in report for m in REPORT_MARKERS), report[-4000:]
    assert f"{len(PROBES)} inputs" in run.stdout
