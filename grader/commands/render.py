"""`python -m grader render SCENE.cfg --out IMAGE`: render a scene file with the
reference renderer and the reference lookup (reference/src/render.c).

The environment is the vertical cross named by the scene's environment_light
(or --map). .exr and .hdr get linear radiance; .png gets tone-mapped sRGB
(grader.envmap.imaging.tone_map).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

HELP = "render a scene file with the reference renderer"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from ..envmap.library import FILTERS
    parser.add_argument("scene", type=Path, help="scene file, e.g. envmap_test.cfg")
    parser.add_argument("--out", type=Path, required=True, help="output image: .exr, .hdr or .png")
    parser.add_argument("--map", type=Path, help="vertical-cross .hdr to use instead of the scene's")
    parser.add_argument("--filter", choices=sorted(FILTERS), default="bilinear",
                        help="texture filter of the lookup (default: bilinear, the grading reference)")
    parser.add_argument("--width", type=int, help="image width (default: the scene's)")
    parser.add_argument("--height", type=int, help="image height (default: the scene's)")
    parser.add_argument("--spp", type=int, help="samples per pixel (default: the scene's)")
    parser.add_argument("--exposure", type=float, default=0.0, help="stops, for .png only (default: 0)")


def run(args: argparse.Namespace) -> int:
    from ..envmap.imaging import write_image
    from ..envmap.library import CubeMap, EnvmapError, Scene
    try:
        scene = Scene.load(args.scene)
        width, height = scene.width, scene.height
        # One side given: keep the scene's aspect ratio.
        if args.width and not args.height:
            width, height = args.width, max(1, round(args.width * height / width))
        elif args.height and not args.width:
            width, height = max(1, round(args.height * width / height)), args.height
        elif args.width and args.height:
            width, height = args.width, args.height
        scene.set_resolution(width, height)
        if args.spp is not None:
            scene.set_samples(args.spp)
        map_path = args.map or scene.environment_path
        start = time.perf_counter()
        cube = CubeMap.load_cross(map_path)
        image = scene.render(cube, args.filter)
        seconds = time.perf_counter() - start
        write_image(args.out, image, exposure=args.exposure)
    except (EnvmapError, OSError, ValueError) as e:
        print(f"render: {e}", file=sys.stderr)
        return 1
    print(f"wrote {args.out} ({width} x {height}, map {map_path}, {args.filter}) in {seconds:.2f} s")
    return 0
