"""Where each lookup method fails: seams at the 12 cube edges and 8 corners,
exact ties, u or v exactly 0 and 1, and degenerate directions.

A seam jump is the largest change of the looked-up colour (max over R, G, B)
between two directions a relative SIDE_OFFSET apart on either side of an edge
(one on each face), over points all along the edge; at a corner, the largest
difference among the three faces' directions. The true environment is
continuous there, so any jump is the method's.

The grading checks use seam_jump(cube, "bilinear") as the handout method's
own seam on a given map: a submission whose seams stay within it is not
marked down for them.
"""
from __future__ import annotations

import itertools
from typing import Callable

import numpy as np

from ..envmap.geometry import FACE_NAMES

SIDE_OFFSET = 1e-9          # relative distance of the two sides from the edge
SAMPLES_PER_TEXEL = 8       # points along each edge, per texel of its length
# A method that is continuous across edges moves by about
# SIDE_OFFSET * face_size * (largest texel difference) between the two sides;
# SEAMLESS_TOLERANCE bounds that, relative to the largest texel value.
SEAMLESS_TOLERANCE = 1e-6


def _as_lookup(cube, method) -> Callable[[np.ndarray], np.ndarray]:
    """A lookup dirs -> rgb from a filter name over cube (faces or CubeMap), or a callable."""
    if callable(method):
        return method
    from ..envmap.library import CubeMap
    cube = cube if isinstance(cube, CubeMap) else CubeMap(np.asarray(cube))
    return lambda dirs: cube.fetch(dirs, method)


def _face_size(cube) -> int:
    return int(cube.face_width if hasattr(cube, "face_width") else np.asarray(cube).shape[2])


def _axis_face(axis: int, sign: int) -> str:
    return FACE_NAMES[2 * axis + (sign < 0)]


def cube_edges():
    """The 12 edges as (name, axis i, sign i, axis j, sign j, free axis k)."""
    out = []
    for i, j in ((0, 1), (0, 2), (1, 2)):
        k = 3 - i - j
        for si, sj in itertools.product((1, -1), repeat=2):
            out.append((f"{_axis_face(i, si)}/{_axis_face(j, sj)}", i, si, j, sj, k))
    return out


def cube_corners():
    """The 8 corners as (name, signs (sx, sy, sz))."""
    return [("".join("+" if s > 0 else "-" for s in signs), signs)
            for signs in itertools.product((1, -1), repeat=3)]


def _edge_points(edge, count: int, offset: float):
    """Directions (count, 3) on both sides of an edge and exactly on it."""
    _, i, si, j, sj, k = edge
    t = -1 + (np.arange(count) + 0.5) * 2 / count
    on = np.zeros((count, 3))
    on[:, i], on[:, j], on[:, k] = si, sj, t
    side_i, side_j = on.copy(), on.copy()
    side_i[:, j] *= 1 - offset        # |d_i| > |d_j|: the face of axis i
    side_j[:, i] *= 1 - offset        # the face of axis j
    return side_i, side_j, on


def seam_jump(cube, method="bilinear", offset: float = SIDE_OFFSET) -> dict[str, float]:
    """Largest colour jump across each of the 12 edges, {"+X/+Y": jump, ...}.
    `method` is a filter name of the reference ("nearest", "bilinear",
    "seamless") or a lookup callable dirs -> rgb; cube is faces (6, N, N, 3)
    or a grader.envmap.library.CubeMap."""
    lookup = _as_lookup(cube, method)
    count = SAMPLES_PER_TEXEL * _face_size(cube)
    out = {}
    for edge in cube_edges():
        side_i, side_j, _ = _edge_points(edge, count, offset)
        out[edge[0]] = float(np.max(np.abs(lookup(side_i) - lookup(side_j))))
    return out


