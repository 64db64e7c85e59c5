"""Mitsuba 3 as a peer renderer: the handout's scene rendered by both, compared.

    .venv/bin/pip install -r requirements-study.txt      # mitsuba, once
    .venv/bin/python bench/bench_mitsuba.py [--scene envmap_test.cfg] [--size 256]
        [--spp 16] [--converged-spp 1024] [--noise-spp 16 64 256] [--repeats 5]
        [--threads 1] [--maps CROSS.hdr ...] [--pictures docs/study] [--no-rotation]

For each map, renders the scene (camera, spheres, max_depth from the .cfg;
the map replaced) with our reference renderer (grader.envmap.library.Scene.render,
the handout's bilinear lookup, all in C, one thread) and with Mitsuba 3's
scalar_rgb `path` integrator, then prints:
  - agreement: SSIM and mean FLIP (grader.checks.instruments.image_metrics, on the
    tone-mapped images) of Mitsuba against ours at the same spp, and of
    both at --converged-spp (noise gone from both); and of the background
    alone (no spheres), which isolates the camera and the environment's
    lat-long resampling;
  - speed: the median of --repeats renders of each at the same spp, after
    the scene is loaded, and the ratio Mitsuba / ours. Mitsuba runs on
    --threads threads (1: the same as ours);
  - equal quality: FLIP against our converged render of ours at --spp and
    of Mitsuba at each --noise-spp, with the time of each render.
--no-rotation leaves out the envmap's turn (below), a control: the
agreement must then drop.
With --pictures DIR, writes DIR/mitsuba_<map>.png: ours | Mitsuba (both converged)
| 4x the difference, for the maps inside the project only (the probes in
../shared/probes may not be redistributed, nor renders that show them).

How the scene is matched (docs/study.md, "Mitsuba 3 as a peer renderer"):
  - camera: `perspective`, to_world look_at(position, look_at, up), our fov
    is vertical, so fov_axis = "y"; a box pixel filter (ours averages
    jittered samples inside the pixel) and a stratified (jittered) sampler;
  - mirror: `conductor` with material "none" (Fresnel off: a 100 % mirror),
    specular_reflectance = tint; glass: `dielectric`, int_ior = ior,
    ext_ior = 1 (Mitsuba's default is air, 1.000277), specular_transmittance
    = tint;
  - path: max_depth = ours + 1 (Mitsuba counts the emitter vertex: 1 means
    directly visible light only; ours counts surface hits), rr_depth above
    max_depth so no path is cut by Russian roulette;
  - environment: `envmap` from a lat-long EXR whose texels are our bilinear
    lookup (the one our renderer uses) point-sampled where Mitsuba puts its
    texels: column i at u = (i + 1/2) / W, row j at latitude 90 - 180 j / (H - 1)
    degrees (Mitsuba's envmap interpolates rows from pole to pole). The
    image is laid out in this project's lat-long convention
    (grader/cubemap/projections.py: centre column along -z, +x at 3/4);
    Mitsuba's puts -z at u = 0 and +x at 1/4, which is the same map turned
    180 degrees about +y, so the emitter gets to_world = rotate(+y, 180).
"""
from __future__ import annotations

import argparse
import re
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from grader.checks.instruments import image_metrics  # noqa: E402
from grader.cubemap.projections import latlong_to_direction  # noqa: E402
from grader.envmap.imaging import write_image  # noqa: E402
from grader.envmap.library import CubeMap, Scene  # noqa: E402

from bench_render import median_seconds  # noqa: E402  (this folder: the same timing as the render bench)

# The probe only when ../shared/probes is beside the checkout (not in the repository).
DEFAULT_MAPS = tuple(p for p in (ROOT / "Cubemap" / "test_environment_map.hdr",
                                 ROOT / "Cubemap" / "sky_cross.hdr",
                                 ROOT.parent / "shared" / "probes" / "grace_cross.hdr") if p.exists())
