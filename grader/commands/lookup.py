"""`python -m grader lookup --map FILE.hdr [--filter F]`: directions in, colours out.

Reads one direction `x y z` per line from stdin, looks every direction up in
the vertical-cross map with the reference library, and prints `r g b` per
line (%.9g). Input is checked whole before anything is printed, so a bad line
gives an error naming it and no partial output.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np

HELP = "look up directions read from stdin in a cube map (reference)"


class InputError(ValueError):
    """A line of stdin that is not three numbers."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from ..envmap.library import FILTERS
    parser.add_argument("--map", required=True, metavar="FILE.hdr",
                        help="environment map: a Radiance .hdr vertical cross")
    parser.add_argument("--filter", choices=sorted(FILTERS), default="bilinear",
                        help="texture filter (default: bilinear, the grading reference)")


def parse_directions(lines) -> np.ndarray:
    """(n, 3) float64 from lines of `x y z`; InputError names the first bad line."""
    dirs = []
    for number, line in enumerate(lines, start=1):
        words = line.split()
        if len(words) != 3:
            raise InputError(f"line {number}: expected three numbers 'x y z', got {line.rstrip()!r}")
        try:
            dirs.append([float(word) for word in words])
        except ValueError:
            raise InputError(f"line {number}: not a number in {line.rstrip()!r}") from None
    return np.array(dirs, dtype=np.float64).reshape(-1, 3)


def run(args: argparse.Namespace) -> int:
    from grader.envmap.library import CubeMap, EnvmapError

    try:
        cube = CubeMap.load_cross(args.map)
    except EnvmapError as error:
        print(f"grader lookup: {error}", file=sys.stderr)
        return 1
    try:
        dirs = parse_directions(sys.stdin)
    except InputError as error:
        print(f"grader lookup: stdin {error}", file=sys.stderr)
        return 2
    rgb = cube.fetch(dirs, args.filter)
    sys.stdout.write("".join(f"{r:.9g} {g:.9g} {b:.9g}\n" for r, g, b in rgb))
    return 0
