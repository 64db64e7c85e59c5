"""Whether what fetchColor answered on a public map is what it asks for on
random faces of the same size.

The arrows and the renders look up on the maps of Cubemap/ (128 and 256
texels wide, texels anyone can read), end to end. Each of those runs is
observed on a sample of its own directions, drawn from the grading's seed
(`sample_runs`, `observe`): before a check's runs, fetchColor is recorded on
them on random faces of each map's size in a fresh worker, as the sweep
records (instruments.fetch_record: its calls answered with tags); right
after each run, in its worker, the student's own readTexture is called
directly on the public map at the face and (u, v) of the call whose answer
came back there. Code whose answers depend on the direction and the face
size alone computes the same thing both ways (bit for bit, or through
float), right or wrong
(a (u, v) snapped to texel centres of that size included). One that
answers otherwise on the public map (it tells the public texels, the
recording's tags, its history in the process or the stream of directions
apart) is observed doing so on the run that is scored. Where one does,
run_checks runs each check that looks up the public maps again through
`RandomFaceRequests` (fetchColor on random faces of each map's size, each
direction's colour the handout's readTexture on the public map at what it
asked there) and keeps the lower score: lookups right on the public maps
only where nothing records them (tests/submissions/redteam5/) earned the
renders and the arrows while the sweep found +Z upside down, and now earn
what the same mistake everywhere earns.

A lookup that depends on the face size is judged at each size by what it
does there: right on every map 128 wide or more and wrong below
(redteam4/right_on_the_public_maps) earns the arrows and renders on the
public maps, which are that wide, and loses the sweep on its smaller faces,
as a lookup that snaps (u, v) to texel centres loses at each size what its
snapping costs there.

What it cannot see: a fetchColor that makes no readTexture call (it reads
the texels itself) asks for nothing to read again; it is judged end to end
on the public maps (redteam5/reads_itself_on_every_map). And one that is
right only in a long or bunched stream of lookups (after thousands on one
map, or for camera rays) is observed answering otherwise in the sample (a
fresh worker, 256 directions), but judged again on the run's whole stream,
recorded in order, where the stream makes it right again
(redteam5/right_after_many_lookups, right_on_dense_or_swept_rays): what a
lookup asks in a stream can be recorded only in that stream, and a fresh
worker per direction would cost a process per ray.
"""
from __future__ import annotations

import dataclasses
import functools
import os
import zlib
from dataclasses import dataclass

import numpy as np

from ...envmap import oracle
from ...envmap.library import FACE_NAMES
from ...grading.results import Diagnosis
from ...i18n import _
from . import fetch_record
from .compare import format_vector
from .textures import random_faces

SAMPLE = 256            # directions observed per run on a public map
DIAGNOSIS_IDS = ("fetch-depends-on-the-map",)


def stamp(path) -> tuple:
    """A file's key for a per-process cache: its path, time and size."""
    st = os.stat(path)
    return str(path), st.st_mtime_ns, st.st_size


@functools.lru_cache(maxsize=16)
def _loaded(key: tuple) -> np.ndarray:
    faces = oracle.current().load_cross(key[0])
    faces.setflags(write=False)
    return faces


def load_map(path) -> np.ndarray:
    """A cross's faces (6, H, W, 3), read-only, loaded once per process
    and again when the file changes."""
    return _loaded(stamp(path))


def random_like(seed: int, size: tuple[int, int]) -> np.ndarray:
    """Random faces (6, H, W, 3) of `size` (H, W), the same for a grading and a size."""
    h, w = size
    return random_faces(w, h, int(np.random.SeedSequence([seed, 0x3A95, 2, h, w]).generate_state(1)[0]))


@dataclass(frozen=True)
class Sample:
    """fetchColor recorded on random faces of the map's size, for some of a run's directions."""
    check: str
    where: str                  # the run in the student's language ("the render of ... with ...")
    rows: np.ndarray            # (k,) indices into the run's directions
    directions: np.ndarray      # (k, 3)
    record: fetch_record.Record


@dataclass(frozen=True)
class Seen:
    """One run's sample, read again on its public map."""
    check: str                  # the check whose run it was
    where: str
    compared: int               # sampled directions whose answer on the random faces came back, well inside a face
    differ: int                 # of those, answered on the public map otherwise than readTexture reads there
    example: tuple | None       # (direction, answer in the run, face, u, v, readTexture's read there)


@dataclass
class MapObservations:
    """Every run observed in a grading (CheckContext.map_probe)."""
    seen: list = dataclasses.field(default_factory=list)

    @property
    def depends(self) -> bool:
        return any(s.differ for s in self.seen)

    def diagnosis(self) -> Diagnosis:
        """The observation in numbers, from the latest check whose runs
        differ: how many of its sampled directions, and one in full."""
        checks = list(dict.fromkeys(s.check for s in self.seen if s.differ))
        runs = [s for s in self.seen if s.check == checks[-1]]
        first = next(s for s in runs if s.differ)
        d, answered, face, u, v, read = first.example
        return Diagnosis(DIAGNOSIS_IDS[0], _(
            "In %(where)s, fetchColor(Vector3(%(x).4f, %(y).4f, %(z).4f)) answered %(answered)s. On random faces of "
            "the same size the same direction asks readTexture for face %(face)s at (u, v) = (%(u)r, %(v)r), and "
            "your readTexture reads %(read)s there on this map: fetchColor answered otherwise than it asks. %(n)d of "
            "%(total)d directions sampled from this check's lookups on public maps differ this way. The arrows and "
            "renders checks were judged again with what fetchColor asks for on random faces of each map's size, "
            "read from the public maps as the handout reads; the lower score counts.") % {
            "where": first.where, "x": d[0], "y": d[1], "z": d[2], "answered": format_vector(answered),
            "face": FACE_NAMES[face], "u": u, "v": v, "read": format_vector(read),
            "n": sum(s.differ for s in runs), "total": sum(s.compared for s in runs)})


