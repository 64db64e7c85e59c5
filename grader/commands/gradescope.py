"""`python -m grader gradescope`: build autograder.zip for Gradescope.

Upload the zip as a "Zip file upload" autograder (base image Ubuntu 24.04,
which has Python 3.12; on 22.04 setup.sh installs python3.11). Gradescope
runs setup.sh once to build the image, then run_autograder for every
submission, each in its own container. Set the course secret in
grader/rubric.toml ([grading] secret) before building: the zip carries it
to Gradescope, whose students never see the autograder's files.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from .. import PROJECT_ROOT

HELP = "build autograder.zip for Gradescope"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.description = __doc__.split("\n", 1)[1].strip("\n")
    p.add_argument("--out", type=Path, default=PROJECT_ROOT / "build" / "autograder.zip",
                   help="where to write the zip (default: build/autograder.zip)")


def run(args) -> int:
    from ..gradescope import build_bundle
    path = build_bundle(args.out)
    print(f"wrote {path} ({path.stat().st_size / 1e6:.1f} MB): upload it as the autograder on Gradescope")
    return 0
