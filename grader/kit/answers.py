"""The kit's reference answers: what the lookup answers on the kit's fixed
public inputs, recorded at kit-build time (grader.envmap.oracle.Recorder) by running
the grader's own checks with the kit's seed, so that the kit can run those
same checks (grader.envmap.oracle.Replay) without the lookup.

Almost every question a check asks depends on the seed alone (directions,
(u, v) points, textures), not on the submission's answers, so one run of a
submission answering as the handout does records them (read_texture's worked
cases come from footprints it measured already). tests/unit/envmap/test_oracle.py replays submissions the
recording never saw and finds every answer. Speed is left out (grader.kit.NOT_IN_KIT): it
times the live reference, which the kit cannot do.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..envmap import oracle
from ..grading import score
from ..checks import all_checks, run_checks
from ..checks.context import CheckContext
from ..worker.protocol import RECORD_ROW
from ..worker.runner import Outcome
from . import ANSWERS, KIT_SEED, NOT_IN_KIT  # noqa: F401 (grade --kit-inputs reads them here)


class _AsTheHandout:
    """SubmissionLookups answering as the handout (the reference), in-process:
    only the recording's driver, never a graded submission."""

    def __init__(self, ask: oracle.Oracle):
        self.ask, self.faces = ask, np.zeros((6, 1, 1, 3), np.float32)

    def set_faces(self, faces, same_process=False):
        self.faces = np.ascontiguousarray(faces, np.float32)

    def _outcome(self, values):
        values = np.asarray(values, np.float64)
        return Outcome(values=values, evaluated=np.ones(len(values), bool))

    def fetch(self, dirs, placement="end"):
        return self._outcome(oracle.LiveReference().fetch(self.faces, dirs))

    def read_texture(self, face, uv, placement="end"):
        return self._outcome(oracle.LiveReference().read_texture(self.faces, face, uv))

    def record_fetch(self, dirs, tags):
        """As grader/shim/reference_submission.c records: one call at the
        table's face and (u, v), its answer (the tag, or the handout's) returned."""
        dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
        live = oracle.LiveReference()
        faces, uv = live.direction_to_face(dirs)
        rows = np.full((len(dirs), RECORD_ROW), np.nan)
        seen = faces >= 0
        h, w = self.faces.shape[1:3]
        answer = (live.read_texture(self.faces, faces[seen], uv[seen]) if tags is None
                  else np.broadcast_to(np.asarray(tags, np.float64)[0], (int(seen.sum()), 3)))
        rows[:, :3] = 0.0
        rows[seen, :3] = answer
        rows[:, 3] = seen
        rows[:, 4] = np.where(seen, 0, -1)
        rows[seen, 5] = faces[seen]
        rows[seen, 6] = faces[seen] * (w * h * 3)
        rows[seen, 7:9] = uv[seen]
        return self._outcome(rows)

    def time_fetch(self, passes):      # pragma: no cover - speed is not in the kit
        raise NotImplementedError


def kit_checks() -> list:
    return [c for c in all_checks().values() if c.name not in NOT_IN_KIT]


def record(path: Path, artifacts: Path, seed: int = KIT_SEED, quick: bool = False) -> int:
    """Record the answers into `path` (.npz); returns how many questions.
    `quick`: the checks' smaller sets (tests)."""
    from ..envmap.geometry import face_frames
    face_frames.cache_clear()            # its probes are questions too
    recorder = oracle.Recorder(oracle.LiveReference())
    checks = kit_checks()
    with oracle.using(recorder):
        ctx = CheckContext(lookups=_AsTheHandout(recorder), seed=seed, artifacts=artifacts, quick=quick,
                           settings=score.load_rubric().get("checks", {}))   # as grader.grading.grade passes them
        run_checks(checks, ctx, [c.name for c in checks])
    recorder.save(path)
    return len(recorder.answers)
