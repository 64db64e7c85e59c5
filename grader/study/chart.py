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

import math
from pathlib import Path

from ..i18n import N_, _, language, languages

# (error column, panel title): the smooth part, where methods differ by their
# order of accuracy, and the band along cube edges, where the per-face clamp
# and nearest break down.
PANELS = (
    ("uniform_smooth_rms", N_("uniform directions, away from hard edges")),
    ("edge_smooth_rms", N_("within one texel of a cube edge, away from hard edges")),
)
# The error columns' axis labels (other columns: their name).
ERROR_LABELS = {"uniform_smooth_rms": N_("uniform smooth rms error (log)"),
                "edge_smooth_rms": N_("edge smooth rms error (log)")}
TIME_COLUMN = "ns_random"
# The time columns' lookup orders, as the x axis names them.
TIME_ORDERS = {"ns_random": N_("random"), "ns_coherent": N_("coherent")}
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
         panels=PANELS, time_column: str = TIME_COLUMN, title: str | None = None, dpi: int = 130,
         layout: list | None = None) -> Path:
    """Draw the chart to path (.png or .svg); returns the path. `layout`, a
    list, receives each panel's axes box in pixels and data limits.

    Cheap on purpose (it is drawn for every graded submission): fixed
    margins instead of tight_layout (which measures every text twice), plain
    tick labels instead of mathtext, labels on major ticks only."""
    import matplotlib
    # The object-oriented API without pyplot: no global figure state, and a
    # fraction of pyplot's import time; imported here (and in _draw), so
    # draw_with_point's cached path needs no matplotlib at all.
    extra_points = extra_points or []
    matplotlib.rcParams["svg.hashsalt"] = "grader-study"     # stable SVG ids between runs
    with matplotlib.rc_context(_font_settings()):
        return _draw(rows, extra_points, path, panels, time_column, title, dpi, layout)


def _font_settings() -> dict:
    """Japanese labels need a font with Japanese glyphs (DejaVu has none):
    the one the arrow pictures use (grader/checks/arrows.py), DejaVu after
    it for any glyph it lacks."""
    font = languages.glyph_font(language())
    if font is None:
        return {}
    from matplotlib import font_manager
    font_manager.fontManager.addfont(font)
    name = font_manager.FontProperties(fname=font).get_name()
    return {"font.family": "sans-serif", "font.sans-serif": [name, "DejaVu Sans"]}


def _draw(rows, extra_points, path, panels, time_column, title, dpi, layout) -> Path:
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
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
                    label=_(series[0].get("label", method)), lw=1.2, ms=5)
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
                    label=_("Pareto front"))
            ax.scatter(ts, es, s=90, facecolors="none", edgecolors="black", lw=1, zorder=3)
        for point in extra_points:
            shown = _finite(point.get(time_column)) and _finite(point.get(column))
            if shown or point.get("legend_only"):
                # legend_only: an entry in the legend, nothing plotted (draw_with_point paints it).
                ax.scatter([point[time_column]] if shown else [], [point[column]] if shown else [],
                           marker="*", s=STAR_AREA, color=point.get("color", "gold"), edgecolors="black",
                           zorder=5, label=point.get("label", "submission"))
        ax.set_xscale("log")
        ax.set_yscale("log")
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_locator(LogLocator(base=10, numticks=8))
            axis.set_major_formatter(FuncFormatter(_plain_log_label))
            axis.set_minor_formatter(NullFormatter())
        ax.tick_params(labelsize=8)
        ax.set_xlabel(_("time per lookup, ns (%(order)s order, log)") % {"order": _(TIME_ORDERS.get(time_column, time_column.removeprefix("ns_")))},
                      fontsize=9)
        ax.set_ylabel(_(ERROR_LABELS[column]) if column in ERROR_LABELS else f"{column.replace('_', ' ')} error (log)",
                      fontsize=9)
        ax.set_title(_(panel_title), fontsize=10)
        ax.grid(True, which="major", alpha=0.3)
        ax.grid(True, which="minor", alpha=0.1)
    handles, labels = axes[0][0].get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    if len(unique) > 12:       # a class's points: keep the legend to the methods
        unique = {k: v for k, v in unique.items() if not any(k == p.get("label") for p in extra_points)}
    # Two legend columns per panel, so a one-panel chart keeps its legend inside the figure.
    columns = 2 * len(panels)
    fig.legend(unique.values(), unique.keys(), loc="lower center", ncol=columns, fontsize=8, frameon=False)
    fig.suptitle(title or _("Cube-map lookups: error against time (numbers: face size)"), fontsize=11)
    # Fixed margins, in inches turned into fractions: room for the tick
    # labels and axis labels, the title on top, the legend's rows below.
    legend_rows = -(-len(unique) // columns)
    bottom_in = 0.75 + 0.19 * legend_rows
    fig.subplots_adjust(left=0.85 / width, right=1 - 0.2 / width, top=1 - 0.65 / height,
                        bottom=min(0.55, bottom_in / height), wspace=0.25)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi, metadata={"Date": None} if path.suffix == ".svg" else None)
    if layout is not None:
        # Where each panel's axes are in the saved image (pixels, top row 0)
        # and their data limits, for draw_with_point.
        scale = dpi / fig.dpi
        h_px = round(height * dpi)
        for ax in axes[0]:
            x0, y0, x1, y1 = ax.get_window_extent().extents * scale
            layout.append({"box": [x0, h_px - y1, x1, h_px - y0], "xlim": list(ax.get_xlim()),
                           "ylim": list(ax.get_ylim())})
    return path


