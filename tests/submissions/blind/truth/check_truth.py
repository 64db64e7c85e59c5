"""Check each blind submission's TRUTH (its header) numerically, before grading.

Each .cpp in tests/submissions/blind/ is compiled with the template's header and
harness.cc (attachFaces, a recording subclass, C entry points; no grader code) and
compared, on random faces of several sizes in one process, with (1) the independent
model tests/helpers/assignment_model.py (the handout) and (2) the truth restated below
in numpy from the header's words. Prints, per file, how often the code differs from the
handout and whether it is exactly the restated truth.

    PYTHONPATH=tests/helpers .venv/bin/python tests/submissions/blind/truth/check_truth.py
"""
from __future__ import annotations

import ctypes
import subprocess
import sys
from pathlib import Path

import numpy as np

import assignment_model as model

HERE = Path(__file__).resolve().parent
BLIND = HERE.parent
ROOT = BLIND.parents[2]
OUT = Path("/tmp/blind-truth")
SIZES = ((16, 9), (8, 8), (6, 5))     # in this order, in one process, each in its own buffer
# (the later faces are smaller, so a file that keeps the first buffer reads inside it)
rng = np.random.default_rng(29)
D = ctypes.POINTER(ctypes.c_double)


def directions():
    n = 4000
    i = np.arange(n) + 0.5
    phi, z = np.pi * (1 + 5 ** 0.5) * i, 1 - 2 * i / n
    r = np.sqrt(1 - z * z)
    sphere = np.stack([r * np.cos(phi), r * np.sin(phi), z], 1)
    edges = []
    for a in range(3):
        for sa in (1, -1):
            for b in range(3):
                if b == a:
                    continue
                for sb in (1, -1):
                    for t in np.linspace(-1, 1, 9):
                        d = np.zeros(3); d[a] = sa; d[b] = sb; d[3 - a - b] = t
                        edges.append(d)
    axes = np.concatenate([np.eye(3), -np.eye(3)])
    lengths = sphere[:300] * np.logspace(-30, 30, 300)[:, None]
    return np.concatenate([sphere, np.array(edges), axes, lengths])


DIRS = directions()


def handout_request(dirs):
    """The table's request: the first touching face in x, y, z order, and the model's (u, v)."""
    faces = np.argmax(model.touching_faces(dirs), axis=1)
    u, v = model.face_uv(dirs, faces)
    return faces, u, v


def texels(flat, base, W, x, y):
    """Texel (x, y) of the face starting at float `base` of `flat`, row 0 at the bottom."""
    i = base + 3 * (y * W + x)
    return np.stack([flat[i], flat[i + 1], flat[i + 2]], 1).astype(np.float64)


def bilinear(flat, base, W, H, u, v, *, lattice=np.floor, edge="clamp", rows_top_down=False):
    """The handout's blend, with the variations the blind files make."""
    px, py = u * W, v * H
    lx, ly = lattice(px), lattice(py)
    a, b = (px - lx)[:, None], (py - ly)[:, None]
    if edge == "clamp":
        x0, x1 = np.clip(lx, 0, W - 1), np.clip(lx + 1, 0, W - 1)
        y0, y1 = np.clip(ly, 0, H - 1), np.clip(ly + 1, 0, H - 1)
    else:                                        # repeat: mod W, mod H
        x0, y0 = np.mod(lx, W), np.mod(ly, H)
        x1, y1 = np.mod(x0 + 1, W), np.mod(y0 + 1, H)
    x0, x1, y0, y1 = (q.astype(np.intp) for q in (x0, x1, y0, y1))
    if rows_top_down:
        y0, y1 = H - 1 - y0, H - 1 - y1
    t = lambda x, y: texels(flat, base, W, x, y)
    return (1 - b) * ((1 - a) * t(x0, y0) + a * t(x1, y0)) + b * ((1 - a) * t(x0, y1) + a * t(x1, y1))


def box3(flat, base, W, H, u, v):
    xc = np.clip(np.trunc(u * W), 0, W - 1).astype(np.intp)
    yc = np.clip(np.trunc(v * H), 0, H - 1).astype(np.intp)
    s = 0
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            s = s + texels(flat, base, W, np.clip(xc + dx, 0, W - 1), np.clip(yc + dy, 0, H - 1))
    return s / 9


