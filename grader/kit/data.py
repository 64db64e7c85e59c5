"""The student kit's expected data: what the reference returns on the kit's
public inputs, and what each known mistake would return on them.

Everything here is computed with the grader's own reference (grader.reference)
and the grader's own input sets and mistake models (grader.checks.*), but the
kit's self-check (student_template/selfcheck/) judges with its own second
implementation of the checks, which has drifted from the grader (issue 20:
12 of 13 wrong submissions score differently). Its replacement is under way:
grader.kit.answers records the lookup's answers for the grader's own checks
(grader.oracle), which the kit is to run itself. The kit receives numbers,
never code: no (u, v) table, no filter.

Files are raw little-endian arrays: inputs (directions, (u, v)) in float64, so
ties stay exact; expected colours in float32, whose rounding (6e-8 relative)
is 100 times below the smallest tolerance they are compared with
(grader.checks.instruments.compare.tolerance: 9.5e-6 for 16-texel faces of magnitude 1).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from .. import PROJECT_ROOT, fixtures, reference
from ..checks import arrows as arrows_check
from ..checks.instruments import face_recovery as diagnosis_check
from ..checks import read_texture as read_texture_check
from ..checks import stability as stability_check
from ..checks.instruments.compare import tie_alternatives, tolerance
from ..checks.instruments.directions import fibonacci_sphere, random_directions, sweep_sets, tied_axes
from ..checks.instruments.textures import coordinate_faces, random_faces
from ..cubemap.directions import texel_directions

# The kit's inputs are public: one fixed seed, unrelated to the course secret.
KIT_SEED = 20261201
FIBONACCI = 20_000          # the sweep's, the arrows' and the diagnosis' sphere (the grader's quick size)
RANDOM = 5_000              # the public stand-in for the grader's per-run random set
DIAGNOSIS_DIRECTIONS = 6_000
RENDER_SIZE = (64, 64)      # small renders: the kit's render metric is measured at this size
RENDER_SPP = 4
FILTERS = ("bilinear", "nearest")

if sys.byteorder != "little":  # pragma: no cover - every supported platform is little-endian
    raise RuntimeError("the kit's data files are little-endian")


class DataWriter:
    """Writes arrays into data/ and returns their names for the manifest."""

    def __init__(self, folder: Path):
        self.folder = folder
        folder.mkdir(parents=True, exist_ok=True)
        self.names: set[str] = set()

    def save(self, name: str, array: np.ndarray, dtype) -> str:
        assert name not in self.names, name
        self.names.add(name)
        np.ascontiguousarray(array, dtype=dtype).tofile(self.folder / name)
        return name

    def f64(self, name: str, array) -> str:
        return self.save(name + ".f64", array, "<f8")

    def f32(self, name: str, array) -> str:
        return self.save(name + ".f32", array, "<f4")

    def i32(self, name: str, array) -> str:
        return self.save(name + ".i32", array, "<i4")


def _faces_file(data: DataWriter, name: str, faces: np.ndarray) -> dict:
    faces = np.asarray(faces, np.float32)
    return {"file": data.f32(name, faces), "width": int(faces.shape[2]), "height": int(faces.shape[1])}


def _expected_fetch(data: DataWriter, name: str, cube: reference.CubeMap, dirs: np.ndarray,
                    dirs_file: str | None = None) -> dict:
    """Expected colours under both filters, the acceptable alternatives on the
    tied rows (edges and corners), and the face the reference picks."""
    out = {"dirs": dirs_file or data.f64(name + "_dirs", dirs), "count": len(dirs)}
    tied_rows = np.flatnonzero(tied_axes(dirs).sum(axis=1) >= 2)
    out["tied"] = data.i32(name + "_tied", tied_rows)
    for f in FILTERS:
        expected, faces = cube.fetch_with_faces(dirs, f)
        out[f"expected_{f}"] = data.f32(f"{name}_expected_{f}", expected)
        alternatives = tie_alternatives(cube, dirs[tied_rows], f) if len(tied_rows) else np.zeros((0, 3, 3))
        out[f"alternatives_{f}"] = data.f32(f"{name}_alternatives_{f}", alternatives)
        if f == "bilinear":
            out["faces"] = data.i32(name + "_faces", faces)
    return out


# Mistakes the kit recognises beyond read_texture.HYPOTHESES (same form: the
# (u, v) at which the reference gives the same answer), keyed by a name, with
# the grader's diagnosis id (grader/diagnoses.py) and the student's words.
EXTRA_HYPOTHESES = {
    "texel-offset-minus": ("texel-offset", "bilinear", lambda uv, w, h: np.clip(uv - 1.0 / np.array([w, h]), 0.0, 1.0),
                           "readTexture reads a whole texel off: it uses p = (uW - 1, vH - 1) instead of p = (uW, vH)."),
    "texel-offset-plus": ("texel-offset", "bilinear", lambda uv, w, h: np.clip(uv + 1.0 / np.array([w, h]), 0.0, 1.0),
                          "readTexture reads a whole texel off: it uses p = (uW + 1, vH + 1) instead of p = (uW, vH)."),
}


def _hypotheses() -> dict:
    """name -> (diagnosis id, filter, transform, detail)."""
    out = {name: (name, f, t, read_texture_check.DETAILS[name]) for name, (f, t) in read_texture_check.HYPOTHESES.items()}
    out.update(EXTRA_HYPOTHESES)
    return out


def read_texture_data(data: DataWriter) -> dict:
    groups = []
    for w, h in read_texture_check.FACE_SIZES:
        uv = read_texture_check.sample_points(w, h, KIT_SEED)
        group = {"width": w, "height": h, "uv": data.f64(f"rt_{w}x{h}_uv", uv), "count": len(uv), "textures": []}
        for kind, faces in (("random", random_faces(w, h, KIT_SEED)), ("coordinate", coordinate_faces(w, h))):
            cube = reference.CubeMap(faces)
            texture = {"kind": kind, "faces": _faces_file(data, f"rt_{w}x{h}_{kind}_faces", faces), "cases": []}
            for face in read_texture_check.FACES:
                case = {"face": int(face),
                        "expected": data.f32(f"rt_{w}x{h}_{kind}_{face}_expected", cube.read_texture(face, uv, "bilinear")),
                        "tolerance": float(tolerance(w, h, float(np.abs(faces[face]).max())))}
                if kind == "coordinate":
                    # What each recognised mistake returns here (read_texture.recognise).
                    case["mistakes"] = {
                        name: data.f32(f"rt_{w}x{h}_{face}_{name}", cube.read_texture(face, transform(uv, w, h), filter))
                        for name, (_, filter, transform, _) in _hypotheses().items()}
                texture["cases"].append(case)
            group["textures"].append(texture)
        groups.append(group)
    return {"groups": groups, "mistakes": {name: {"id": i, "detail": d} for name, (i, _, _, d) in _hypotheses().items()}}


def sweep_data(data: DataWriter, fibonacci: np.ndarray) -> dict:
    w, h = 32, 32
    faces = coordinate_faces(w, h)
    cube = reference.CubeMap(faces)
    sets = sweep_sets(KIT_SEED, fibonacci=FIBONACCI)
    # The grader's per-run random set is secret-seeded; the kit has a public one.
    sets = {name: dirs for name, dirs in sets.items() if not name.startswith("random")}
    sets["random (public)"] = random_directions(RANDOM, KIT_SEED)
    out_sets = []
    for i, (name, dirs) in enumerate(sets.items()):
        shared = None
        if name == "Fibonacci sphere":
            assert np.array_equal(dirs, fibonacci)
            shared = "fibonacci.f64"
        entry = _expected_fetch(data, f"sweep{i}", cube, dirs, shared)
        entry["name"] = name
        out_sets.append(entry)
    return {"faces": _faces_file(data, "sweep_faces", faces), "sets": out_sets,
            "tolerance": float(tolerance(w, h, float(max(w, h) + 1)))}


def diagnosis_data(data: DataWriter) -> dict:
    """The reference's face per direction and, for each filter, where the
    reference samples (in texels) at u, 1 - u, v and 1 - v, also for (u, v)
    computed by dividing by the length: a coordinate texture's red channel
    depends on u only and its green on v only, so these four numbers give the
    position of every swapped or flipped (u, v) (diagnosis.TRANSFORMS)."""
    size = diagnosis_check.FACE_SIZE
    cube = reference.CubeMap(coordinate_faces(size, size))
    dirs = fibonacci_sphere(DIAGNOSIS_DIRECTIONS)
    ref_faces, ref_uv = reference.direction_to_face(dirs)
    clear = tied_axes(dirs).sum(axis=1) == 1
    m_over_len = np.abs(dirs).max(axis=1) / np.linalg.norm(dirs, axis=1)
    uv_len = 0.5 + (ref_uv - 0.5) * m_over_len[:, None]
    out = {"dirs": data.f64("diag_dirs", dirs), "count": len(dirs), "face_size": size,
           "faces": _faces_file(data, "diag_faces", coordinate_faces(size, size)),
           "reference_faces": data.i32("diag_ref_faces", ref_faces), "clear": data.i32("diag_clear", clear),
           "share": diagnosis_check.SHARE,
           # the grader's tolerance for comparing answers at two lengths (face_recovery.Instrument)
           "tolerance": float(tolerance(size, size, float(size + 1)))}
    for f in FILTERS:
        for tag, uv in (("uv", ref_uv), ("uvlen", uv_len)):
            # columns: position at u, 1-u, v, 1-v (clipped to [0, 1] as the check does)
            a, b = uv[:, 0], uv[:, 1]
            probe_u = np.stack([a, 1 - a, b, 1 - b], axis=1)
            pos = np.empty((len(dirs), 4))
            for k in range(4):
                t = np.clip(probe_u[:, k], 0.0, 1.0)
                rgb = cube.read_texture(np.zeros(len(dirs), np.int64), np.stack([t, t], axis=1), f)
                pos[:, k] = rgb[:, 0] - 1.0
            out[f"positions_{f}_{tag}"] = data.f32(f"diag_pos_{f}_{tag}", pos)
    return out


def arrows_data(data: DataWriter, fibonacci: np.ndarray, test_map: Path) -> dict:
    cube = reference.CubeMap.load_cross(test_map)
    caps = arrows_check.axis_caps()
    return {"caps": data.f64("arrows_caps", caps.reshape(-1, 3)), "per_cap": int(caps.shape[1]),
            "sphere": "fibonacci.f64", "sphere_count": len(fibonacci),
            "reference_classes": data.i32("arrows_ref_classes", arrows_check.colour_class(cube.fetch(fibonacci))),
            "arrows": [list(a) for a in arrows_check.ARROWS], "axis_names": list(arrows_check.AXIS_NAMES),
            "shape_agreement": arrows_check.SHAPE_AGREEMENT}


def stability_data(data: DataWriter) -> dict:
    size = stability_check.FACE_SIZE
    cube = reference.CubeMap(coordinate_faces(size, size))
    out = {"faces": _faces_file(data, "stab_faces", coordinate_faces(size, size)),
           "tolerance": float(tolerance(size, size, size + 1.0)),
           "degenerate": data.f64("stab_degenerate", stability_check.degenerate_directions())}
    out["extreme"] = _expected_fetch(data, "stab_extreme", cube, stability_check.extreme_directions())
    ties = stability_check.ulp_moved(np.concatenate([stability_check.corners(), stability_check.edges(4)]))
    out["ties"] = _expected_fetch(data, "stab_ties", cube, ties)
    smooth_faces = 0.5 + 0.5 * texel_directions(size)
    smooth = reference.CubeMap(smooth_faces)
    a, b, edge = stability_check.edge_pairs()
    out["smooth"] = {"faces": _faces_file(data, "stab_smooth_faces", smooth.faces),
                     "a": data.f64("stab_edge_a", a), "b": data.f64("stab_edge_b", b),
                     "edge": data.i32("stab_edge_index", edge),
                     "step": float(np.abs(np.diff(smooth.faces, axis=2)).max()),
                     "tolerance": float(tolerance(size, size, 1.0))}
    for f in FILTERS:
        out["smooth"][f"jump_{f}"] = data.f64(f"stab_jump_{f}", np.abs(smooth.fetch(a, f) - smooth.fetch(b, f)).max(axis=1))
    return out


def renders_data(data: DataWriter) -> dict:
    """Reference renders of every fixture scene at the kit's small size."""
    items = []
    for fixture in fixtures.render_fixtures():
        scene = reference.Scene.load(fixture.scene)
        scene.set_resolution(*RENDER_SIZE)
        scene.set_samples(RENDER_SPP)
        image = scene.render(reference.CubeMap.load_cross(fixture.map))
        scene_rel = fixture.scene.resolve().relative_to(PROJECT_ROOT.resolve())
        items.append({"name": fixture.name, "scene": scene_rel.as_posix(), "map": fixture.map.name,
                      "expected": data.f32("render_" + fixture.name, image)})
    return {"width": RENDER_SIZE[0], "height": RENDER_SIZE[1], "samples": RENDER_SPP, "items": items}


def write_data(folder: Path, test_map: Path) -> dict:
    """Every check's data under folder; returns the manifest's "checks" part."""
    data = DataWriter(folder)
    fibonacci = fibonacci_sphere(FIBONACCI)
    data.f64("fibonacci", fibonacci)
    return {
        "read_texture": read_texture_data(data),
        "fetch_sweep": sweep_data(data, fibonacci),
        "diagnosis": diagnosis_data(data),
        "arrows": arrows_data(data, fibonacci, test_map),
        "stability": stability_data(data),
        "renders": renders_data(data),
    }


def dump(manifest: dict, path: Path) -> None:
    path.write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n")
