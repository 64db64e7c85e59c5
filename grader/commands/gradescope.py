"""`python -m grader gradescope`: build autograder.zip."""
from __future__ import annotations

import argparse
from pathlib import Path

from .. import PROJECT_ROOT

HELP = "build autograder.zip for Gradescope"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", type=Path, default=PROJECT_ROOT / "build" / "autograder.zip")


def run(args) -> int:
    from ..gradescope import build_bundle
    path = build_bundle(args.out)
    print(f"wrote {path} ({path.stat().st_size / 1e6:.1f} MB): upload it as the autograder on Gradescope")
    return 0
