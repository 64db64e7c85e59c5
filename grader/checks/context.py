"""What every check receives: the submission's isolated lookups, the seed of
this grading run, and where to put pictures. What one check tells another
travels as its typed return value (grader.checks: `requires`), not here.

`SubmissionLookups` is the shape of grader.worker's runner as the checks use
it: each call returns an Outcome whose failed inputs have NaN rows and a
Failure each (crash, timeout, out-of-bounds read, ...), already narrowed down
to the input that caused it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from ..i18n import _
from ..grading.results import Diagnosis
from ..worker.failures import KINDS, TIMEOUT
from .instruments import map_probe, process_state
from .instruments.process_state import set_faces_after_another_size

# failure_diagnoses' ids: a worker failure's kind is its diagnosis id.
DIAGNOSIS_IDS = KINDS


class SubmissionLookups(Protocol):
    # same_process: in the running worker if they fit (grader.worker.runner)
    def set_faces(self, faces: np.ndarray, same_process: bool = False) -> None: ...
    def fetch(self, dirs: np.ndarray) -> Any: ...
    def read_texture(self, face: int, uv: np.ndarray, placement: str = "end") -> Any: ...
    # fetchColor with readTexture's calls recorded (grader.checks.instruments.fetch_record)
    def record_fetch(self, dirs: np.ndarray, tags: np.ndarray | None) -> Any: ...
    def restart(self) -> None: ...    # the next call in a fresh worker (no state carried over)
    # run_checks, before each check, where the lookups have it (grader.worker.runner)
    def reset_failure_budget(self) -> None: ...
    def time_fetch(self, passes: list[np.ndarray], repeats: int = 1) -> Any: ...    # grader.worker.runner.TimedPasses


@dataclass
class CheckContext:
    lookups: SubmissionLookups
    seed: int                         # per submission and course secret: reproducible, not guessable
    artifacts: Path                   # folder for this submission's pictures
    quick: bool = False               # smaller sets (tests of the harness itself)
    settings: dict[str, dict] = field(default_factory=dict)  # the rubric's entry per check
    # run_checks sets it to run an end-to-end check again in the other state
    # (instruments.process_state): each lookup in a fresh worker whose first faces they are.
    first_faces: bool = False
    _states: Any = None
    _maps: Any = None

    def states(self):
        """fetchColor asked the same directions on the same faces in a process
        whose first faces they are and after faces of another size
        (instruments.process_state.StateProbe), probed once per grading."""
        if self._states is None:
            self._states = process_state.probe(self.lookups, self.seed)
        return self._states

    def map_probe(self):
        """What the runs on public maps were seen to answer against what
        fetchColor asks for on random faces of their size (instruments.map_probe), so far."""
        if self._maps is None:
            self._maps = map_probe.MapObservations()
        return self._maps

    def random_face_requests(self):
        """The lookups a check on the public maps sees when run_checks runs it
        again on what fetchColor asks for on random faces of each map's size
        (instruments.map_probe.RandomFaceRequests)."""
        return map_probe.RandomFaceRequests(self.lookups, self.seed)

    def artifact(self, name: str) -> Path:
        self.artifacts.mkdir(parents=True, exist_ok=True)
        return self.artifacts / name


def set_end_to_end_faces(ctx: CheckContext, faces: np.ndarray, largest: tuple[int, int] | None = None) -> None:
    """The faces an end-to-end check looks up on: after faces of another
    size (set_faces_after_another_size), or, when run_checks runs the check
    in the other state (ctx.first_faces), in a fresh worker whose first
    faces they are, as in a program that loads one map."""
    if ctx.first_faces:
        ctx.lookups.restart()
        ctx.lookups.set_faces(faces)
    else:
        set_faces_after_another_size(ctx.lookups, faces, largest)


def look_up_public_map(ctx: CheckContext, faces: np.ndarray, dirs: np.ndarray, largest: tuple[int, int] | None = None,
                       first: bool = True, sample=None):
    """fetchColor for `dirs` on a public map (the arrows', a render's), as
    a program looks it up: the first of a check's maps after faces of another
    size (`largest`: the largest map the check uses; process_state.prelude),
    the others in the same worker; held right after to `sample`
    (instruments.map_probe.sample_runs, taken before the check's runs). In
    the other state of run_checks (ctx.first_faces) each map goes to a fresh
    worker as its first faces."""
    if ctx.first_faces:
        ctx.lookups.restart()
        ctx.lookups.set_faces(faces)
        return ctx.lookups.fetch(dirs)
    if first:
        process_state.prelude(ctx.lookups, largest or faces.shape[1:3])
    ctx.lookups.set_faces(faces, same_process=True)
    outcome = ctx.lookups.fetch(dirs)
    if sample is not None:
        map_probe.observe(ctx, sample, faces, outcome)
    return outcome


def failure_diagnoses(failures, limit: int = 3) -> list[Diagnosis]:
    """One diagnosis per distinct failure kind (grader.worker.Failure), with
    the input that caused it. A failure's kind (grader.worker.failures.KINDS)
    is its diagnosis id: each has its own words in grader/grading/catalogue.py."""
    out, seen = [], set()
    for failure in failures:
        kind = failure.kind
        if kind in seen:
            continue
        seen.add(kind)
        # The hint travels separately: reports print it as what to do.
        stops = [f.grader_limit for f in failures if f.kind == TIMEOUT]
        out.append(Diagnosis(kind, _("%(input)s: %(message)s.") % {"input": failure.input, "message": failure.message},
                             hint=failure.hint,
                             stopped_by="" if kind != TIMEOUT else "grader" if any(stops) else "code"))
        if len(out) >= limit:
            break
    return out


def unique_diagnoses(diagnoses) -> list[Diagnosis]:
    """Diagnoses with repeats of the same id on the same face dropped, order kept."""
    seen, out = set(), []
    for d in diagnoses:
        if (d.id, d.face) not in seen:
            seen.add((d.id, d.face))
            out.append(d)
    return out