# Lat-long columns per cube face texel along the equator: 8 puts 2 lat-long
# texels across each cube texel, so Mitsuba's bilinear over the samples stays
# close to the bilinear lookup it samples.
LATLONG_PER_FACE_TEXEL = 8

# Defaults of the keys a .cfg may leave out (reference/src/scene.c).
CAMERA_DEFAULTS = {"position": (0.0, 0.0, 0.0), "look_at": (0.0, 0.0, -1.0), "up": (0.0, 1.0, 0.0), "fov": 45.0}
SAMPLING_DEFAULTS = {"max_depth": 32}
SPHERE_DEFAULTS = {"ior": 1.5, "tint": (1.0, 1.0, 1.0)}


# ---- the scene file, as far as Mitsuba needs it ------------------------------------

def read_blocks(text: str) -> list[tuple[str, dict]]:
    """The .cfg's blocks as (name, {key: str | float | tuple}). The file must
    already have passed the C parser (Scene.load), so this reader need not
    report errors."""
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    blocks = []
    for name, body in re.findall(r"([A-Za-z_]\w*)\s*\{([^}]*)\}", text):
        keys = {}
        for key, value in re.findall(r"([A-Za-z_]\w*)\s*=\s*([^;]*);", body):
            value = value.strip()
            if value.startswith('"'):
                keys[key] = value.strip('"')
            else:
                numbers = tuple(float(x) for x in re.split(r"[\s,()]+", value) if x)
                keys[key] = numbers[0] if len(numbers) == 1 else numbers
        blocks.append((name, keys))
    return blocks


def scene_settings(text: str) -> dict:
    blocks = read_blocks(text)
    camera = dict(CAMERA_DEFAULTS)
    sampling = dict(SAMPLING_DEFAULTS)
    spheres = []
    for name, keys in blocks:
        if name == "camera":
            camera.update(keys)
        elif name == "sampling":
            sampling.update(keys)
        elif name == "sphere":
            spheres.append({**SPHERE_DEFAULTS, **keys})
    return {"camera": camera, "max_depth": int(sampling["max_depth"]), "spheres": spheres}


def without_spheres(text: str) -> str:
    return re.sub(r"\bsphere\s*\{[^}]*\}", "", re.sub(r"/\*.*?\*/", "", text, flags=re.S))


# ---- the environment for Mitsuba -------------------------------------------------------

def mitsuba_latlong(cube: CubeMap, width: int, hdr_gamma: float = 1.0) -> np.ndarray:
    """(width/2, width, 3) float32: our bilinear lookup at Mitsuba's envmap
    texel positions, in this project's lat-long layout (module docstring)."""
    height = width // 2
    s = (np.arange(width) + 0.5) / width
    t = np.arange(height) / (height - 1)
    dirs = latlong_to_direction(*np.meshgrid(s, t))
    rgb = cube.fetch(dirs.reshape(-1, 3), "bilinear").reshape(height, width, 3)
    if hdr_gamma != 1.0:       # ours raises each looked-up colour to hdr_gamma
        rgb = np.where(rgb > 0, np.power(np.maximum(rgb, 0), hdr_gamma), 0.0)
    return rgb.astype(np.float32)


# ---- Mitsuba ------------------------------------------------------------------------------

def mitsuba_scene(mi, settings: dict, envmap_path: Path, size: int, spp: int,
                  spheres: bool = True, rotate: bool = True):
    cam = settings["camera"]
    T = mi.ScalarTransform4f
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": settings["max_depth"] + 1,
                       "rr_depth": settings["max_depth"] + 2},
        "sensor": {
            "type": "perspective", "fov": float(cam["fov"]), "fov_axis": "y",
            "to_world": T().look_at(origin=list(cam["position"]), target=list(cam["look_at"]),
                                    up=list(cam["up"])),
            "film": {"type": "hdrfilm", "width": size, "height": size,
                     "pixel_format": "rgb", "rfilter": {"type": "box"}},
            "sampler": {"type": "stratified", "sample_count": spp, "jitter": True, "seed": 0},
        },
        "environment": {"type": "envmap", "filename": str(envmap_path),
                        "to_world": T().rotate(axis=[0, 1, 0], angle=180.0 if rotate else 0.0)},
    }
    for i, sphere in enumerate(settings["spheres"] if spheres else []):
        tint = {"type": "rgb", "value": list(sphere["tint"])}
        if sphere["material"] == "mirror":
            bsdf = {"type": "conductor", "material": "none", "specular_reflectance": tint}
        else:
            bsdf = {"type": "dielectric", "int_ior": float(sphere["ior"]), "ext_ior": 1.0,
                    "specular_transmittance": tint}
        scene[f"sphere_{i}"] = {"type": "sphere", "center": list(sphere["center"]),
                                "radius": float(sphere["radius"]), "bsdf": bsdf}
    return mi.load_dict(scene)