def corner_jump(cube, method="bilinear", offset: float = SIDE_OFFSET) -> dict[str, float]:
    """Largest colour difference among the three faces at each of the 8 corners."""
    lookup = _as_lookup(cube, method)
    out = {}
    for name, signs in cube_corners():
        dirs = np.tile(np.array(signs, float), (3, 1))
        for axis in range(3):              # row `axis`: the face of that axis wins
            for other in range(3):
                if other != axis:
                    dirs[axis, other] *= 1 - offset
        rgb = lookup(dirs)
        out[name] = float(max(np.max(np.abs(rgb[a] - rgb[b])) for a, b in ((0, 1), (0, 2), (1, 2))))
    return out


def tie_behaviour(cube, method="bilinear") -> dict:
    """At directions exactly on an edge (two equal components), which side's
    value does the method return? The contract accepts either face; the
    reference takes the first axis in x, y, z order. Returns the share of
    edge points equal to the first-axis side, to the other side, to neither
    (e.g. a blend or black), and whether any output is not finite."""
    lookup = _as_lookup(cube, method)
    count = 2 * _face_size(cube)
    first = other = neither = 0
    finite = True
    for edge in cube_edges():
        side_i, side_j, on = _edge_points(edge, count, SIDE_OFFSET)
        a, b, tie = lookup(side_i), lookup(side_j), lookup(on)
        finite &= bool(np.isfinite(tie).all())
        scale = SEAMLESS_TOLERANCE * max(1.0, float(np.abs(a).max()))
        near_a = np.abs(tie - a).max(axis=1) <= scale
        near_b = np.abs(tie - b).max(axis=1) <= scale
        first += int(near_a.sum())            # i < j: side_i is the first axis
        other += int((near_b & ~near_a).sum())
        neither += int((~near_a & ~near_b).sum())
    total = first + other + neither
    return {"first_axis": first / total, "other_face": other / total,
            "neither": neither / total, "finite": finite}


def boundary_uv_behaviour(cube, filter_name: str) -> dict:
    """read_texture at u or v exactly 0 and 1 (reference filters only): the
    largest difference from the limit 1e-12 inside, and whether u = 1 and
    v = 1 read the last column/row (not past it)."""
    from ..envmap.library import CubeMap
    cube = cube if isinstance(cube, CubeMap) else CubeMap(np.asarray(cube))
    size = cube.face_width
    t = (np.arange(4 * size) + 0.5) / (4 * size)
    jump = 0.0
    for face in range(6):
        for edge_value, inside in ((0.0, 1e-12), (1.0, 1 - 1e-12)):
            for axis in (0, 1):
                uv_edge = np.stack([t, t], 1)
                uv_edge[:, axis] = edge_value
                uv_in = uv_edge.copy()
                uv_in[:, axis] = inside
                diff = cube.read_texture(np.full(len(t), face), uv_edge, filter_name) \
                    - cube.read_texture(np.full(len(t), face), uv_in, filter_name)
                jump = max(jump, float(np.abs(diff).max()))
    corner = cube.read_texture(np.array([0]), np.array([[1.0, 1.0]]), filter_name)[0]
    return {"max_jump_at_0_or_1": jump,
            "u1_v1_is_last_texel": bool(np.allclose(corner, cube.faces[0, -1, -1]))}


DEGENERATE_DIRECTIONS = {
    "zero": (0.0, 0.0, 0.0),
    "negative zero": (-0.0, -0.0, -0.0),
    "NaN": (np.nan, 0.5, 0.5),
    "+inf": (np.inf, 0.0, 0.0),
    "inf, inf": (np.inf, np.inf, 0.0),
    "denormal": (5e-324, 1e-324 * 0, 0.0),
    "denormal, all tied": (4e-320, 4e-320, 4e-320),
    "huge (1e308, 1e308, 1)": (1e308, 1e308, 1.0),
    "tiny generic": (3e-310, -2e-310, 1e-310),
}
# The direction each finite degenerate input means, to compare against.
_MEANING = {"denormal": (1.0, 0.0, 0.0), "denormal, all tied": (1.0, 1.0, 1.0),
            "huge (1e308, 1e308, 1)": (1.0, 1.0, 1e-308), "tiny generic": (3.0, -2.0, 1.0)}


