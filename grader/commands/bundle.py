"""`python -m grader bundle`: the old name of `python -m grader kit`.

student_template/ no longer holds copies of the reference: the student kit is
generated from it and from reference/ by `python -m grader kit`
(grader/kit/build.py). This name stays so that old scripts keep working.
"""
from __future__ import annotations

import argparse

from . import kit

HELP = "the old name of `kit`: build the student kit"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    kit.add_arguments(parser)


def run(args: argparse.Namespace) -> int:
    print("`bundle` is now `kit`: building the student kit")
    return kit.run(args)
