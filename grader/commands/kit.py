"""`python -m grader kit`: build the student kit (the student release) from
student_template/ and reference/: a folder and a .zip. See grader/kit/build.py."""
from __future__ import annotations

import argparse
import time
from pathlib import Path

HELP = "build the student kit (template, renderer, self-check; no lookup, no secret)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from ..kit.build import DEFAULT_OUT
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT,
                        help=f"the kit's folder (default: {DEFAULT_OUT}); the zip is written beside it")
    parser.add_argument("--zip", type=Path, help="where to write the zip (default: OUT.zip)")


def run(args: argparse.Namespace) -> int:
    from ..kit.build import KitError, build_kit
    t0 = time.monotonic()
    try:
        kit = build_kit(args.out, args.zip)
    except KitError as e:
        print(f"kit: {e}")
        return 1
    print(f"wrote {kit.folder} ({len(kit.files)} files) and {kit.zip_path} ({kit.size / 1e6:.1f} MB) "
          f"in {time.monotonic() - t0:.0f} s")
    return 0