def degenerate_behaviour(cube, method="bilinear") -> dict[str, str]:
    """What a method returns for zero, NaN, infinite, denormal and huge
    directions: "black", "NaN", "colour" (for inputs with no direction), or
    "as normalised" / "differs" (for finite ones, against the same method at
    the direction the input means)."""
    lookup = _as_lookup(cube, method)
    out = {}
    for name, d in DEGENERATE_DIRECTIONS.items():
        try:
            rgb = np.asarray(lookup(np.array([d], float)), float)[0]
        except Exception as exc:          # a method may refuse; that is its behaviour
            out[name] = f"error ({type(exc).__name__})"
            continue
        if not np.isfinite(rgb).all():
            out[name] = "NaN"
        elif name in _MEANING:
            expect = np.asarray(lookup(np.array([_MEANING[name]], float)), float)[0]
            out[name] = "as normalised" if np.allclose(rgb, expect, rtol=1e-6, atol=1e-9) else "differs"
        else:
            out[name] = "black" if not rgb.any() else "colour"
    return out


def failure_table(cube, methods: dict[str, object]) -> list[dict]:
    """One row per method: every edge and corner jump, the worst of each, the
    tie behaviour, and the degenerate-direction outcomes. `methods` maps a
    name to a filter name or a lookup callable."""
    rows = []
    for name, method in methods.items():
        edges = seam_jump(cube, method)
        corners = corner_jump(cube, method)
        row = {"method": name, "max_edge_jump": max(edges.values()),
               "max_corner_jump": max(corners.values())}
        row.update({f"edge {k}": v for k, v in edges.items()})
        row.update({f"corner {k}": v for k, v in corners.items()})
        ties = tie_behaviour(cube, method)
        row["ties"] = (f"first axis {ties['first_axis']:.0%}, other face {ties['other_face']:.0%}, "
                       f"neither {ties['neither']:.0%}" + ("" if ties["finite"] else ", NOT FINITE"))
        if isinstance(method, str):
            uv = boundary_uv_behaviour(cube, method)
            row["u,v = 0 or 1"] = (f"jump {uv['max_jump_at_0_or_1']:.2g}; u=v=1 reads "
                                   + ("the last texel" if uv["u1_v1_is_last_texel"] else "a blend"))
        else:
            row["u,v = 0 or 1"] = "n/a (directions only)"
        row.update({f"dir {k}": v for k, v in degenerate_behaviour(cube, method).items()})
        rows.append(row)
    return rows


def draw_failure_map(rows: list[dict], path, title: str = "") -> None:
    """A heat map: methods x (12 edges, 8 corners), log colour of the jump."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    columns = [k for k in rows[0] if k.startswith(("edge ", "corner "))]
    data = np.array([[max(r[c], 1e-12) for c in columns] for r in rows])
    plt.rcParams["svg.hashsalt"] = "grader-study"
    fig, ax = plt.subplots(figsize=(13, 1.2 + 0.55 * len(rows)))
    image = ax.imshow(data, norm=LogNorm(vmin=1e-9, vmax=max(1.0, data.max())), cmap="magma_r",
                      aspect="auto")
    ax.set_xticks(range(len(columns)), [c.split(" ", 1)[1] for c in columns], rotation=60, fontsize=8)
    ax.set_yticks(range(len(rows)), [r["method"] for r in rows], fontsize=9)
    ax.axvline(11.5, color="black", lw=1)
    for y, row in enumerate(data):
        for x, value in enumerate(row):
            ax.text(x, y, f"{value:.0e}" if value > 1e-11 else "0", ha="center", va="center",
                    fontsize=5.5, color="white" if value > 1e-3 else "black")
    fig.colorbar(image, ax=ax, label="largest colour jump")
    ax.set_title(title or "Seams: colour jump across the 12 edges (left) and 8 corners (right)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=130, metadata={"Date": None} if str(path).endswith(".svg") else None)
    plt.close(fig)
