"""The study: what each cube-map lookup method costs in time and gets wrong.

    ground_truth   an analytic environment with exact radiance per direction
    geometry       directions <-> (face, u, v), in numpy, per ASSIGNMENT.md
    bake           the environment averaged over each texel's solid angle
    methods        the lookups compared (reference C, numpy, OpenImageIO, a submission)
    accuracy       direction sets and error statistics against the ground truth
    timing         nanoseconds per lookup, median of repeats
    failure_map    seam jumps at the 12 edges and 8 corners, ties, degenerate input
    chart          error against time per lookup, the Pareto front, extra points
    run            the whole study: rows for the CSV and the chart

`python -m grader study` (grader/commands/study.py) runs it; docs/study.md
reads the result.
"""
