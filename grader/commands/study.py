"""`python -m grader study`: speed against accuracy of the lookup methods.

Writes to --out (default build/study-figures/): study.csv (one row per
method and face size), study.png and study.svg (the chart),
failure_map.csv, failure_map.md, failure_map.png (seams, ties, degenerate
directions, at face size 32) and bake_error.csv (the bake's own error).
Timings are this machine's, so the committed figures change only when asked:
--update writes to docs/study/ and the rows to fixtures/study.csv (a grading
input: the speed check's chart), as `make study UPDATE=1` does.
"""
from __future__ import annotations

import csv
import sys
from pathlib import Path

from .. import PROJECT_ROOT

HELP = "speed against accuracy of the lookup methods"
FAILURE_MAP_SIZE = 32
# OpenImageIO reads textures from files: the lat-long conversions live here.
OIIO_WORK_DIR = PROJECT_ROOT / "build" / "study" / "oiio"
DEFAULT_OUT = PROJECT_ROOT / "build" / "study-figures"
COMMITTED_OUT = PROJECT_ROOT / "docs" / "study"      # with --update, and the rows to fixtures/study.csv


def add_arguments(parser) -> None:
    parser.add_argument("--submission", type=Path,
                        help="a submission (folder, .cpp, .zip, .tar.gz) to add to the chart")
    parser.add_argument("--out", type=Path, default=None,
                        help="output folder (default build/study-figures/)")
    parser.add_argument("--update", action="store_true",
                        help="update the committed figures: write to docs/study/ and fixtures/study.csv")
    parser.add_argument("--sizes", type=int, nargs="+", help="face sizes (default 8 ... 512)")
    parser.add_argument("--quick", action="store_true",
                        help="a small configuration (sizes 8 and 32, fewer directions)")
    parser.add_argument("--extra-points", type=Path,
                        help="CSV of extra chart points (label, ns_random, uniform_smooth_rms, ...)")
    parser.add_argument("--no-oiio", action="store_true", help="leave OpenImageIO out")
    parser.add_argument("--no-bicubic", action="store_true", help="leave the numpy bicubic out")


def _submission(path: Path):
    """The submission as a study method, through the isolated worker."""
    from ..build import build_submission
    from ..study.methods import submission_method
    from ..worker.lookups import bind_submission   # (build result, faces) -> lookup
    build = build_submission(path)
    if not build.ok:
        raise SystemExit(f"study: {path} does not build:\n{build.log}")
    return submission_method(lambda faces: bind_submission(build, faces),
                             name="submission", label=f"submission ({path.name})")


def _write_failure_map(out: Path, quick: bool) -> None:
    from ..study import failure_map
    from ..study.bake import bake
    from ..study.ground_truth import DEFAULT_ENVIRONMENT
    from ..study.methods import bicubic_method, numpy_method, oiio_method

    faces = bake(DEFAULT_ENVIRONMENT, FAILURE_MAP_SIZE)
    methods = {"nearest": "nearest", "bilinear": "bilinear", "seamless": "seamless",
               "numpy-bilinear": numpy_method().bind(faces)}
    if not quick:
        methods["oiio-latlong"] = oiio_method(OIIO_WORK_DIR).bind(faces)
        methods["bicubic"] = bicubic_method().bind(faces)
    rows = failure_map.failure_table(faces, methods)
    with open(out / "failure_map.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.3g}" if isinstance(v, float) else v) for k, v in row.items()})
    (out / "failure_map.md").write_text(failure_map_markdown(rows))
    failure_map.draw_failure_map(rows, out / "failure_map.png",
                                 title=f"Seams at face size {FAILURE_MAP_SIZE}: largest colour jump "
                                       "across the 12 edges (left) and 8 corners (right)")


def failure_map_markdown(rows: list[dict]) -> str:
    summary = ["method", "max_edge_jump", "max_corner_jump", "ties", "u,v = 0 or 1"]
    degenerate = [k for k in rows[0] if k.startswith("dir ")]
    lines = ["| " + " | ".join(summary) + " |", "|" + "---|" * len(summary)]
    for row in rows:
        lines.append("| " + " | ".join(f"{row[k]:.2g}" if isinstance(row[k], float) else str(row[k])
                                       for k in summary) + " |")
    lines += ["", "| method | " + " | ".join(k[4:] for k in degenerate) + " |",
              "|---|" + "---|" * len(degenerate)]
    for row in rows:
        lines.append(f"| {row['method']} | " + " | ".join(row[k] for k in degenerate) + " |")
    return "\n".join(lines) + "\n"


def destinations(out: Path | None, update: bool) -> tuple[Path, Path]:
    """(folder for the figures, where the rows go). The rows are a grading
    input: fixtures/study.csv, only when updating the committed figures."""
    from ..study import STUDY_CSV
    if update:
        return COMMITTED_OUT, STUDY_CSV
    out = out or DEFAULT_OUT
    return out, out / "study.csv"


def _read_points(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        points = list(csv.DictReader(f))
    for point in points:
        for key, value in point.items():
            if key != "label" and key != "color":
                try:
                    point[key] = float(value)
                except (TypeError, ValueError):
                    pass
    return points


def run(args) -> int:
    from ..study import chart
    from ..study.bake import bake_error
    from ..study.ground_truth import DEFAULT_ENVIRONMENT
    from ..study.methods import default_methods
    from ..study.run import StudyConfig, run_study, write_csv

    if args.update and args.out is not None:
        print("study: --update writes to docs/study/; leave out --out", file=sys.stderr)
        return 2
    out, rows_csv = destinations(args.out, args.update)
    out.mkdir(parents=True, exist_ok=True)
    config = StudyConfig.quick() if args.quick else StudyConfig()
    if args.sizes:
        config.sizes = tuple(args.sizes)
    methods = default_methods(OIIO_WORK_DIR, include_oiio=not args.no_oiio,
                              include_bicubic=not args.no_bicubic)
    submission = _submission(args.submission) if args.submission else None
    if submission:
        methods.append(submission)

    def progress(message: str) -> None:
        print(f"study: {message}", file=sys.stderr, flush=True)

    rows = run_study(config, methods, progress=progress)
    write_csv(rows, rows_csv)
    extra = _read_points(args.extra_points) if args.extra_points else []
    if submission:
        # The submission's series stays on the chart; its point at the
        # largest size is the star the report shows.
        own = [r for r in rows if r["method"] == submission.name]
        if own:
            extra.append(dict(own[-1], label=own[-1]["label"]))
    for suffix in (".png", ".svg"):
        chart.draw(rows, extra, out / f"study{suffix}")

    progress("failure map")
    _write_failure_map(out, args.quick)
    progress("bake error")
    with open(out / "bake_error.csv", "w", newline="") as f:
        writer = None
        for size in [s for s in config.sizes if s <= 128]:
            row = bake_error(DEFAULT_ENVIRONMENT, size)
            writer = writer or csv.DictWriter(f, fieldnames=list(row))
            if f.tell() == 0:
                writer.writeheader()
            writer.writerow({k: (f"{v:.3g}" if isinstance(v, float) else v) for k, v in row.items()})
    print(f"study: wrote {out}/study.csv, study.png, study.svg, failure_map.*, bake_error.csv")
    return 0
