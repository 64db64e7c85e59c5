"""Whether fetchColor asks readTexture the same on the public maps as on
the sweep's faces.

The arrows and the renders look up on the maps of Cubemap/ (128 and 256
texels wide, texels anyone can read). fetchColor is recorded
(instruments.fetch_record: its calls logged and answered with tags, the
student's readTexture never called) on the same directions on random faces
of the sweep's size (32 x 32) and on each of those maps, in one worker. The
handout's fetchColor asks for the face and (u, v) the direction alone
decides; one that asks otherwise on a public map (it tells the maps by
their size or their texels) is observed doing so, call for call. Where one
does, run_checks runs each check that looks up the public maps again
through `SweepFaceRequests`: fetchColor runs on random faces of the sweep's
size, and each direction's colour is the handout's readTexture on the
public map at the face and (u, v) it asked for there. The lower score
counts: a lookup right only on faces 128 wide or more
(redteam4/right_on_the_public_maps) earned the renders and the arrows while
the sweep found +Z upside down, and now earns what the same mistake
everywhere earns.

What it cannot see: a fetchColor that makes no readTexture call (it reads
the texels itself) records nothing to compare.
"""
from __future__ import annotations

import functools
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...envmap import library, oracle
from ...grading import fixtures
from ...grading.results import Diagnosis
from ...i18n import _
from . import fetch_record
from .directions import random_directions
from .textures import SWEEP_FACE_SIZE, random_faces

PROBE_DIRECTIONS = 2048
DIAGNOSIS_IDS = ("fetch-depends-on-the-map",)


def public_maps() -> list[Path]:
    """Every map the end-to-end checks look up (the renders' maps, the arrows' among them), once each."""
    return sorted({f.map.resolve() for f in fixtures.render_fixtures()})


def stamp(path) -> tuple:
    """A file's key for a per-process cache: its path, time and size."""
    st = os.stat(path)
    return str(path), st.st_mtime_ns, st.st_size


@functools.lru_cache(maxsize=16)
def _loaded(stamp: tuple) -> np.ndarray:
    faces = oracle.current().load_cross(stamp[0])
    faces.setflags(write=False)
    return faces


def load_map(path) -> np.ndarray:
    """A cross's faces (6, H, W, 3), read-only, loaded once per process
    and again when the file changes."""
    return _loaded(stamp(path))


@dataclass(frozen=True)
class MapProbe:
    """fetchColor's record for the same directions on the sweep's faces and on each public map."""
    directions: np.ndarray                  # (n, 3)
    on_sweep_faces: fetch_record.Record     # on random faces of SWEEP_FACE_SIZE
    on_maps: tuple                          # ((path, (W, H), Record), ...)

    def _differ(self, rec: fetch_record.Record) -> np.ndarray:
        return differ(self.on_sweep_faces, rec)

    @property
    def depends(self) -> bool:
        return any(self._differ(rec).any() for _path, _size, rec in self.on_maps)

    def diagnosis(self) -> Diagnosis:
        """The observation in numbers: on which map, how many, and one direction's calls both ways."""
        path, (w, h), rec = next(m for m in self.on_maps if self._differ(m[2]).any())
        rows = self._differ(rec)
        i = int(np.flatnonzero(rows)[0])
        d = self.directions[i]
        sw, sh = SWEEP_FACE_SIZE
        return Diagnosis(DIAGNOSIS_IDS[0], _(
            "On %(map)s (%(w)d x %(h)d faces) fetchColor asked readTexture otherwise than on random %(sw)d x %(sh)d "
            "faces for %(n)d of %(total)d directions; e.g. fetchColor(Vector3(%(x).4f, %(y).4f, %(z).4f)) asked for "
            "%(there)s there and %(here)s on the random faces. The arrows and renders checks were judged again with "
            "what fetchColor asks for on %(sw)d x %(sh)d faces, read from the public maps as the handout reads; the "
            "lower score counts.")
            % {"map": Path(path).name, "w": w, "h": h, "sw": sw, "sh": sh, "n": int(rows.sum()),
               "total": int(compared(self.on_sweep_faces, rec).sum()), "x": d[0], "y": d[1], "z": d[2],
               "there": calls_in_words(rec, i), "here": calls_in_words(self.on_sweep_faces, i)})


def compared(a: fetch_record.Record, b: fetch_record.Record) -> np.ndarray:
    """(n,) bool: fetchColor finished in both records (a crash or a hang
    on one map is the end-to-end checks' to see, not a difference here)."""
    return (a.calls >= 0) & (b.calls >= 0)


