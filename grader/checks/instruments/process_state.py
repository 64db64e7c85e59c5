"""Whether fetchColor answers the same in the two states a program meets:
in a process whose first faces these are (a program that loads one map),
and in one that looked up on faces of another size first (the state the
end-to-end checks look up in: set_faces_after_another_size, which shows a
size kept from the first call).

The same directions on the same faces, asked in both states: any answer
that differs (beyond float rounding) is observed, not inferred. Where one
does, run_checks runs each end-to-end check (arrows, stability, renders) in
both states and keeps the lower score, and the sweep judges its set on faces
of a second size in both: a lookup wrong until the face size
changes (tests/submissions/redteam4/wrong_until_the_faces_change.cpp) was
judged right by every end-to-end check, as they look up only after the
prelude.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...grading.results import Diagnosis
from ...i18n import _
from .compare import tolerance
from .directions import random_directions
from .textures import random_faces

PROBE_SIZE = 24          # texels per side of the probe's random faces
PROBE_DIRECTIONS = 2048
DIAGNOSIS_IDS = ("fetch-depends-on-earlier-faces",)


@dataclass(frozen=True)
class StateProbe:
    """Answers to the same directions on the same faces in both states."""
    directions: np.ndarray      # (n, 3)
    first: np.ndarray           # (n, 3): in a process whose first faces they were
    after: np.ndarray           # (n, 3): after a lookup on faces of another size
    compared: np.ndarray        # (n,) bool: answered in either state
    differ: np.ndarray          # (n,) bool: answered otherwise

    @property
    def depends(self) -> bool:
        return bool(self.differ.any())

    def diagnosis(self) -> Diagnosis:
        """The observation in numbers: how many differ, and one of them."""
        i = int(np.flatnonzero(self.differ)[0])
        d, a, b = self.directions[i], self.first[i], self.after[i]
        return Diagnosis(DIAGNOSIS_IDS[0], _(
            "%(n)d of %(total)d directions were answered otherwise in a program whose first faces they were "
            "than after a lookup on faces of another size, on the same %(size)d x %(size)d faces; e.g. "
            "fetchColor(Vector3(%(x).4f, %(y).4f, %(z).4f)) gave (%(a)s) first and (%(b)s) after. The sweep's set on "
            "faces of a second size and the arrows, stability and renders checks were judged in both states; "
            "the lower score counts.") % {
            "n": int(self.differ.sum()), "total": int(self.compared.sum()), "size": PROBE_SIZE,
            "x": d[0], "y": d[1], "z": d[2], "a": _rgb(a), "b": _rgb(b)})


# A direction no check asks (the first call, on faces of another size).
FIRST_CALL = np.array([[0.7071067811865476, 0.5772156649015329, -0.3141592653589793]])


def set_faces_after_another_size(lookups, faces: np.ndarray,
                                 largest: tuple[int, int] | None = None) -> None:
    """Set `faces` (6, H, W, 3) in a worker whose first lookup was on faces
    8 texels larger each way than `largest` (default: `faces`' own size): a
    size kept from the first call (a static, issue 29's pattern 12) shows in
    what follows, as in the sweep's second size. Faces no larger than
    `largest` can follow in the same worker (set_faces(..., same_process=True))."""
    prelude(lookups, largest or faces.shape[1:3])
    lookups.set_faces(faces, same_process=True)


def prelude(lookups, largest: tuple[int, int]) -> None:
    """A fresh worker whose first lookup was on faces 8 texels larger each
    way than `largest` (H, W): faces no larger follow in it."""
    h, w = largest
    restart = getattr(lookups, "restart", None)     # in-process stand-ins have no process to restart
    if restart is not None:
        restart()       # fresh even where the running worker's faces were as large
    lookups.set_faces(np.ones((6, h + 8, w + 8, 3), np.float32))
    lookups.fetch(FIRST_CALL)


def _rgb(c: np.ndarray) -> str:
    return ", ".join(f"{float(v):.4g}" for v in c)


def probe(lookups, seed: int) -> StateProbe:
    """Ask the same directions in a fresh worker whose first faces are the
    probe's, then after faces of another size (set_faces_after_another_size)."""
    faces = random_faces(PROBE_SIZE, PROBE_SIZE, int(np.random.SeedSequence([seed, 0x57A7E]).generate_state(1)[0]))
    dirs = random_directions(PROBE_DIRECTIONS, int(np.random.SeedSequence([seed, 0x57A7E, 1]).generate_state(1)[0]))
    restart = getattr(lookups, "restart", None)     # in-process stand-ins have no process to restart
    if restart is not None:
        restart()
    lookups.set_faces(faces)
    first = lookups.fetch(dirs)
    set_faces_after_another_size(lookups, faces)
    after = lookups.fetch(dirs)
    a, b = np.asarray(first.values, np.float64), np.asarray(after.values, np.float64)
    ran_first, ran_after = np.asarray(first.evaluated, bool), np.asarray(after.evaluated, bool)
    tol = float(tolerance(PROBE_SIZE, PROBE_SIZE, 1.0))
    with np.errstate(invalid="ignore"):
        same = ((np.abs(a - b) <= tol) | (np.isnan(a) & np.isnan(b))).all(axis=1)
    # Answered in one state and failed in the other differs too.
    return StateProbe(dirs, a, b, ran_first | ran_after, (ran_first & ran_after & ~same) | (ran_first ^ ran_after))