def observing(ctx) -> bool:
    """Whether a run on a public map is observed: not while run_checks runs
    a check again in another state (a worker whose first faces they are,
    where a recording first would change that; or through RandomFaceRequests)."""
    return not getattr(ctx, "first_faces", False) and not isinstance(ctx.lookups, RandomFaceRequests) \
        and hasattr(ctx, "map_probe")


def sample_runs(ctx, check: str, runs) -> dict:
    """{key: Sample} for a check's runs on public maps, `runs` as (key,
    where, directions, the map's (H, W)): SAMPLE of each run's directions
    (drawn from the grading's seed and the run's key), fetchColor recorded
    on them on random faces of the map's size, in a fresh worker (largest
    faces first, smaller ones after them in it), as the sweep records it: no
    state of the runs, and no public texel, reaches it. {} where the runs are
    not observed (`observing`)."""
    if not observing(ctx):
        return {}
    taken = []
    for key, where, dirs, size in runs:
        dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
        rng = np.random.default_rng(np.random.SeedSequence([ctx.seed, 0x3A95, zlib.crc32(key.encode())]))
        taken.append((key, where, np.sort(rng.choice(len(dirs), min(SAMPLE, len(dirs)), replace=False)), dirs,
                      tuple(size)))
    restart = getattr(ctx.lookups, "restart", None)     # in-process stand-ins have no process to restart
    if restart is not None:
        restart()
    out = {}
    for k, size in enumerate(sorted({t[4] for t in taken}, key=lambda hw: -hw[0] * hw[1])):
        ctx.lookups.set_faces(random_like(ctx.seed, size), same_process=k > 0)
        here = [t for t in taken if t[4] == size]
        # One recording, no second one in a fresh worker: a direction it
        # answers from memory makes no call, and is not compared.
        rec = fetch_record.record(ctx.lookups, np.concatenate([dirs[rows] for _k, _w, rows, dirs, _s in here]),
                                  fresh=False)
        start = 0
        for key, where, rows, dirs, _size in here:
            part = slice(start, start + len(rows))
            start += len(rows)
            out[key] = Sample(check, where, rows, dirs[rows], dataclasses.replace(
                rec, **{name: getattr(rec, name)[part] for name in ("values", "calls", "returned", "faces", "offsets",
                                                                    "uv")}))
    return out


def observe(ctx, taken: Sample, faces: np.ndarray, outcome) -> None:
    """Right after a run on `faces`, in its worker: the run's answers to the
    sampled directions against the student's readTexture called directly
    on the same faces at what fetchColor asked for on random faces of
    their size, bit for bit or through float (fetch_record.returned_as),
    where the tag came back there and (u, v) lies well inside the face
    (fetch_record.inside_face, read_again)."""
    face, uv = taken.record.request()
    answers = np.asarray(outcome.values, np.float64)[taken.rows]
    evaluated = np.asarray(outcome.evaluated, bool)[taken.rows]
    usable = np.flatnonzero((face >= 0) & fetch_record.inside_face(uv, faces.shape[2:0:-1]) & evaluated)
    same, read = fetch_record.read_again(ctx.lookups, face[usable], uv[usable], answers[usable])
    example = None
    if not same.all():
        k = fetch_record.first_differing(face[usable], same)
        i = usable[k]
        example = (taken.directions[i], answers[i], int(face[i]), float(uv[i, 0]), float(uv[i, 1]), read[k])
    ctx.map_probe().seen.append(Seen(taken.check, taken.where, len(usable), int((~same).sum()), example))


class RandomFaceRequests:
    """The submission's lookups as a check that looks up the public maps
    sees them, with fetchColor judged on what it asks for on random faces of
    each map's size: each fetch is recorded there (answered with tags), and a
    direction's colour is the handout's readTexture on the faces the check
    set (a public map) at the face and (u, v) of the call whose answer
    fetchColor returned, or of its first call where it returned none as it
    came. A direction with no readTexture call, or none at a face's start,
    is black: what it reads on other faces says nothing about the map.
    fetchColor never sees a public texel here."""

    def __init__(self, lookups, seed: int):
        self.inner, self.seed = lookups, seed
        self.faces = None

    def set_faces(self, faces, same_process: bool = False) -> None:
        self.faces = np.asarray(faces)
        self.inner.set_faces(random_like(self.seed, self.faces.shape[1:3]), same_process=same_process)

    def restart(self) -> None:
        self.inner.restart()

    def reset_failure_budget(self) -> None:
        reset = getattr(self.inner, "reset_failure_budget", None)
        if reset is not None:
            reset()

    def fetch(self, dirs: np.ndarray, placement: str = "end"):
        rec = fetch_record.record(self.inner, dirs)
        n = len(rec.calls)
        k = np.minimum(np.where(rec.returned >= 0, rec.returned, 0), fetch_record.RECORDED_CALLS - 1)
        face = np.where(rec.calls >= 1, rec.faces[np.arange(n), k], -1)
        values = fetch_record.handout_read(self.faces, face, rec.uv[np.arange(n), k])
        values[(rec.calls >= 0) & (face < 0)] = 0.0
        outcome = rec.outcome
        return dataclasses.replace(outcome, values=values, evaluated=np.asarray(outcome.evaluated, bool) & (rec.calls >= 0))
