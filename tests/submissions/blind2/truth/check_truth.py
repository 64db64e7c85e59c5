"""Check each blind2 submission's TRUTH (its header) numerically, before grading.

Adapted from tests/submissions/blind/truth/check_truth.py (and its harness.cc, used as
it is: attachFaces, a recording subclass, C entry points; no grader code). Each .cpp in
tests/submissions/blind2/ is compiled with the template's header and that harness and
compared, on random faces of several sizes in one process, with (1) the independent
model tests/helpers/assignment_model.py (the handout) and (2) the truth restated below
in numpy from the header's words. Prints, per file and size, how often the code is the
handout and whether it is exactly the restated truth, end to end, in its recorded
readTexture calls and in readTexture alone; then, per face of the table, how many
recorded calls differ from the table (where a fetchColor mistake shows), and the
header's narrower claims (CLAIMS below).

    PYTHONPATH=tests/helpers .venv/bin/python tests/submissions/blind2/truth/check_truth.py [NAME ...]
"""
from __future__ import annotations

import ctypes
import subprocess
import sys
from pathlib import Path

import numpy as np

import assignment_model as model

HERE = Path(__file__).resolve().parent
BLIND2 = HERE.parent
ROOT = BLIND2.parents[2]
HARNESS = BLIND2.parent / "blind" / "truth" / "harness.cc"
OUT = Path("/tmp/blind2-truth")
SIZES = ((16, 9), (8, 8), (6, 5))
rng = np.random.default_rng(2911)
np.seterr(invalid="ignore", over="ignore", divide="ignore")   # the degenerate directions' NaN (u, v), never compared


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
    # near the borders: one in-face component at +-(1 - k 2^-20) of the major, the other random
    near = []
    for a in range(3):
        for sa in (1, -1):
            for b in range(3):
                if b == a:
                    continue
                for sb in (1, -1):
                    for k in (1, 7, 300):
                        d = np.zeros(3); d[a] = sa; d[b] = sb * (1 - k * 2.0 ** -20); d[3 - a - b] = rng.uniform(-0.9, 0.9)
                        near.append(d)
    inf, nan = np.inf, np.nan
    degenerate = np.array([[0, 0, 0], [nan, 1, 0], [0, nan, 0], [1, 0, nan], [inf, 0, 0], [0, -inf, 1], [1, 2, inf],
                           [-0.0, 0, 0], [nan, nan, nan]])
    return np.concatenate([sphere, np.array(edges), axes, lengths, np.array(near), degenerate])


DIRS = directions()


def handout_request(dirs):
    """The table's request: the first touching face in x, y, z order, and the model's (u, v)."""
    faces = np.argmax(model.touching_faces(dirs), axis=1)
    u, v = model.face_uv(dirs, faces)
    return faces, u, v


def texels(flat, base, W, x, y):
    i = base + 3 * (y * W + x)
    return np.stack([flat[i], flat[i + 1], flat[i + 2]], 1).astype(np.float64)


def corners(W, H, px, py, lattice):
    lx, ly = lattice(px), lattice(py)
    a, b = (px - lx)[:, None], (py - ly)[:, None]
    x0, x1 = np.clip(lx, 0, W - 1), np.clip(lx + 1, 0, W - 1)
    y0, y1 = np.clip(ly, 0, H - 1), np.clip(ly + 1, 0, H - 1)
    return a, b, *(q.astype(np.intp) for q in (x0, x1, y0, y1))


def bilinear(flat, base, W, H, u, v, *, lattice=np.floor):
    a, b, x0, x1, y0, y1 = corners(W, H, u * W, v * H, lattice)
    t = lambda x, y: texels(flat, base, W, x, y)
    return (1 - b) * ((1 - a) * t(x0, y0) + a * t(x1, y0)) + b * ((1 - a) * t(x0, y1) + a * t(x1, y1))


def read_handout(flat, base, W, H, u, v):
    return bilinear(flat, base, W, H, u, v)


def read_round_half_up(flat, base, W, H, u, v):
    return bilinear(flat, base, W, H, u, v, lattice=lambda p: np.floor(p + 0.5))


def read_round_half_even(flat, base, W, H, u, v):
    return bilinear(flat, base, W, H, u, v, lattice=np.rint)


def read_fractions_exchanged(flat, base, W, H, u, v):
    a, b, x0, x1, y0, y1 = corners(W, H, u * W, v * H, np.floor)
    t = lambda x, y: texels(flat, base, W, x, y)
    return (1 - a) * ((1 - b) * t(x0, y0) + b * t(x1, y0)) + a * ((1 - b) * t(x0, y1) + b * t(x1, y1))


def read_last_column_single(flat, base, W, H, u, v):
    c = read_handout(flat, base, W, H, u, v)
    x0 = np.clip(np.floor(u * W), 0, W - 1).astype(np.intp)
    y0 = np.clip(np.floor(v * H), 0, H - 1).astype(np.intp)
    last = x0 == W - 1
    c[last] = texels(flat, np.broadcast_to(base, u.shape)[last], W, x0[last], y0[last])
    return c