STAR_AREA = 160     # points^2, matplotlib's scatter size


def _star(cx: float, cy: float, radius: float) -> list[tuple[float, float]]:
    """A five-pointed star's polygon, point up (image y grows downwards)."""
    out = []
    for k in range(10):
        r = radius if k % 2 == 0 else radius * 0.38
        angle = math.pi / 2 - k * math.pi / 5
        out.append((cx + r * math.cos(angle), cy - r * math.sin(angle)))
    return out


def draw_with_point(rows: list[dict], point: dict, path: str | Path, cache_dir: str | Path,
                    panels=PANELS[:1], time_column: str = TIME_COLUMN, title: str | None = None,
                    dpi: int = 90) -> Path:
    """draw(rows, [point], path, ...) for one PNG with one point, cheaply:
    the chart without the point (its legend entry included) is drawn once
    and kept in cache_dir, keyed by everything it shows; the point is then
    painted on a copy (Pillow). A point outside the cached axes, or a cache
    that cannot be written, gets the full draw."""
    import hashlib
    import json
    import os
    import tempfile
    from importlib.metadata import version
    path = Path(path)
    label = point.get("label", "submission")
    key = hashlib.sha256(json.dumps([rows, [list(p) for p in panels], time_column, title, dpi, label, language(),
                                     version("matplotlib"), Path(__file__).read_bytes().hex()],
                                    sort_keys=True, default=str).encode()).hexdigest()[:24]
    cache = Path(cache_dir)
    background, layout_file = cache / f"chart-{key}.png", cache / f"chart-{key}.json"
    try:
        if not (background.is_file() and layout_file.is_file()):
            cache.mkdir(parents=True, exist_ok=True)
            layout: list[dict] = []
            with tempfile.TemporaryDirectory(dir=cache) as tmp:
                draw(rows, [{"label": label, "legend_only": True, "color": point.get("color", "gold"),
                             time_column: None}], Path(tmp) / "chart.png", panels=panels,
                     time_column=time_column, title=title, dpi=dpi, layout=layout)
                (Path(tmp) / "layout.json").write_text(json.dumps(layout))
                os.replace(Path(tmp) / "chart.png", background)        # atomic: another grader may race
                os.replace(Path(tmp) / "layout.json", layout_file)
        layout = json.loads(layout_file.read_text())
    except OSError:
        return draw(rows, [point], path, panels=panels, time_column=time_column, title=title, dpi=dpi)
    from PIL import Image, ImageDraw
    image = Image.open(background).convert("RGBA")
    paint = ImageDraw.Draw(image)
    radius = math.sqrt(STAR_AREA) / 2 / 72 * dpi * 1.15
    for (column, _), box in zip(panels, layout):
        if not (_finite(point.get(time_column)) and _finite(point.get(column))):
            continue
        (x0, x1), (y0, y1) = box["xlim"], box["ylim"]
        t, e = float(point[time_column]), float(point[column])
        if not (x0 <= t <= x1 and y0 <= e <= y1):
            return draw(rows, [point], path, panels=panels, time_column=time_column, title=title, dpi=dpi)
        left, top, right, bottom = box["box"]
        px = left + (math.log(t) - math.log(x0)) / (math.log(x1) - math.log(x0)) * (right - left)
        py = bottom - (math.log(e) - math.log(y0)) / (math.log(y1) - math.log(y0)) * (bottom - top)
        paint.polygon(_star(px, py, radius), fill=point.get("color", "gold"), outline="black")
    path.parent.mkdir(parents=True, exist_ok=True)
    image.convert("RGB").save(path)
    return path
