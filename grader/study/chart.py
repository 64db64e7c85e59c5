"""The chart: error (log) against time per lookup (log), one series per
method across face sizes, the Pareto front marked, and extra points (a
submission, or every submission of a class) on top.

    draw(rows, extra_points, path)

rows are run.run_study's rows (or run.read_csv's). An extra point is a dict
with a "label" and the columns it has (a submission measured by the study has
them all; a point from elsewhere may give only "ns_random" and
"uniform_smooth_rms"); a point missing a panel's column is left off it.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib
# The object-oriented API without pyplot: no global figure state, and a
# fraction of pyplot's import time (this is drawn once per graded submission).
from matplotlib.figure import Figure

# (error column, panel title): the smooth part, where methods differ by their
# order of accuracy, and the band along cube edges, where the per-face clamp
# and nearest break down.
PANELS = (
    ("uniform_smooth_rms", "uniform directions, away from hard edges"),
    ("edge_smooth_rms", "within one texel of a cube edge, away from hard edges"),
)
TIME_COLUMN = "ns_random"
STYLES = {
    "nearest": ("tab:gray", "s"), "bilinear": ("tab:red", "o"), "seamless": ("tab:blue", "o"),
    "numpy-bilinear": ("tab:orange", "^"), "oiio-latlong": ("tab:green", "v"),
    "bicubic": ("tab:purple", "D"),
}


def pareto_front(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The points (time, error) no other point beats in both, fastest first."""
    front, best = [], float("inf")
    for t, e in sorted(points):
        if e < best:
            front.append((t, e))
            best = e
    return front


def _series(rows: list[dict]) -> dict[str, list[dict]]:
    out: dict[str, list[dict]] = {}
    for row in rows:
        out.setdefault(row["method"], []).append(row)
    for series in out.values():
        series.sort(key=lambda r: r["face_size"])
    return out


def _finite(x) -> bool:
    try:
        return 0 < float(x) < float("inf")
    except (TypeError, ValueError):
        return False


def _plain_log_label(x, _pos=None) -> str:
    """A log axis's tick label as plain text ("0.001", "1e-05", "100"):
    matplotlib's default draws each through mathtext, which was most of the
    chart's cost (drawn once per graded submission)."""
    if x <= 0:
        return ""
    return f"{x:g}"


def draw(rows: list[dict], extra_points: list[dict] | None = None, path: str | Path = "study.png",
         panels=PANELS, time_column: str = TIME_COLUMN, title: str | None = None, dpi: int = 130) -> Path:
    """Draw the chart to path (.png or .svg); returns the path.

    Cheap on purpose (it is drawn for every graded submission): fixed
    margins instead of tight_layout (which measures every text twice), plain
    tick labels instead of mathtext, labels on major ticks only."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    extra_points = extra_points or []
    matplotlib.rcParams["svg.hashsalt"] = "grader-study"     # stable SVG ids between runs
    width, height = 6.2 * len(panels), 5.2
    fig = Figure(figsize=(width, height))
    axes = fig.subplots(1, len(panels), squeeze=False)
    for ax, (column, panel_title) in zip(axes[0], panels):
        all_points = []
        for method, series in _series(rows).items():
            pts = [(r[time_column], r[column], r["face_size"]) for r in series
                   if _finite(r[time_column]) and _finite(r[column])]
            if not pts:
                continue
            color, marker = STYLES.get(method, ("black", "x"))
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker=marker, color=color,
                    label=series[0].get("label", method), lw=1.2, ms=5)
            for t, e, size in pts:
                ax.annotate(str(size), (t, e), textcoords="offset points", xytext=(4, 2),
                            fontsize=6, color=color)
            all_points += [(t, e) for t, e, _ in pts]
        front = pareto_front(all_points)
        if front:
            # A step line: each front point is the best error for any budget up to the next.
            ts = [p[0] for p in front]
            es = [p[1] for p in front]
            ax.step(ts, es, where="post", color="black", lw=2.5, alpha=0.25, zorder=0,
                    label="Pareto front")
            ax.scatter(ts, es, s=90, facecolors="none", edgecolors="black", lw=1, zorder=3)
        shown = [p for p in extra_points if _finite(p.get(time_column)) and _finite(p.get(column))]
        for point in shown:
            ax.scatter([point[time_column]], [point[column]], marker="*", s=160,
                       color=point.get("color", "gold"), edgecolors="black", zorder=5,
                       label=point.get("label", "submission"))
        ax.set_xscale("log")
        ax.set_yscale("log")
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_locator(LogLocator(base=10, numticks=8))
            axis.set_major_formatter(FuncFormatter(_plain_log_label))
            axis.set_minor_formatter(NullFormatter())
        ax.tick_params(labelsize=8)
        ax.set_xlabel(f"time per lookup, ns ({time_column.removeprefix('ns_')} order, log)", fontsize=9)
        ax.set_ylabel(f"{column.replace('_', ' ')} error (log)", fontsize=9)
        ax.set_title(panel_title, fontsize=10)
        ax.grid(True, which="major", alpha=0.3)
        ax.grid(True, which="minor", alpha=0.1)
    handles, labels = axes[0][0].get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    if len(unique) > 12:       # a class's points: keep the legend to the methods
        unique = {k: v for k, v in unique.items() if not any(k == p.get("label") for p in extra_points)}
    # Two legend columns per panel, so a one-panel chart keeps its legend inside the figure.
    columns = 2 * len(panels)
    fig.legend(unique.values(), unique.keys(), loc="lower center", ncol=columns, fontsize=8, frameon=False)
    fig.suptitle(title or "Cube-map lookups: error against time (numbers: face size)", fontsize=11)
    # Fixed margins, in inches turned into fractions: room for the tick
    # labels and axis labels, the title on top, the legend's rows below.
    legend_rows = -(-len(unique) // columns)
    bottom_in = 0.75 + 0.19 * legend_rows
    fig.subplots_adjust(left=0.85 / width, right=1 - 0.2 / width, top=1 - 0.65 / height,
                        bottom=min(0.55, bottom_in / height), wspace=0.25)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi, metadata={"Date": None} if path.suffix == ".svg" else None)
    return path