def rounded(flat, base, W, H, u, v):
    # C's round: halves away from zero (p >= 0 here).
    return bilinear(flat, base, W, H, u, v, lattice=lambda p: np.floor(p + 0.5))


# ---- each file's truth: (what fetchColor asks, what readTexture does) --------------------

def ask_table(dirs, W, H, k):
    return handout_request(dirs)


def ask_flip(face_name, what):
    def ask(dirs, W, H, k):
        f, u, v = handout_request(dirs)
        on = f == model.FACE_NAMES.index(face_name) if face_name != "all" else np.ones(len(f), bool)
        if what == "u":
            u = np.where(on, 1 - u, u)
        else:
            v = np.where(on, 1 - v, v)
        return f, u, v
    return ask


def read_handout(flat, base, W, H, u, v):
    return bilinear(flat, base, W, H, u, v)


TRUTH = {
    # name: (fetchColor's request, readTexture, calls per answered direction, note)
    "correct_sign-mask-switch_twice-averaged": (ask_table, read_handout, 2),
    "correct_rotation-matrices_memoised-geometry": (ask_table, read_handout, 1),
    "correct_lambda-array_reads-texels-itself": (ask_table, read_handout, 0),
    "lattice-rounded-not-floored_early-returns": (ask_table, rounded, 1),
    "box-3x3-around-nearest_face-templates": (ask_table, box3, 1),
    "repeat-both-axes-at-p_axis-switch": (ask_table, lambda *a: bilinear(*a, edge="repeat"), 1),
    "face-addresses-cached-in-static_if-chain": (ask_table, read_handout, 1),
    "opengl-table-converted-neg-x-u-sign_sc-tc": (ask_flip("-X", "u"), read_handout, 1),
    "v-flipped-every-face_rows-top-down_member-pointers": (ask_flip("all", "v"), lambda *a: bilinear(*a, rows_top_down=True), 1),
    "hostile_recorded-by-own-blend_v-flipped-pos-z": (ask_table, read_handout, 1),   # when recorded
    "hostile_control_v-flipped-pos-z": (ask_flip("+Z", "v"), read_handout, 1),
}
# What the code does end to end where that differs from its recorded request.
END_TO_END = {"hostile_recorded-by-own-blend_v-flipped-pos-z": ask_flip("+Z", "v")}


def build(name: str) -> ctypes.CDLL:
    OUT.mkdir(exist_ok=True)
    lib = OUT / f"{name}.so"
    subprocess.run(["g++", "-std=c++17", "-O2", "-shared", "-fPIC", f"-I{ROOT / 'student_template'}",
                    str(BLIND / f"{name}.cpp"), str(HERE / "harness.cc"), "-o", str(lib)], check=True)
    so = ctypes.CDLL(str(lib))
    so.h_new.restype = ctypes.c_void_p
    for f in ("h_attach", "h_fetch", "h_record", "h_read"):
        getattr(so, f).restype = None
    return so


def ptr(a):
    return a.ctypes.data_as(ctypes.c_void_p)


