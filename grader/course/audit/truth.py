"""What a mutant really does: compared with the reference densely,
independently of the grader's checks.

The mutant is built as the grader builds a submission (grader.build) and run
in the grader's isolated worker (grader.worker.runner), which places the faces
against guard pages, so a read outside a face is reported (as a crash) and
not silently answered. Its answers are compared with the C reference
(grader.envmap.library) on random textures, where every texel differs from its
neighbours, so that any wrong index, weight or face shows:

    ordinary     fetchColor over the whole sphere, a dense (u, v) grid and every
                 lattice point of each face, near every edge and corner (1e-2
                 to 1e-5 inside), with both guard placements; readTexture on
                 every face over a grid with u, v = 0 and 1 and the lattice
    ties         directions exactly on edges and corners, and one ulp off them
    extreme      lengths from 1e-310 to 1e308
    degenerate   zero, NaN and infinite components (any answer; no failure)
    non-square   the same on W x H faces with W != H, and on 1 x 1 faces

Wherever components tie (or are within NEAR_TIE of the largest, where float
rounding may pick either) every touching face's colour is accepted
(docs/assignment.md); that colour is the reference's readTexture at the point
where the direction meets that face (grader.envmap.geometry's face frames).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field
from functools import cache
from pathlib import Path

import numpy as np

from ...envmap.library import CubeMap
from ...envmap.geometry import face_frames, face_uv_to_direction

# Classes, in the order reports list them.
EQUIVALENT = "equivalent"
WRONG = "wrong"
WRONG_EXTREME = "wrong-extreme"
WRONG_TIES = "wrong-ties"
WRONG_NON_SQUARE = "wrong-non-square"
CRASHING = "crashing"
HANGING = "hanging"
NOT_COMPILING = "not-compiling"
UNJUDGED = "unjudged"           # the audit itself failed on it (a harness error): in no rate
CLASSES = (EQUIVALENT, WRONG, WRONG_EXTREME, WRONG_TIES, WRONG_NON_SQUARE, CRASHING, HANGING, NOT_COMPILING,
           UNJUDGED)
CLASS_WORDS = {EQUIVALENT: "equivalent", WRONG: "wrong", WRONG_EXTREME: "wrong only at extreme lengths",
               WRONG_TIES: "wrong only at ties", WRONG_NON_SQUARE: "wrong only on non-square or 1 x 1 faces",
               CRASHING: "crashing (or reading outside a face)", HANGING: "hanging",
               NOT_COMPILING: "not compiling", UNJUDGED: "not judged (the audit failed on it)"}
# Mutants whose behaviour differs from the reference: the grader must mark them down.
BEHAVIOUR_CHANGING = frozenset({WRONG, WRONG_EXTREME, WRONG_TIES, WRONG_NON_SQUARE, CRASHING, HANGING})

GROUPS = ("ordinary", "ties", "extreme", "degenerate", "non-square")
ONLY_IN = {"ties": WRONG_TIES, "extreme": WRONG_EXTREME, "non-square": WRONG_NON_SQUARE}

# Texels are random in [0, 1). Float rounding in a correct solution moves a
# colour by about W * 2^-24 (1e-6 here); a real mistake by at least a share
# of a texel step (about 0.3 on average): 1e-4 separates the two with room.
TOLERANCE = 1e-4
# Components within this relative distance of the largest count as tied:
# a float solution may choose either face there (float32's epsilon is 6e-8).
NEAR_TIE = 1e-6
SQUARE = (16, 16)                       # (W, H)
NON_SQUARE = ((16, 9), (9, 16), (1, 1), (3, 2))
SEED = 20261201                         # the probes' own: the same for every audit


@dataclass(frozen=True)
class Probe:
    group: str
    name: str
    faces: np.ndarray          # (6, H, W, 3)
    inputs: np.ndarray         # directions (n, 3) or (u, v) (n, 2)
    face: int | None = None    # readTexture's face; None: fetchColor
    placement: str = "end"     # the guard page after the faces ("end") or before them ("start")
    judged: bool = True        # False: only a failure counts (degenerate directions)


@dataclass
class Truth:
    klass: str
    groups: list[str] = field(default_factory=list)   # where it differs from the reference
    example: str = ""                                  # the first difference or failure, in words
    seconds: float = 0.0
    isolation: str = ""                                # how it ran: bubblewrap, privilege-drop, unsafe-none

    def to_json(self) -> dict:
        return asdict(self)


def _textures(rng, size) -> np.ndarray:
    w, h = size
    return rng.random((6, h, w, 3)).astype(np.float32)


def _uv_grid(w: int, h: int) -> np.ndarray:
    """(u, v): a grid through 0, 1 and every lattice line, and between them."""
    u = np.unique(np.concatenate([np.linspace(0, 1, 4 * w + 1), (np.arange(4 * w) + 0.37) / (4 * w)]))
    v = np.unique(np.concatenate([np.linspace(0, 1, 4 * h + 1), (np.arange(4 * h) + 0.61) / (4 * h)]))
    uu, vv = np.meshgrid(u, v)
    return np.stack([uu.ravel(), vv.ravel()], axis=1)


def _on_faces(uv: np.ndarray) -> np.ndarray:
    """Directions (major component +-1) through (u, v) on every face."""
    return np.concatenate([face_uv_to_direction(f, uv[:, 0], uv[:, 1], normalized=False) for f in range(6)])


def _sphere(rng, n: int) -> np.ndarray:
    d = rng.normal(size=(n, 3))
    return d * 10.0 ** rng.uniform(-1, 1, (n, 1))


def _near_borders(offsets=(1e-2, 1e-3, 1e-5)) -> np.ndarray:
    """Directions just inside every edge and corner of every face (none on an edge: those are ties)."""
    t = (np.arange(33) + 0.5) / 33
    uv = []
    for o in offsets:
        for a in t:
            uv += [(o, a), (1 - o, a), (a, o), (a, 1 - o)]
        for cu in (o, 1 - o):
            for cv in (o, 1 - o):
                uv.append((cu, cv))
    return _on_faces(np.array(uv))


def _ties() -> np.ndarray:
    """Exactly on the edges and corners, at three lengths, and one ulp off."""
    t = np.linspace(0, 1, 17)
    uv = np.array([(e, a) for e in (0.0, 1.0) for a in t] + [(a, e) for e in (0.0, 1.0) for a in t])
    exact = np.concatenate([_on_faces(uv) * s for s in (1.0, 0.3, 7.5)])
    moved = np.concatenate([np.nextafter(exact, np.inf), np.nextafter(exact, -np.inf)])
    return np.concatenate([exact, moved])


def _extreme(rng) -> np.ndarray:
    unit = rng.normal(size=(400, 3))
    unit /= np.linalg.norm(unit, axis=1, keepdims=True)
    scaled = np.concatenate([unit * s for s in (1e-310, 1e-300, 1e-150, 1e150, 1e300, 1e308)])
    mixed = np.array([[1e300, 1e-300, 0], [1e308, 1, 1], [1, -1e308, 1e308], [1e-300, 1e-300, 1],
                      [5e-324, 0, 0], [0, -5e-324, 0], [0, 0, 5e-324], [1e-310, -2e-310, 3e-310]])
    return np.concatenate([scaled, mixed])


def _degenerate() -> np.ndarray:
    nan, inf = np.nan, np.inf
    return np.array([[0, 0, 0], [-0.0, 0, -0.0], [nan, 0, 0], [0, nan, 1], [nan, nan, nan], [inf, 0, 0],
                     [0, -inf, 0], [inf, inf, inf], [-inf, inf, 1], [inf, nan, 1]], np.float64)


def _lattice(w: int, h: int) -> np.ndarray:
    """Every lattice point inside a face (u = i/W, v = j/H, 0 < i < W, 0 < j < H)."""
    uu, vv = np.meshgrid(np.arange(1, w) / w, np.arange(1, h) / h)
    return np.stack([uu.ravel(), vv.ravel()], axis=1)


@cache
def probes() -> tuple[Probe, ...]:
    rng = np.random.default_rng(SEED)
    square = _textures(rng, SQUARE)
    w, h = SQUARE
    grid = _uv_grid(w, h)
    inner = grid[(grid > 0).all(1) & (grid < 1).all(1)]
    out = [
        Probe("ordinary", "sphere", square, _sphere(rng, 6000)),
        Probe("ordinary", "face grid", square, _on_faces(inner)),
        Probe("ordinary", "lattice", square, _on_faces(_lattice(w, h))),
        Probe("ordinary", "near edges and corners", square, _near_borders()),
        Probe("ordinary", "sphere, guard before the faces", square, _sphere(rng, 3000), placement="start"),
    ]
    read_uv = np.concatenate([grid, rng.random((200, 2))])
    for face in range(6):
        for placement in ("end", "start"):
            out.append(Probe("ordinary", f"readTexture face {face}", square, read_uv, face, placement))
    out += [
        Probe("ties", "edges and corners", square, _ties()),
        Probe("extreme", "lengths 1e-310 to 1e308", square, _extreme(rng)),
        Probe("degenerate", "zero, NaN, infinite", square, _degenerate(), judged=False),
    ]
    for size in NON_SQUARE:
        faces = _textures(rng, size)
        sw, sh = size
        g = _uv_grid(sw, sh)
        label = f"{sw} x {sh}"
        out += [
            Probe("non-square", f"sphere, {label}", faces, _sphere(rng, 3000)),
            Probe("non-square", f"face grid, {label}", faces, _on_faces(g[(g > 0).all(1) & (g < 1).all(1)])),
            Probe("non-square", f"near edges, {label}", faces, _near_borders()),
            Probe("non-square", f"ties, {label}", faces, _ties()),
        ]
        uv = np.concatenate([g, rng.random((100, 2))])
        for face in (0, 3, 5):
            for placement in ("end", "start"):
                out.append(Probe("non-square", f"readTexture face {face}, {label}", faces, uv, face, placement))
    return tuple(out)


def acceptable_colours(cube: CubeMap, dirs: np.ndarray) -> np.ndarray:
    """(n, 4, 3): the reference's colour, then the colour on each face whose
    axis ties (within NEAR_TIE) with the largest component (NaN rows where not)."""
    dirs = np.asarray(dirs, np.float64)
    out = np.full((len(dirs), 4, 3), np.nan)
    out[:, 0] = cube.fetch(dirs)
    with np.errstate(invalid="ignore", over="ignore"):
        a = np.abs(dirs)
        m = a.max(axis=1)
        finite = np.isfinite(dirs).all(axis=1) & (m > 0)
    normal, u_axis, v_axis = face_frames()
    for axis in range(3):
        rows = np.flatnonzero(finite & (a[:, axis] >= m * (1 - NEAR_TIE)))
        if not len(rows):
            continue
        d = dirs[rows] / m[rows, None]
        face = 2 * axis + (d[:, axis] < 0)
        t = np.einsum("ij,ij->i", d, normal[face])
        uv = np.stack([(np.einsum("ij,ij->i", d, u_axis[face]) / t + 1) / 2,
                       (np.einsum("ij,ij->i", d, v_axis[face]) / t + 1) / 2], axis=1)
        uv = np.clip(uv, 0.0, 1.0)
        for f in np.unique(face):
            sel = face == f
            out[rows[sel], 1 + axis] = cube.read_texture(np.full(sel.sum(), f), uv[sel])
    return out


def _first_mismatch(actual: np.ndarray, acceptable: np.ndarray) -> int | None:
    with np.errstate(invalid="ignore"):
        err = np.abs(actual[:, None, :] - acceptable).max(axis=2)
    err = np.where(np.isnan(err), np.inf, err).min(axis=1)
    bad = np.flatnonzero(~(err <= TOLERANCE))
    return int(bad[0]) if len(bad) else None


def _describe(probe: Probe, i: int, actual: np.ndarray, expected: np.ndarray) -> str:
    where = (f"readTexture(face {probe.face}, u = {probe.inputs[i][0]!r}, v = {probe.inputs[i][1]!r})"
             if probe.face is not None else f"fetchColor({', '.join(repr(float(c)) for c in probe.inputs[i])})")
    fmt = lambda c: "(" + ", ".join(f"{x:.4g}" for x in c) + ")"   # noqa: E731
    return f"{probe.name}: {where} gave {fmt(actual[i])}, the reference {fmt(expected[i])}"


def judge(library: Path, sandbox: bool | None = None, allow_unsafe: bool = False) -> Truth:
    """The truth of one built submission: its class and where it differs."""
    from ...worker.lookups import MODES
    from ...worker.runner import SubmissionRunner
    all_probes = probes()
    runner = SubmissionRunner(library, all_probes[0].faces, sandbox=MODES[sandbox], timeout_s=1.0,
                              max_failures=1, max_timeouts=1, budget_s=30.0, allow_unsafe=allow_unsafe)
    with runner:
        truth = _judge_with(runner, all_probes, {})
        truth.isolation = runner.isolation
        return truth


def _judge_with(runner, all_probes: tuple[Probe, ...], differs: dict[str, str]) -> Truth:
    """Run the probes in order; stop at a failure or at a difference on ordinary inputs."""
    for probe in all_probes:
        if probe.group in differs and probe.group != "ordinary":
            continue   # this group is known to differ: its other probes change nothing
        runner.set_faces(probe.faces)
        cube = CubeMap(probe.faces)
        if probe.face is None:
            outcome = runner.fetch(probe.inputs, probe.placement)
        else:
            outcome = runner.read_texture(probe.face, probe.inputs, probe.placement)
        if outcome.failures or outcome.gave_up:
            failure = outcome.failures[0] if outcome.failures else None
            klass = HANGING if failure is None or failure.kind == "timeout" else CRASHING
            said = failure.describe() if failure else "gave up (the time budget ran out)"
            return Truth(klass, sorted(set(differs) | {probe.group}, key=GROUPS.index),
                         f"{probe.name}: {said}")
        if not probe.judged:
            continue
        if probe.face is None:
            acceptable = acceptable_colours(cube, probe.inputs)
        else:
            acceptable = cube.read_texture(np.full(len(probe.inputs), probe.face), probe.inputs)[:, None, :]
        bad = _first_mismatch(outcome.values, acceptable)
        if bad is not None:
            differs.setdefault(probe.group, _describe(probe, bad, outcome.values, acceptable[:, 0]))
            if probe.group == "ordinary":
                return Truth(WRONG, ["ordinary"], differs["ordinary"])
    if not differs:
        return Truth(EQUIVALENT)
    groups = sorted(differs, key=GROUPS.index)
    return Truth(ONLY_IN[groups[0]], groups, differs[groups[0]])


def truth_of(source: Path, sandbox: bool | None = None, allow_unsafe: bool = False) -> Truth:
    """Build `source` as the grader does, then judge it (runs in a pool process)."""
    import time
    from ...build import build_submission
    began = time.monotonic()
    build = build_submission(Path(source))
    if not build.ok:
        first = build.log.strip().splitlines()[0] if build.log.strip() else "did not build"
        truth = Truth(NOT_COMPILING, example=first[:300])
    else:
        truth = judge(build.library, sandbox, allow_unsafe)
    truth.seconds = round(time.monotonic() - began, 3)
    return truth
