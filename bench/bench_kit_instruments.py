"""The numpy instrument the student kit needs, timed against the library
code it replaces (the grader's development environment still has
scikit-image): image_metrics.ssim against scikit-image's
structural_similarity. Both give the same answers
(tests/unit/checks/instruments/test_image_metrics.py); this says what that costs.

    .venv/bin/python bench/bench_kit_instruments.py [--repeats 9]

Prints medians and the ratio numpy / library, measured in the same run
(the machine is shared: quote ratios, not absolute times).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

from grader.grading import fixtures  # noqa: E402
from grader.checks.instruments.image_metrics import display, ssim  # noqa: E402


def median_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=9)
    args = parser.parse_args()
    from skimage.metrics import structural_similarity

    renders = [display(np.load(p)) for p in sorted((fixtures.FIXTURES / "renders").glob("*.npy"))]
    pairs = [(r, np.clip(r + 0.001, 0, 1).astype(np.float32)) for r in renders]

    def numpy_ssim():
        for a, b in pairs:
            ssim(a, b)

    def scikit_ssim():
        for a, b in pairs:
            structural_similarity(a, b, data_range=1.0, channel_axis=2, gaussian_weights=True, sigma=1.5,
                                  use_sample_covariance=False, K1=0.01, K2=0.03)

    for name, ours, theirs, library in (
            (f"SSIM, the {len(pairs)} fixture renders", numpy_ssim, scikit_ssim, "scikit-image")):
        t_ours, t_theirs = median_time(ours, args.repeats), median_time(theirs, args.repeats)
        print(f"{name}: numpy {t_ours * 1e3:.0f} ms, {library} {t_theirs * 1e3:.0f} ms, "
              f"ratio {t_ours / t_theirs:.2f} (median of {args.repeats})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
