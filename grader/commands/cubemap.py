"""`python -m grader cubemap`: generate the maps in Cubemap/, convert environment maps, draw the figures.

    python -m grader cubemap generate [--out Cubemap/] [--only NAME ...]
    python -m grader cubemap latlong-to-cross IN OUT --face N
    python -m grader cubemap angular-to-cross IN OUT --face N
    python -m grader cubemap cross-to-latlong IN OUT --width N
    python -m grader cubemap figures [--out docs/figures/]

Inputs may be .hdr or .exr; crosses are written as .hdr by the reference
writer; lat-long output may be .hdr, .exr or .png. Conventions and measured
errors: docs/cubemap.md.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

HELP = "generate and convert environment maps"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="action", metavar="ACTION", required=True)

    p = sub.add_parser("generate", help="write the generated maps (test map, sky, interior, grid room) into Cubemap/")
    p.add_argument("--out", type=Path, default=None, help="folder (default: the project's Cubemap/)")
    p.add_argument("--only", nargs="+", metavar="NAME", help="only these files, e.g. sky_cross.hdr")

    for name, source in (("latlong-to-cross", "a lat-long (equirectangular) map"),
                         ("angular-to-cross", "a Debevec angular map (light probe)")):
        p = sub.add_parser(name, help=f"{source} -> vertical-cross .hdr")
        p.add_argument("input", type=Path)
        p.add_argument("output", type=Path)
        p.add_argument("--face", type=int, default=256, help="face size in texels (default 256)")

    p = sub.add_parser("cross-to-latlong", help="vertical cross -> lat-long image, for viewing")
    p.add_argument("input", type=Path)
    p.add_argument("output", type=Path, help=".hdr, .exr or .png")
    p.add_argument("--width", type=int, default=1024, help="output width (height is half; default 1024)")
    p.add_argument("--exposure", type=float, default=0.0, help="stops, for .png output")

    p = sub.add_parser("figures", help="draw the handout's figures and the map previews (PNG)")
    p.add_argument("--out", type=Path, default=None, help="folder (default: docs/figures/)")


def run(args: argparse.Namespace) -> int:
    from ..cubemap import convert
    from ..envmap.library import EnvmapError

    try:
        if args.action == "generate":
            from ..cubemap.generate import CUBEMAP_DIR, GENERATED_MAPS, generate_all
            unknown = sorted(set(args.only or []) - set(GENERATED_MAPS))
            if unknown:
                print(f"cubemap generate: unknown map(s) {', '.join(unknown)}; "
                      f"choose from {', '.join(GENERATED_MAPS)}", file=sys.stderr)
                return 2
            generate_all(args.out or CUBEMAP_DIR, args.only)
        elif args.action in ("latlong-to-cross", "angular-to-cross"):
            image = convert.read_environment(args.input)
            to_faces = convert.latlong_to_faces if args.action == "latlong-to-cross" else convert.angular_to_faces
            convert.write_cross(args.output, to_faces(image, args.face))
            print(f"{args.output}: vertical cross, face {args.face}")
        elif args.action == "cross-to-latlong":
            from ..envmap.imaging import write_image
            latlong = convert.faces_to_latlong(convert.read_cross(args.input), args.width)
            write_image(args.output, latlong, exposure=args.exposure)
            print(f"{args.output}: lat-long {latlong.shape[1]} x {latlong.shape[0]}")
        elif args.action == "figures":
            from ..cubemap.figures import FIGURES_DIR, draw_all
            for path in draw_all(args.out or FIGURES_DIR):
                print(path)
    except (OSError, ValueError, EnvmapError) as error:
        print(f"cubemap {args.action}: {error}", file=sys.stderr)
        return 1
    return 0