# ---- fetchColor's requests ------------------------------------------------------------------

def ask_table(dirs, W, H):
    return handout_request(dirs)


def ask_z_exchanged(dirs, W, H):
    f, u, v = handout_request(dirs)
    return np.where(f == 4, 5, np.where(f == 5, 4, f)), u, v


def ask_fmod(dirs, W, H):
    f, u, v = handout_request(dirs)
    return f, np.fmod(u, 1.0), np.fmod(v, 1.0)


def ask_u_wrap_v_flip_pos_z(dirs, W, H):
    f, u, v = handout_request(dirs)
    on = f == 4
    with np.errstate(invalid="ignore", divide="ignore"):
        v_flip = (1 + dirs[:, 1] / np.abs(dirs[:, 2])) / 2
    v = np.where(on, v_flip, v)
    u = np.where(u >= 1.0, u - 1.0, u)
    return f, u, v


def ask_clamp(eps_u, eps_v):
    def ask(dirs, W, H):
        f, u, v = handout_request(dirs)
        eu, ev = eps_u(W), eps_v(H)
        return f, np.minimum(np.maximum(u, eu), 1 - eu), np.minimum(np.maximum(v, ev), 1 - ev)
    return ask


TRUTH = {
    # name: (fetchColor's request, readTexture)
    "lattice-int-plus-half_rgb-lerp-struct": (ask_table, read_round_half_up),
    "lattice-nearbyint_z-faces-exchanged": (ask_z_exchanged, read_round_half_even),
    "fractions-exchanged_lerp-template_face-switch": (ask_table, read_fractions_exchanged),
    "edge-last-column-only_x0-plus-one-ge-w": (ask_table, read_last_column_single),
    "wrap-fmod-both_face-lambda-table": (ask_fmod, read_handout),
    "wrap-u-if-ge-one_v-flipped-pos-z": (ask_u_wrap_v_flip_pos_z, read_handout),
    "uv-clamp-1e-4_std-clamp_axis-struct": (ask_clamp(lambda W: 1e-4, lambda H: 1e-4), read_handout),
    "uv-clamp-texel-centres_half-over-w": (ask_clamp(lambda W: 0.5 / W, lambda H: 0.5 / H), read_handout),
    "correct_modf-weights_axis-permutation-table": (ask_table, read_handout),
    "correct_clamped-to-unit-square_ternary-chain": (ask_table, read_handout),
}


def build(name: str) -> ctypes.CDLL:
    OUT.mkdir(exist_ok=True)
    lib = OUT / f"{name}.so"
    subprocess.run(["g++", "-std=c++17", "-O2", "-shared", "-fPIC", f"-I{ROOT / 'student_template'}",
                    str(BLIND2 / f"{name}.cpp"), str(HARNESS), "-o", str(lib)], check=True)
    so = ctypes.CDLL(str(lib))
    so.h_new.restype = ctypes.c_void_p
    for f in ("h_attach", "h_fetch", "h_record", "h_read"):
        getattr(so, f).restype = None
    return so


def ptr(a):
    return a.ctypes.data_as(ctypes.c_void_p)


def close(a, b):
    return np.isclose(a, b, rtol=1e-9, atol=1e-12).all(1)