def agreement(ours: np.ndarray, theirs: np.ndarray) -> tuple[float, float]:
    a, b = image_metrics.display(ours), image_metrics.display(theirs)
    return image_metrics.ssim(a, b), image_metrics.flip(a, b)[0]


def side_by_side(ours: np.ndarray, theirs: np.ndarray) -> np.ndarray:
    a, b = image_metrics.display(ours), image_metrics.display(theirs)
    gap = np.ones((a.shape[0], 4, 3), np.float32)
    return np.concatenate([a, gap, b, gap, image_metrics.difference_picture(a, b)], axis=1)


def compare_map(mi, dr, default_threads: int, args, text: str, settings: dict, map_path: Path, workdir: Path) -> dict:
    scene = Scene.parse(text, str(args.scene), str(args.scene.parent))
    scene.set_resolution(args.size, args.size)
    scene.set_samples(args.spp)
    background = Scene.parse(without_spheres(text), str(args.scene), str(args.scene.parent))
    background.set_resolution(args.size, args.size)
    background.set_samples(args.spp)
    cube = CubeMap.load_cross(map_path)

    latlong = mitsuba_latlong(cube, LATLONG_PER_FACE_TEXEL * cube.face_width, scene.hdr_gamma)
    envmap_path = workdir / f"{map_path.stem}_latlong.exr"
    write_image(envmap_path, latlong)
    # Loading an envmap deadlocks Mitsuba 3.9.1 with a one-thread pool, so
    # load on the default pool and narrow it for rendering only.
    dr.set_thread_count(default_threads)
    mi_scene = mitsuba_scene(mi, settings, envmap_path, args.size, args.spp, rotate=not args.no_rotation)
    mi_background = mitsuba_scene(mi, settings, envmap_path, args.size, args.spp, spheres=False,
                                  rotate=not args.no_rotation)
    dr.set_thread_count(args.threads)

    t_ours, ours = median_seconds(lambda: scene.render(cube, "bilinear"), args.repeats)
    t_mi, theirs = median_seconds(lambda: np.array(mi.render(mi_scene, spp=args.spp, seed=0)),
                                  args.repeats)
    bg_ours = background.render(cube, "bilinear")
    bg_theirs = np.array(mi.render(mi_background, spp=args.spp, seed=0))
    # Converged: both at converged_spp (not timed, so on every thread).
    dr.set_thread_count(default_threads)
    theirs_converged = np.array(mi.render(mi_scene, spp=args.converged_spp, seed=1))
    scene.set_samples(args.converged_spp)
    ours_converged = scene.render(cube, "bilinear")
    row = {"map": map_path.name, "t_ours": t_ours, "t_mitsuba": t_mi}
    row["ssim"], row["flip"] = agreement(ours, theirs)
    row["ssim_conv"], row["flip_conv"] = agreement(ours_converged, theirs_converged)
    row["ssim_bg"], row["flip_bg"] = agreement(bg_ours, bg_theirs)
    row["mean_ratio"] = float(theirs_converged.mean() / ours_converged.mean())
    # Equal quality: FLIP against the converged reference of ours at --spp,
    # and of Mitsuba at each --noise-spp, with the time of that render.
    row["flip_ours_noise"] = agreement(ours_converged, ours)[1]
    dr.set_thread_count(args.threads)
    row["noise"] = []
    for spp in args.noise_spp:
        seconds, image = median_seconds(lambda: np.array(mi.render(mi_scene, spp=spp, seed=2)), 1)
        row["noise"].append((spp, agreement(ours_converged, image)[1], seconds))
    # A render of a probe from outside the project shows the probe itself, and
    # the probes may not be redistributed (../shared/probes/PROVENANCE.md).
    if args.pictures and map_path.resolve().is_relative_to(ROOT):
        args.pictures.mkdir(parents=True, exist_ok=True)
        path = args.pictures / f"mitsuba_{map_path.stem}.png"
        write_image(path, side_by_side(ours_converged, theirs_converged), display_referred=True)
        row["picture"] = path
    return row


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", type=Path, default=ROOT / "envmap_test.cfg")
    parser.add_argument("--maps", type=Path, nargs="+", default=list(DEFAULT_MAPS))
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--spp", type=int, default=16, help="a square, for the stratified sampler")
    parser.add_argument("--converged-spp", type=int, default=1024)
    parser.add_argument("--noise-spp", type=int, nargs="*", default=[16, 64, 256],
                        help="Mitsuba spp levels for the equal-quality table")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--threads", type=int, default=1, help="Mitsuba's render threads")
    parser.add_argument("--pictures", type=Path, help="write DIR/mitsuba_<map>.png")
    parser.add_argument("--no-rotation", action="store_true",
                        help="leave out the envmap's 180-degree turn (a control: agreement must drop)")
    args = parser.parse_args()

    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError:
        print("mitsuba is not installed: .venv/bin/pip install -r requirements-study.txt")
        return 2
    mi.set_variant("scalar_rgb")
    default_threads = dr.thread_count()

    Scene.load(args.scene)          # the C parser checks the file first
    text = args.scene.read_text()
    settings = scene_settings(text)
    print(f"{args.scene.name} at {args.size} x {args.size}, {args.spp} spp (converged: "
          f"{args.converged_spp}), max_depth {settings['max_depth']}, Mitsuba {mi.__version__} "
          f"scalar_rgb on {args.threads} thread(s), ours on 1; times: median of {args.repeats}")
    header = (f"{'map':28} {'SSIM':>6} {'FLIP':>6} {'SSIM*':>6} {'FLIP*':>6} {'SSIMbg':>6} "
              f"{'FLIPbg':>6} {'mean*':>6} {'ours s':>7} {'Mitsuba s':>9} {'ratio':>6}")
    print(header)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for map_path in args.maps:
            r = compare_map(mi, dr, default_threads, args, text, settings, map_path, Path(tmp))
            rows.append(r)
            print(f"{r['map']:28} {r['ssim']:6.4f} {r['flip']:6.4f} {r['ssim_conv']:6.4f} "
                  f"{r['flip_conv']:6.4f} {r['ssim_bg']:6.4f} {r['flip_bg']:6.4f} "
                  f"{r['mean_ratio']:6.4f} {r['t_ours']:7.3f} {r['t_mitsuba']:9.3f} "
                  f"{r['t_mitsuba'] / r['t_ours']:6.2f}", flush=True)
    print("SSIM, FLIP: Mitsuba against ours at the same spp; *: both at the converged spp; "
          "bg: the background alone (no spheres); mean*: mean pixel value, Mitsuba* / ours; "
          "ratio: Mitsuba time / ours.")
    if args.noise_spp:
        print(f"\nEqual quality: FLIP against ours at {args.converged_spp} spp (time of one render, s)")
        print(f"{'map':28} {'ours ' + str(args.spp) + ' spp':>20} "
              + " ".join(f"{'Mitsuba ' + str(n) + ' spp':>22}" for n in args.noise_spp))
        for r in rows:
            cells = " ".join(f"{flip_value:12.4f} ({seconds:6.2f})" for _, flip_value, seconds in r["noise"])
            print(f"{r['map']:28} {r['flip_ours_noise']:11.4f} ({r['t_ours']:6.2f}) {cells}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