def check(name: str) -> list[str]:
    so = build(name)
    ask, read, calls_per = TRUTH[name]
    e2e = END_TO_END.get(name, ask)
    plain, rec = so.h_new(0), so.h_new(1)
    lines, keep, first = [], [], None
    for k, (W, H) in enumerate(SIZES):
        cube = rng.random((6, H, W, 3), dtype=np.float32) * 4
        flat = np.ascontiguousarray(cube).reshape(-1)
        keep.append(flat)                       # every buffer outlives the process's maps
        first = first or (flat, W, H)
        for m in (plain, rec):
            so.h_attach(ctypes.c_void_p(m), ptr(flat), W, H)
        dirs = np.ascontiguousarray(DIRS)
        n = len(dirs)
        # end to end
        got = np.zeros((n, 3))
        so.h_fetch(ctypes.c_void_p(plain), ptr(dirs), n, ptr(got))
        colours, touched = model.fetch_touching(cube, dirs)
        right = np.zeros(n, bool)
        for f in range(6):
            right |= touched[:, f] & np.isclose(got, colours[:, f], rtol=1e-9, atol=1e-12).all(1)
        f_, u_, v_ = e2e(dirs, W, H, k)
        if name.startswith("face-addresses") and k > 0:
            # the first call's buffer, its face starts at the first size, read with this size
            src, W0, H0 = first
            want = read(src, f_ * 3 * W0 * H0, W, H, u_, v_)
        else:
            want = read(flat, f_ * 3 * W * H, W, H, u_, v_)
        valid = touched.any(1)
        truth_ok = np.isclose(got[valid], want[valid], rtol=1e-9, atol=1e-12).all(1)
        # the record
        r = np.zeros((n, 5))
        so.h_record(ctypes.c_void_p(rec), ptr(dirs), n, ptr(r))
        rf, ru, rv = ask(dirs, W, H, k)
        asked = r[valid]
        rec_ok = ((asked[:, 0] == calls_per) & ((calls_per == 0) | ((asked[:, 1] == rf[valid])
                  & np.isclose(asked[:, 2], ru[valid], rtol=0, atol=1e-15) & np.isclose(asked[:, 3], rv[valid], rtol=0, atol=1e-15)
                  & (asked[:, 4] == 1))))
        hf, hu, hv = handout_request(dirs)
        if name.startswith("face-addresses") and k > 0:
            # the first buffer's face starts: not a face start of this map (the harness says -2) or another face
            rec_ok = (asked[:, 0] == 1) & (asked[:, 1] != hf[valid]) & np.isclose(asked[:, 2], hu[valid], atol=1e-15) \
                & np.isclose(asked[:, 3], hv[valid], atol=1e-15)
        rec_handout = (asked[:, 1] == hf[valid]) & np.isclose(asked[:, 2], hu[valid], atol=1e-15) & np.isclose(asked[:, 3], hv[valid], atol=1e-15)
        # readTexture alone
        uv = np.concatenate([rng.random((3000, 2)), np.stack(np.meshgrid(np.arange(W + 1) / W, np.arange(H + 1) / H), -1).reshape(-1, 2),
                             np.array([[1, 1], [1 - 2 ** -30, 1 - 2 ** -30], [0, 0], [1, 0], [0, 1]])])
        uv = np.ascontiguousarray(uv)
        face = 2
        rt = np.zeros((len(uv), 3))
        so.h_read(ctypes.c_void_p(plain), face, ptr(uv), len(uv), ptr(rt))
        rt_model = model.read_texture(cube, face, uv[:, 0], uv[:, 1])
        rt_truth = read(flat, face * 3 * W * H, W, H, uv[:, 0], uv[:, 1])
        rt_is_handout = np.isclose(rt, rt_model, rtol=1e-9, atol=1e-12).all(1)
        rt_is_truth = np.isclose(rt, rt_truth, rtol=1e-9, atol=1e-12).all(1)
        if name.startswith("v-flipped-every-face"):
            # the header's claim: end to end, the handout's blend one texel lower (v - 1/H), away from the
            # bottom and top rows and from whole vH
            lower = np.zeros((n, 3))
            for f in range(6):
                rows = hf == f
                lower[rows] = model.read_texture(cube, f, hu[rows], hv[rows] - 1 / H)
            py = hv * H
            inner = valid & (py > 1) & (py < H - 1) & (py != np.floor(py))
            one_lower = np.isclose(got[inner], lower[inner], rtol=1e-9, atol=1e-12).all(1)
            lines.append(f"  {W}x{H}: one texel lower: {one_lower.mean():7.2%} of {inner.sum()} directions with 1 < vH < H - 1")
        lines.append(f"  {W}x{H}: end to end = handout {right[valid].mean():7.2%}, = truth {truth_ok.mean():7.2%};"
                     f" record = truth {rec_ok.mean():7.2%} (= table {rec_handout.mean():7.2%});"
                     f" readTexture = handout {rt_is_handout.mean():7.2%}, = truth {rt_is_truth.mean():7.2%}")
    return lines


if __name__ == "__main__":
    names = sys.argv[1:] or sorted(TRUTH)
    assert set(TRUTH) == {p.stem for p in BLIND.glob("*.cpp")}
    for name in names:
        print(name)
        print("\n".join(check(name)))