def check(name: str) -> list[str]:
    so = build(name)
    ask, read = TRUTH[name]
    plain, rec = so.h_new(0), so.h_new(1)
    lines, keep = [], []
    for W, H in SIZES:
        cube = rng.random((6, H, W, 3), dtype=np.float32) * 4
        flat = np.ascontiguousarray(cube).reshape(-1)
        keep.append(flat)
        for m in (plain, rec):
            so.h_attach(ctypes.c_void_p(m), ptr(flat), W, H)
        dirs = np.ascontiguousarray(DIRS)
        n = len(dirs)
        got = np.zeros((n, 3))
        so.h_fetch(ctypes.c_void_p(plain), ptr(dirs), n, ptr(got))
        colours, touched = model.fetch_touching(cube, dirs)
        right = np.zeros(n, bool)
        for f in range(6):
            right |= touched[:, f] & close(got, colours[:, f])
        valid = touched.any(1)
        f_, u_, v_ = ask(dirs, W, H)
        want = read(flat, np.where(valid, f_, 0) * 3 * W * H, W, H, np.nan_to_num(u_), np.nan_to_num(v_))
        truth_ok = close(got[valid], want[valid])
        black = (got[~valid] == 0).all(1)
        r = np.zeros((n, 5))
        so.h_record(ctypes.c_void_p(rec), ptr(dirs), n, ptr(r))
        asked = r[valid]
        rec_ok = ((asked[:, 0] == 1) & (asked[:, 1] == f_[valid]) & np.isclose(asked[:, 2], u_[valid], rtol=0, atol=1e-15)
                  & np.isclose(asked[:, 3], v_[valid], rtol=0, atol=1e-15) & (asked[:, 4] == 1))
        hf, hu, hv = handout_request(dirs)
        rec_handout = (asked[:, 1] == hf[valid]) & np.isclose(asked[:, 2], hu[valid], atol=1e-15) \
            & np.isclose(asked[:, 3], hv[valid], atol=1e-15)
        per_face = " ".join(f"{model.FACE_NAMES[f]}:{int((~rec_handout & (hf[valid] == f)).sum())}" for f in range(6))
        # readTexture alone
        grid = np.stack(np.meshgrid(np.arange(2 * W + 1) / (2 * W), np.arange(2 * H + 1) / (2 * H)), -1).reshape(-1, 2)
        uv = np.concatenate([rng.random((3000, 2)), grid,
                             np.array([[1, 1], [1 - 2 ** -30, 1 - 2 ** -30], [0, 0], [1, 0], [0, 1]])])
        uv = np.ascontiguousarray(uv)
        face = 2
        rt = np.zeros((len(uv), 3))
        so.h_read(ctypes.c_void_p(plain), face, ptr(uv), len(uv), ptr(rt))
        rt_model = model.read_texture(cube, face, uv[:, 0], uv[:, 1])
        rt_truth = read(flat, face * 3 * W * H, W, H, uv[:, 0], uv[:, 1])
        lines.append(f"  {W}x{H}: end to end = handout {right[valid].mean():7.2%}, = truth {truth_ok.mean():7.2%};"
                     f" record = truth {rec_ok.mean():7.2%} (= table {rec_handout.mean():7.2%});"
                     f" readTexture = handout {close(rt, rt_model).mean():7.2%}, = truth {close(rt, rt_truth).mean():7.2%};"
                     f" no face -> black {black.mean():7.2%}")
        lines.append(f"  {W}x{H}: requests off the table, by the table's face: {per_face}")
        claim = CLAIMS.get(name)
        if claim:
            lines.append(f"  {W}x{H}: {claim(W, H, dirs, valid, got, colours, touched, hf, hu, hv, uv, rt, rt_model)}")
    return lines


# ---- narrower claims of some headers -------------------------------------------------------

def claim_rt_differs_where(region_doc, region):
    """readTexture differs from the handout only inside `region` (and somewhere inside it)."""
    def claim(W, H, dirs, valid, got, colours, touched, hf, hu, hv, uv, rt, rt_model):
        differs = ~close(rt, rt_model)
        inside = region(W, H, uv[:, 0], uv[:, 1])
        return (f"readTexture differs from the handout at {differs.sum()} (u, v), all {region_doc}: "
                f"{bool((differs <= inside).all())}; differs at {differs[inside].mean():.1%} of those {inside.sum()}")
    return claim


def claim_e2e_differs_where(region_doc, region):
    def claim(W, H, dirs, valid, got, colours, touched, hf, hu, hv, uv, rt, rt_model):
        right = np.zeros(len(dirs), bool)
        for f in range(6):
            right |= touched[:, f] & close(got, colours[:, f])
        wrong = valid & ~right
        inside = valid & region(W, H, hu, hv)
        return (f"end to end wrong at {wrong.sum()} directions, all {region_doc}: {bool((wrong <= inside).all())}"
                f" ({inside.sum()} directions there)")
    return claim


CLAIMS = {
    "edge-last-column-only_x0-plus-one-ge-w": claim_rt_differs_where(
        "with uW >= W - 1, frac(vH) > 0 and vH < H - 1",
        lambda W, H, u, v: (u * W >= W - 1) & (v * H - np.floor(v * H) > 0) & (v * H < H - 1)),
    "fractions-exchanged_lerp-template_face-switch": claim_rt_differs_where(
        "off the top-right texel and with alpha != beta",
        lambda W, H, u, v: ~((u * W >= W - 1) & (v * H >= H - 1)) & (u * W - np.floor(u * W) != v * H - np.floor(v * H))),
    "lattice-int-plus-half_rgb-lerp-struct": claim_rt_differs_where(
        "where frac(uW) >= 0.5 or frac(vH) >= 0.5",
        lambda W, H, u, v: (u * W - np.floor(u * W) >= 0.5) | (v * H - np.floor(v * H) >= 0.5)),
    "uv-clamp-texel-centres_half-over-w": claim_e2e_differs_where(
        "with uW < 0.5 or vH < 0.5 (none near u = 1 or v = 1)",
        lambda W, H, u, v: (u * W < 0.5) | (v * H < 0.5)),
    "uv-clamp-1e-4_std-clamp_axis-struct": claim_e2e_differs_where(
        "within 1e-4 of u = 0 or v = 0",
        lambda W, H, u, v: (u < 1e-4) | (v < 1e-4)),
}


if __name__ == "__main__":
    names = sys.argv[1:] or sorted(TRUTH)
    assert set(TRUTH) == {p.stem for p in BLIND2.glob("*.cpp")}
    for name in names:
        print(name)
        print("\n".join(check(name)))
