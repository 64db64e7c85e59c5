"""The reference library's own tests, run again against its AddressSanitizer
and UBSan build (build/asan/libenvmap.so): lookups, scenes, renders, the RGBE
reader and the cross cutter must be clean, not only correct."""
import os
import subprocess
import sys

import pytest

from grader import PROJECT_ROOT

pytestmark = [pytest.mark.sanitizer, pytest.mark.slow]   # AddressSanitizer builds

ASAN_LIBRARY = PROJECT_ROOT / "build" / "asan" / "libenvmap.so"
SUITES = ["tests/reference/test_lookup.py", "tests/reference/test_scene.py", "tests/reference/test_render.py", "tests/reference/test_rgbe.py", "tests/reference/test_cross.py"]
REPORT_MARKERS = ("ERROR: AddressSanitizer", "runtime error:")


def test_reference_tests_pass_under_asan_and_ubsan():
    built = subprocess.run(["make", "-s", "-C", str(PROJECT_ROOT), "build/asan/libenvmap.so"], capture_output=True, text=True)
    assert built.returncode == 0, built.stderr
    libasan = subprocess.run(["cc", "-print-file-name=libasan.so"], capture_output=True, text=True).stdout.strip()
    if not os.path.isabs(libasan):
        pytest.skip("the C compiler has no AddressSanitizer runtime")
    env = {**os.environ, "ENVMAP_LIBRARY": str(ASAN_LIBRARY), "LD_PRELOAD": libasan,
           # CPython itself leaks by design; UBSan stops at the first finding.
           "ASAN_OPTIONS": "detect_leaks=0:abort_on_error=1", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1"}
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:xdist", "-p", "no:cacheprovider",
                          "-k", "not subprocess and not command", *SUITES],
                         cwd=PROJECT_ROOT, env=env, capture_output=True, text=True, timeout=900)
    output = run.stdout + run.stderr
    assert not [m for m in REPORT_MARKERS if m in output], output[-4000:]
    assert run.returncode == 0, output[-4000:]
