"""The handout's lost figures, and previews of the generated maps, drawn with matplotlib.

- cross_layout.png: the vertical cross with the face names, each face's u
  and v arrows, and the cube folded up in 3D with its axes (the handout's
  figure 3);
- face_uv.png: each face as seen from the centre of the cube, its (u, v)
  arrows in 3D terms and the direction of each corner (docs/assignment.md's table);
- test_environment_map.png: the test map as a cross, a lat-long view and a
  mirror sphere;
- generated_maps.png: the other generated maps, as crosses and lat-long views.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .. import PROJECT_ROOT  # noqa: E402
from ..envmap import library
from ..envmap.imaging import tone_map  # noqa: E402
from .convert import faces_to_latlong  # noqa: E402
from ..envmap.geometry import FACE_NAMES, cross_cells, face_frames, face_uv_formulas, face_uv_to_direction  # noqa: E402

FIGURES_DIR = PROJECT_ROOT / "docs" / "figures"
CUBEMAP_DIR = PROJECT_ROOT / "Cubemap"

# (column, row) of each face's cell in the vertical cross, row 0 at the top
# (docs/assignment.md), as reference/src/cross.c lays it out.
CROSS_CELLS = cross_cells()
AXIS_COLOURS = {"x": "#d62728", "y": "#2ca02c", "z": "#1f5fd6"}
FACE_FILL = "#f2f2f2"


def _axis_label(vector: np.ndarray) -> str:
    """'+x', '-z', ... for a unit axis vector."""
    i = int(np.argmax(np.abs(vector)))
    return ("+" if vector[i] > 0 else "-") + "xyz"[i]


def _face_axes(face: int) -> tuple[np.ndarray, np.ndarray]:
    """The 3D directions in which u and v grow on a face."""
    _, u_axis, v_axis = face_frames()
    return u_axis[face], v_axis[face]


def _colour_of(label: str) -> str:
    return AXIS_COLOURS[label[1]]


def _draw_uv_arrows(ax, x0: float, y0: float, size: float, face: int) -> None:
    """u and v arrows from the bottom-left corner of a face drawn at (x0, y0) (y up)."""
    du, dv = _face_axes(face)
    start = np.array([x0 + 0.1 * size, y0 + 0.1 * size])
    length = 0.33 * size
    for label, vec, step in (("u", du, (length, 0.0)), ("v", dv, (0.0, length))):
        axis = _axis_label(vec)
        tip = start + np.array(step)
        ax.annotate("", xy=tip, xytext=start, arrowprops=dict(arrowstyle="-|>", lw=2, color=_colour_of(axis)))
        if label == "u":
            ax.text(tip[0] + 0.03 * size, tip[1], f"u: {axis}", fontsize=10, color=_colour_of(axis),
                    ha="left", va="center")
        else:
            ax.text(tip[0] - 0.02 * size, tip[1] + 0.03 * size, f"v: {axis}", fontsize=10,
                    color=_colour_of(axis), ha="left", va="bottom")


def cross_layout(path: Path) -> None:
    fig = plt.figure(figsize=(11.5, 6.4))
    ax = fig.add_axes([0.01, 0.02, 0.52, 0.9])
    for name, (col, row) in CROSS_CELLS.items():
        face = FACE_NAMES.index(name)
        x0, y0 = col, 3 - row                       # matplotlib y grows upwards
        ax.add_patch(plt.Rectangle((x0, y0), 1, 1, facecolor=FACE_FILL, edgecolor="black", lw=1.5))
        ax.text(x0 + 0.68, y0 + 0.7, name, ha="center", va="center", fontsize=20, weight="bold")
        _draw_uv_arrows(ax, x0, y0, 1.0, face)
    ax.text(0.04, 3.96, "Vertical cross,\nrow 0 at the top\nof the file.\n\nIn every cell u grows\n"
            "right and v up:\nfaces are copied\nwithout rotation.", ha="left", va="top", fontsize=9)
    ax.text(2.06, 0.96, "+Z sits upside down\nin the cross: its\nbottom row looks\ntowards +y.",
            ha="left", va="top", fontsize=9)
    ax.set_xlim(-0.02, 3.02)
    ax.set_ylim(-0.02, 4.02)
    ax.set_aspect("equal")
    ax.axis("off")

    ax3 = fig.add_axes([0.52, 0.02, 0.47, 0.9])
    _draw_cube(ax3)
    fig.suptitle("Cube-map faces: the vertical cross and the cube it folds into "
                 "(right-handed, y up, -z is the front face)", fontsize=11)
    fig.savefig(path, dpi=110)
    plt.close(fig)


# Where the names of the faces at the back of the cube are written (screen units).
HIDDEN_LABEL_AT = {"-X": (-2.1, 0.3), "-Y": (0.0, -2.3), "-Z": (1.7, 2.0)}


def _draw_cube(ax) -> None:
    """The cube [-1, 1]^3 seen from outside (orthographic, from +x +y +z), face names and axes."""
    towards_camera = np.array([1.1, 0.8, 2.0])
    towards_camera /= np.linalg.norm(towards_camera)
    right = np.cross([0.0, 1.0, 0.0], towards_camera)
    right /= np.linalg.norm(right)
    up = np.cross(towards_camera, right)

    def screen(p):
        p = np.atleast_2d(p)
        return p @ right, p @ up

    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    hidden_corner = -np.sign(towards_camera)           # the corner at the back
    for i, a in enumerate(corners):
        for b in corners[i + 1:]:
            if np.sum(a != b) == 1:
                hidden = np.any(np.all(np.isclose([a, b], hidden_corner), axis=1))
                ax.plot(*screen([a, b]), color="grey", lw=1, ls=":" if hidden else "-")
    for face, name in enumerate(FACE_NAMES):
        c = face_uv_to_direction(face, 0.5, 0.5)
        c = c / np.max(np.abs(c))
        (x,), (y,) = screen(c)
        if c @ towards_camera > 0:
            # Off the face centre (towards +v), clear of the axis through it.
            (x,), (y,) = screen(c + 0.5 * _face_axes(face)[1])
            ax.text(x, y, name, fontsize=14, weight="bold", ha="center", va="center")
        else:
            ax.annotate(f"{name} (behind)", xy=(x, y), xytext=HIDDEN_LABEL_AT[name],
                        fontsize=10, color="dimgrey", ha="center", va="center",
                        arrowprops=dict(arrowstyle="-", color="lightgrey", lw=1))
    for axis, name in enumerate("xyz"):
        end = np.zeros(3)
        end[axis] = 2.0
        (x0, y0), (x1, y1) = np.concatenate(screen(np.zeros(3))), np.concatenate(screen(end))
        ax.annotate("", xy=(x1, y1), xytext=(x0, y0),
                    arrowprops=dict(arrowstyle="-|>", lw=2.5, color=AXIS_COLOURS[name]))
        ax.text(x1 * 1.1, y1 * 1.1, name, color=AXIS_COLOURS[name], fontsize=15, weight="bold",
                ha="center", va="center")
    ax.set_xlim(-2.6, 2.6)
    ax.set_ylim(-2.6, 2.6)
    ax.set_aspect("equal")
    ax.axis("off")
    ax.set_title("The cube seen from outside (+x, +y, +z towards you)", fontsize=10)


# The handout's table, as text for the panels: worded from the reference's frames.
UV_FORMULAS = face_uv_formulas()


def _corner_text(d: np.ndarray) -> str:
    d = np.round(d / np.max(np.abs(d)))
    return "(" + ", ".join(f"{c:+.0f}" if c else "0" for c in d) + ")"


def face_uv(path: Path) -> None:
    fig, axes = plt.subplots(2, 3, figsize=(11, 7.6))
    for ax, name in zip(axes.ravel(), ("+X", "-X", "+Y", "-Y", "+Z", "-Z")):
        face = FACE_NAMES.index(name)
        ax.add_patch(plt.Rectangle((0, 0), 1, 1, facecolor=FACE_FILL, edgecolor="black", lw=1.5))
        _draw_uv_arrows(ax, 0.0, 0.0, 1.0, face)
        for u, v in ((0, 0), (1, 0), (0, 1), (1, 1)):
            ax.text(u, v + (0.03 if v else -0.03), f"(u,v)=({u},{v})\n{_corner_text(face_uv_to_direction(face, u, v))}",
                    ha="left" if u == 0 else "right", va="bottom" if v else "top", fontsize=8)
        ax.text(0.5, 0.55, name, ha="center", va="center", fontsize=22, weight="bold")
        centre = _corner_text(face_uv_to_direction(face, 0.5, 0.5))
        ax.text(0.5, 0.42, f"centre {centre}", ha="center", va="center", fontsize=8.5)
        fu, fv = UV_FORMULAS[name]
        ax.set_title(f"{name}:  u = {fu},  v = {fv}", fontsize=10)
        ax.set_xlim(-0.08, 1.08)
        ax.set_ylim(-0.22, 1.22)
        ax.set_aspect("equal")
        ax.axis("off")
    fig.suptitle("Each face as stored (x right, y up, y = 0 the bottom row) and as seen from the "
                 "cube's centre;\ncorner labels are the direction (x, y, z) through that corner; "
                 "m = |major component|", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def mirror_sphere(faces: np.ndarray, size: int = 320) -> np.ndarray:
    """A mirror sphere seen from far along +z (orthographic), looked up with the reference."""
    a, b = np.meshgrid((np.arange(size) + 0.5) / size * 2 - 1, 1 - (np.arange(size) + 0.5) / size * 2)
    inside = a * a + b * b < 1
    nz = np.sqrt(np.clip(1 - a * a - b * b, 0, 1))
    normal = np.stack([a, b, nz], axis=-1)
    reflected = np.array([0.0, 0.0, -1.0]) + 2 * nz[..., None] * normal
    rgb = library.CubeMap(faces).fetch(reflected.reshape(-1, 3)).reshape(size, size, 3)
    return np.where(inside[..., None], rgb, 1.0).astype(np.float32)


def test_environment_map(path: Path, map_path: Path) -> None:
    cross = library.read_hdr(map_path)
    faces = library.cross_to_faces(cross)
    fig = plt.figure(figsize=(12, 7.2))
    ax = fig.add_axes([0.01, 0.02, 0.37, 0.9])
    ax.imshow(tone_map(np.where(cross > 0, cross, 1.0)))
    for name, (col, row) in CROSS_CELLS.items():
        n = faces.shape[1]
        ax.text(col * n + 6, row * n + 6, name, color="white", fontsize=11, weight="bold", va="top")
    ax.set_title("As stored: the vertical cross")
    ax.axis("off")

    ax = fig.add_axes([0.4, 0.45, 0.58, 0.48])
    ax.imshow(tone_map(faces_to_latlong(faces, 1024)), extent=(-180, 180, -90, 90))
    for label, lon, lat in (("-z", 0, 0), ("+x", 90, 0), ("-x", -90, 0), ("+z", 180, 0),
                            ("+z", -180, 0), ("+y", 0, 86), ("-y", 0, -86)):
        ax.text(lon, lat, label, color="white", fontsize=9, ha="center", va="center",
                bbox=dict(facecolor="black", alpha=0.4, pad=1, lw=0))
    ax.set_xticks(range(-180, 181, 90))
    ax.set_yticks(range(-90, 91, 45))
    ax.set_title("Lat-long view from the centre (longitude 0 looks along -z, +x at +90)", fontsize=10)

    ax = fig.add_axes([0.42, 0.02, 0.34, 0.38])
    ax.imshow(tone_map(mirror_sphere(faces)))
    ax.set_title("A mirror sphere seen from +z", fontsize=10)
    ax.axis("off")
    fig.text(0.76, 0.36, "On the mirror sphere (the centre\nreflects +z back to the viewer):\n"
             "red points right (+x),\ngreen points up (+y),\nblue points at you (+z): its head\n"
             "ends on the disc in the centre.\n\nDiscs mark +x, +y, +z;\nrings mark -x, -y, -z.\n"
             "Each arrow carries a flag on its\nleft as seen in a mirror (on its\nright seen directly), "
             "and a dashed\nline back to its ring.", fontsize=9, va="top")
    fig.savefig(path, dpi=100)
    plt.close(fig)


GENERATED_PREVIEWS = (("sky_cross.hdr", -4.0, "Preetham clear sky, sun 35 deg up (exposure -4)"),
                      ("interior_cross.hdr", 0.0, "Interior with rectangular lights"),
                      ("grid_room_cross.hdr", 0.0, "Checker room (turned 20 deg)"))


def generated_maps(path: Path, cubemap_dir: Path) -> None:
    fig, axes = plt.subplots(2, 3, figsize=(13, 8.4), gridspec_kw=dict(height_ratios=[2, 1]))
    for column, (name, exposure, title) in enumerate(GENERATED_PREVIEWS):
        cross = library.read_hdr(cubemap_dir / name)
        faces = library.cross_to_faces(cross)
        axes[0, column].imshow(tone_map(np.where(cross > 0, cross, 2.0 ** -exposure), exposure))
        axes[0, column].set_title(f"{name}\n{title}", fontsize=10)
        axes[1, column].imshow(tone_map(faces_to_latlong(faces, 768), exposure))
        axes[1, column].set_title("lat-long view", fontsize=9)
        for ax in axes[:, column]:
            ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def draw_all(out_dir: Path = FIGURES_DIR, cubemap_dir: Path = CUBEMAP_DIR) -> list[Path]:
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = {name: out_dir / name for name in
             ("cross_layout.png", "face_uv.png", "test_environment_map.png", "generated_maps.png")}
    cross_layout(paths["cross_layout.png"])
    face_uv(paths["face_uv.png"])
    test_environment_map(paths["test_environment_map.png"], cubemap_dir / "test_environment_map.hdr")
    generated_maps(paths["generated_maps.png"], cubemap_dir)
    return list(paths.values())
