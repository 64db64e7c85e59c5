"""A fake submission whose readTexture is a member of the model family
(grader.checks.instruments.texture_model) and whose fetchColor has chosen mistakes,
composed the way a student's code is: fetchColor's (face, u, v) go through
the fake's own readTexture. No compiler, no worker.

    ModelLookups(texture=TextureModel(...), fetch={"+X": "u-flipped"})
    ModelLookups(fetch="float")              # components through float
"""
from __future__ import annotations

import numpy as np

from grader.envmap import library
from grader.checks.instruments import texture_model as tm
from grader.worker.runner import Failure, Outcome

FACES = library.FACE_NAMES

UV_MISTAKES = {
    "u-flipped": lambda uv: np.stack([1 - uv[:, 0], uv[:, 1]], 1),
    "v-flipped": lambda uv: np.stack([uv[:, 0], 1 - uv[:, 1]], 1),
    "uv-swapped": lambda uv: uv[:, ::-1].copy(),
    "u-squared": lambda uv: np.stack([uv[:, 0] ** 2, uv[:, 1]], 1),     # no candidate does this
}


class ModelLookups:
    def __init__(self, texture: tm.TextureModel = tm.HANDOUT, fetch: dict[str, str] | str | None = None):
        self.model, self.fetch_mistakes = texture, fetch or {}
        self.faces = np.zeros((6, 1, 1, 3), np.float32)

    def set_faces(self, faces, same_process=False):
        self.faces = np.asarray(faces, np.float32)

    def _outcome(self, values, describe) -> Outcome:
        ok = np.isfinite(values).all(axis=1)
        failures = [Failure("out-of-bounds-read", "x", int(i), describe(int(i)), "read past the face", "")
                    for i in np.flatnonzero(~ok)[:16]]
        return Outcome(values=np.where(ok[:, None], values, np.nan), evaluated=ok, failures=failures)

    def read_texture(self, face, uv, placement="end"):
        values = tm.evaluate(self.model, self.faces[face], uv)[0]
        return self._outcome(values, lambda i: f"readTexture(face {FACES[face]}, {uv[i]})")

    def _face_uv(self, dirs):
        dirs = np.asarray(dirs, np.float64)
        mistake = self.fetch_mistakes if isinstance(self.fetch_mistakes, str) else None
        with np.errstate(all="ignore"):
            if mistake == "float":            # float x = direction.x, ...
                dirs = dirs.astype(np.float32).astype(np.float64)
            if mistake == "normalise-first":  # x / sqrt(x*x + y*y + z*z)
                dirs = dirs / np.sqrt((dirs ** 2).sum(axis=1))[:, None]
            face, uv = library.direction_to_face(np.nan_to_num(dirs, nan=0.0, posinf=0.0, neginf=0.0))
            bad = ~np.isfinite(dirs).all(axis=1) | (np.abs(dirs).max(axis=1) == 0)
        if mistake == "strict-ties":          # ties fall through to the z face
            a = np.abs(dirs)
            m = a.max(axis=1)
            tie = ((a == m[:, None]).sum(axis=1) >= 2) & (a[:, 2] < m)
            face = np.where(tie, np.where(dirs[:, 2] > 0, 4, 5), face)
            with np.errstate(all="ignore"):
                az = a[:, 2]
                u = (1 + dirs[:, 0] / az) / 2
                v = np.where(dirs[:, 2] > 0, (1 - dirs[:, 1] / az) / 2, (1 + dirs[:, 1] / az) / 2)
            uv = np.where(tie[:, None], np.stack([u, v], 1), uv)
        if isinstance(self.fetch_mistakes, dict):
            original = face.copy()
            for name, what in self.fetch_mistakes.items():
                rows = original == FACES.index(name)
                if what.startswith("wrong-face:"):
                    face = np.where(rows, FACES.index(what.split(":")[1]), face)
                else:
                    uv[rows] = UV_MISTAKES[what](uv[rows])
        return face, uv, bad

    def fetch(self, dirs, placement="end"):
        face, uv, bad = self._face_uv(dirs)
        values = np.full((len(face), 3), np.nan)
        ok = ~bad & (face >= 0)
        if ok.any():
            with np.errstate(invalid="ignore"):
                uvc = np.clip(np.nan_to_num(uv[ok], nan=0.5), -4, 5)
            values[ok] = tm.evaluate_in_buffer(self.model, self.faces, face[ok], uvc)[0]
        values[bad] = 0.0    # a guarded lookup returns black for the zero direction
        out = self._outcome(values, lambda i: f"fetchColor({dirs[i]})")
        return out

    def record_fetch(self, dirs, tags):
        """As the shim records it: one readTexture call at the model's face and (u, v) (fake_lookups.record_rows)."""
        from fake_lookups import record_rows
        face, uv, bad = self._face_uv(dirs)
        return record_rows(self.faces, face, uv, ~bad & (face >= 0), self.fetch(dirs).values, tags)

    def time_fetch(self, dirs, repeats=5):
        return 10.0, None
