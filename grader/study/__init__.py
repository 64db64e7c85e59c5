"""The study: what each cube-map lookup method costs in time and gets wrong.

    ground_truth   an analytic environment with exact radiance per direction
    bake           the environment averaged over each texel's solid angle
    methods        the lookups compared (reference C, numpy, OpenImageIO, a submission)
    accuracy       direction sets and error statistics against the ground truth
    timing         nanoseconds per lookup, median of repeats
    failure_map    seam jumps at the 12 edges and 8 corners, ties, degenerate input
    chart          error against time per lookup, the Pareto front, extra points
    run            the whole study: rows for the CSV and the chart

Directions <-> (face, u, v) and solid angles come from grader/envmap/geometry.py
(on the reference library), like everywhere else.
`python -m grader study` (grader/commands/study.py) runs it; docs/study.md
reads the result.
"""
from .. import PROJECT_ROOT

# The study's rows (one per method and face size). A grading input (the speed
# check draws a submission on this chart), so it lives with the fixtures, not
# under docs/; `make study` rewrites it.
STUDY_CSV = PROJECT_ROOT / "fixtures" / "study.csv"