def differ(a: fetch_record.Record, b: fetch_record.Record) -> np.ndarray:
    """(n,) bool: directions whose calls differ between two records of the
    same directions: how many, the face of each, its (u, v) beyond float
    rounding (fetch_record.UV_TOLERANCE), or which answer came back."""
    n = fetch_record.RECORDED_CALLS
    made = np.arange(n)[None, :] < np.minimum(a.calls, n)[:, None]
    with np.errstate(invalid="ignore"):
        uv = (np.abs(a.uv - b.uv) <= fetch_record.UV_TOLERANCE) | (np.isnan(a.uv) & np.isnan(b.uv))
    same_calls = ((a.faces == b.faces) & uv.all(axis=2)) | ~made
    same = (a.calls == b.calls) & (a.returned == b.returned) & same_calls.all(axis=1)
    return compared(a, b) & ~same


def calls_in_words(rec: fetch_record.Record, i: int) -> str:
    """One direction's readTexture calls as a student reads them."""
    calls = int(rec.calls[i])
    if calls == 0:
        return _("no readTexture call")
    shown = []
    for k in range(min(calls, fetch_record.RECORDED_CALLS)):
        face = int(rec.faces[i, k])
        where = library.FACE_NAMES[face] if face >= 0 else _("an address that is no face's start")
        shown.append(_("%(face)s at (u, v) = (%(u)r, %(v)r)") % {"face": where, "u": float(rec.uv[i, k, 0]),
                                                                  "v": float(rec.uv[i, k, 1])})
    more = "" if calls <= fetch_record.RECORDED_CALLS else _(", and %(n)d more calls") % {
        "n": calls - fetch_record.RECORDED_CALLS}
    return "; ".join(shown) + more


def probe(lookups, seed: int) -> MapProbe:
    """fetchColor recorded on the same directions on each public map
    (largest first, in one worker, as the renders look them up) and then on
    random faces of the sweep's size."""
    dirs = random_directions(PROBE_DIRECTIONS, int(np.random.SeedSequence([seed, 0x3A95]).generate_state(1)[0]))
    maps = sorted(((path, load_map(path)) for path in public_maps()), key=lambda m: -m[1].nbytes)
    on_maps = []
    restart = getattr(lookups, "restart", None)     # in-process stand-ins have no process to restart
    if restart is not None:
        restart()
    for k, (path, faces) in enumerate(maps):
        lookups.set_faces(faces, same_process=k > 0)
        on_maps.append((str(path), (faces.shape[2], faces.shape[1]), fetch_record.record(lookups, dirs)))
    w, h = SWEEP_FACE_SIZE
    faces = random_faces(w, h, int(np.random.SeedSequence([seed, 0x3A95, 1]).generate_state(1)[0]))
    lookups.set_faces(faces, same_process=bool(maps))
    return MapProbe(dirs, fetch_record.record(lookups, dirs), tuple(on_maps))


class SweepFaceRequests:
    """The submission's lookups as a check that looks up the public maps
    sees them, with fetchColor judged on what it asks for on faces of the
    sweep's size: each fetch is recorded on random faces of that size
    (answered with tags), and a direction's colour is the handout's
    readTexture on the faces the check set (a public map) at the face and
    (u, v) of the call whose answer fetchColor returned, or of its first call
    where it returned none as it came. A direction with no readTexture call,
    or none at a face's start, is black: what it reads on other faces says
    nothing about the map. fetchColor never sees a public map here."""

    def __init__(self, lookups, seed: int):
        w, h = SWEEP_FACE_SIZE
        self.inner = lookups
        self.sweep_faces = random_faces(w, h, int(np.random.SeedSequence([seed, 0x3A95, 2]).generate_state(1)[0]))
        self.faces = self.sweep_faces

    def set_faces(self, faces, same_process: bool = False) -> None:
        self.faces = np.asarray(faces)
        self.inner.set_faces(self.sweep_faces, same_process=same_process)

    def restart(self) -> None:
        self.inner.restart()

    def reset_failure_budget(self) -> None:
        reset = getattr(self.inner, "reset_failure_budget", None)
        if reset is not None:
            reset()

    def fetch(self, dirs: np.ndarray, placement: str = "end"):
        import dataclasses
        rec = fetch_record.record(self.inner, dirs)
        n = len(rec.calls)
        k = np.where(rec.returned >= 0, rec.returned, 0)
        asked = (rec.calls >= 1) & (k < fetch_record.RECORDED_CALLS)
        face = np.where(asked, rec.faces[np.arange(n), np.minimum(k, fetch_record.RECORDED_CALLS - 1)], -1)
        uv = rec.uv[np.arange(n), np.minimum(k, fetch_record.RECORDED_CALLS - 1)]
        values = fetch_record.handout_read(self.faces, face, uv)
        values[(rec.calls >= 0) & (face < 0)] = 0.0
        outcome = rec.outcome
        return dataclasses.replace(outcome, values=values, evaluated=np.asarray(outcome.evaluated, bool) & (rec.calls >= 0))
