"""A fake submission: grader.checks.context.SubmissionLookups in-process,
over the reference library, with mistakes injected on purpose.

Checks run against it in milliseconds, with no compiler and no worker, so
each check can be unit-tested per mistake (tests/unit/checks/test_checks_unit.py). The
mistakes are written here from what each one *is* (the handout's (u, v) made
wrong), independently of the recognisers in grader/checks/, and they compose
the way a student's code does: fetchColor's (face, u, v) goes through the
fake's own readTexture.

    FakeLookups()                                         # a correct submission
    FakeLookups(texture="nearest")                        # readTexture mistake
    FakeLookups(fetch={"+X": "u-flipped"})                # fetchColor mistake on one face
    FakeLookups(fetch={"+X": "wrong-face:-X", "-X": "wrong-face:+X"})
    FakeLookups(fetch="not-normalized", texture="half-texel")
    FakeLookups(fetch="half-texel-u", texture="one-point")     # issue 18's attack
    FakeLookups(fetch="inset", texture="scrambled")             # nothing models readTexture
    FakeLookups(fetch="wraps-at-one")                           # u - floor(u) on every face
    FakeLookups(fetch="clamped-inward")                         # (u, v) clamped to [0.001, 0.999]
    FakeLookups(fetch="clamped-to-texel-centres")               # ... to [0.5/W, 1 - 0.5/W] x [0.5/H, 1 - 0.5/H]
"""
from __future__ import annotations

import numpy as np

from grader.envmap import library
from grader.worker.protocol import RECORD_ROW
from grader.worker.runner import Failure, Outcome

FACES = library.FACE_NAMES

# readTexture mistakes: (filter, (u, v) as the reference should read them).
TEXTURE_MISTAKES = {
    "correct": ("bilinear", lambda uv, w, h: uv),
    "nearest": ("nearest", lambda uv, w, h: uv),
    "half-texel": ("bilinear", lambda uv, w, h: np.clip(uv - [0.5 / w, 0.5 / h], 0, 1)),
    "size-minus-one": ("bilinear", lambda uv, w, h: uv * [(w - 1) / w, (h - 1) / h]),
    "u-flipped": ("bilinear", lambda uv, w, h: np.stack([1 - uv[:, 0], uv[:, 1]], 1)),
    "v-flipped": ("bilinear", lambda uv, w, h: np.stack([uv[:, 0], 1 - uv[:, 1]], 1)),
    "uv-swapped": ("bilinear", lambda uv, w, h: uv[:, ::-1]),
    # Reads one texel past the face where u or v is 1 (x1 = x0 + 1 unclamped):
    # the worker reports an out-of-bounds read there; elsewhere it is right.
    "out-of-bounds": ("bilinear", lambda uv, w, h: uv),
    "black": ("bilinear", lambda uv, w, h: uv),
    # The handout's except one answer, at (u, v) = (0.5, 0.5): black. No model
    # of the family reproduces it (issue 18's "unfittable" readTexture).
    "one-point": ("bilinear", lambda uv, w, h: uv),
    # Crashes whenever it is called on its own (fetchColor here reads texels itself).
    "crash-alone": ("bilinear", lambda uv, w, h: uv),
    # One texel, at a column scrambled by x -> 5x mod W: nothing like any model.
    "scrambled": ("nearest", lambda uv, w, h: np.stack([((np.floor(np.minimum(uv[:, 0] * w, w - 1)) * 5) % w + 0.5) / w,
                                                        uv[:, 1]], 1)),
}

# fetchColor mistakes per face, on the (u, v) the reference computes.
UV_MISTAKES = {
    "u-flipped": lambda uv: np.stack([1 - uv[:, 0], uv[:, 1]], 1),
    "v-flipped": lambda uv: np.stack([uv[:, 0], 1 - uv[:, 1]], 1),
    "uv-swapped": lambda uv: uv[:, ::-1],
}


class FakeLookups:
    def __init__(self, fetch: dict[str, str] | str | None = None, texture: str = "correct", ns_per_lookup: float = 10.0):
        if texture not in TEXTURE_MISTAKES:
            raise ValueError(f"unknown readTexture mistake {texture!r}: {sorted(TEXTURE_MISTAKES)}")
        self.fetch_mistakes = fetch or {}
        self.texture = texture
        self.ns_per_lookup = ns_per_lookup
        self.faces = np.zeros((6, 1, 1, 3), np.float32)
        self.isolation, self.warnings, self.calls = "fake", [], 0
        self._cube = library.CubeMap(self.faces)

    # ---- SubmissionLookups ------------------------------------------------

    def set_faces(self, faces: np.ndarray, same_process: bool = False) -> None:
        self.faces = np.ascontiguousarray(faces, dtype=np.float32)
        self._cube = library.CubeMap(self.faces)

    def read_texture(self, face: int, uv: np.ndarray, placement: str = "end") -> Outcome:
        self.calls += 1
        uv = np.asarray(uv, np.float64).reshape(-1, 2)
        faces = np.full(len(uv), face, np.int32)
        values, failed = self._read(faces, uv)
        if self.texture == "crash-alone":
            failed = np.ones(len(uv), bool)
        return self._outcome(values, failed, lambda i: f"readTexture(face {FACES[face]}, u = {uv[i, 0]!r}, v = {uv[i, 1]!r})",
                             "readTexture")

    def fetch(self, dirs: np.ndarray, placement: str = "end") -> Outcome:
        self.calls += 1
        dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
        if self.fetch_mistakes == "black":
            return self._outcome(np.zeros((len(dirs), 3)), np.zeros(len(dirs), bool), None, "fetchColor")
        faces, uv = self._requests(dirs)
        values, failed = self._read(faces, uv)
        # Degenerate directions: the reference returns *something*; keep it finite.
        values[~np.isfinite(dirs).all(axis=1) | ~dirs.any(axis=1)] = 0.0
        return self._outcome(values, failed, lambda i: "fetchColor(Vector3(" + ", ".join(map(repr, dirs[i])) + "))",
                             "fetchColor")

    def record_fetch(self, dirs: np.ndarray, tags: np.ndarray | None) -> Outcome:
        """The shim's recording: one readTexture call per direction, at the
        fake's (face, u, v), answered with tags[0] (tags None: the fake's
        readTexture) and returned; "black" and degenerate directions make no
        call and return black; with the "crash-alone" readTexture, or a
        subclass's own fetch, fetchColor reads the texels itself (no call)."""
        dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
        itself = self.fetch(dirs).values
        faces, uv = self._requests(dirs)
        calls = (np.isfinite(dirs).all(axis=1) & dirs.any(axis=1) & (self.fetch_mistakes != "black")
                 & (self.texture != "crash-alone") & (type(self).fetch is FakeLookups.fetch))
        return record_rows(self.faces, faces, uv, calls, itself, tags)

    def _requests(self, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The (face, u, v) this fake's fetchColor asks readTexture for."""
        faces, uv = library.direction_to_face(dirs)
        faces, uv = faces.copy(), uv.copy()
        mistakes = self.fetch_mistakes
        if mistakes == "inset":
            # 1.5 texels in from every border, on every face.
            size = np.array(self.faces.shape[2:0:-1], np.float64)
            uv = (1.5 + uv * (size - 3)) / size
        elif mistakes == "wraps-at-one":
            # u - floor(u): a coordinate of exactly 1 (on a cube edge) becomes 0.
            uv = uv - np.floor(uv)
        elif mistakes == "clamped-inward":
            uv = np.clip(uv, 0.001, 0.999)
        elif mistakes == "clamped-to-texel-centres":
            # Half a texel in from every border: a range that depends on the face size and the axis.
            size = np.array(self.faces.shape[2:0:-1], np.float64)
            uv = np.clip(uv, 0.5 / size, 1 - 0.5 / size)
        elif mistakes == "half-texel-u":
            # Half a texel off in u on every face.
            uv[:, 0] = uv[:, 0] + 0.5 / self.faces.shape[2]
        elif mistakes == "not-normalized":
            # Divided by the length instead of the major component's magnitude.
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                ratio = np.abs(dirs).max(axis=1) / np.linalg.norm(dirs, axis=1)
            uv = 0.5 + (uv - 0.5) * np.nan_to_num(ratio, nan=1.0)[:, None]
        elif isinstance(mistakes, dict):
            original = faces.copy()
            for name, mistake in mistakes.items():
                rows = original == FACES.index(name)
                if mistake.startswith("wrong-face:"):
                    faces[rows] = FACES.index(mistake.split(":", 1)[1])
                else:
                    uv[rows] = UV_MISTAKES[mistake](uv[rows])
        return faces, np.clip(uv, 0, 1)

    def time_fetch(self, passes: list[np.ndarray], repeats: int = 1):
        """grader.worker.runner.TimedPasses at ns_per_lookup, with the fake's
        colours (none for repeated passes, as the runner gives none)."""
        from grader.worker.runner import TimedPasses
        values = [self.fetch(p).values for p in passes] if repeats == 1 else []
        return TimedPasses(cpu_ns=[int(self.ns_per_lookup * len(p) * repeats) for p in passes],
                           lookups=[len(p) * repeats for p in passes], values=values)

    # ---- the fake readTexture ---------------------------------------------

    def _read(self, faces: np.ndarray, uv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        h, w = self.faces.shape[1:3]
        filter, transform = TEXTURE_MISTAKES[self.texture]
        values = self._cube.read_texture(faces, np.asarray(transform(uv, w, h), np.float64), filter)
        failed = np.zeros(len(uv), bool)
        if self.texture == "out-of-bounds":
            failed = (uv >= 1.0).any(axis=1)
        if self.texture == "black":
            values[:] = 0.0
        if self.texture == "one-point":
            values[(uv == 0.5).all(axis=1)] = 0.0
        return values, failed

    def _outcome(self, values, failed, describe, function: str) -> Outcome:
        values = np.array(values, np.float64)
        values[failed] = np.nan
        failures = [Failure("out-of-bounds-read", function, int(i), describe(int(i)),
                            "out-of-bounds read (SIGSEGV): right after the face's last texel",
                            "Clamp x1 and y1 to the face as well as x0 and y0.")
                    for i in np.flatnonzero(failed)[:4]]
        return Outcome(values=values, evaluated=~failed, failures=failures, gave_up=bool(failed.sum() > 4))


def record_rows(texels: np.ndarray, faces: np.ndarray, uv: np.ndarray, calls: np.ndarray, itself: np.ndarray,
                tags: np.ndarray | None) -> Outcome:
    """RECORD_FETCH's rows (grader.worker.protocol) for a fetchColor that
    makes one readTexture call at (faces[i], uv[i]) where calls[i], and
    returns its answer (tags[0], or itself[i] when tags is None: the
    answer of the fake's own readTexture); elsewhere no call and itself[i]."""
    rows = np.full((len(faces), RECORD_ROW), np.nan)
    h, w = texels.shape[1:3]
    answer = itself if tags is None else np.broadcast_to(np.asarray(tags, np.float64)[0], itself.shape)
    rows[:, :3] = np.where(calls[:, None], answer, itself)
    rows[:, 3] = calls
    rows[:, 4] = np.where(calls, 0, -1)
    rows[calls, 5] = faces[calls]
    rows[calls, 6] = faces[calls] * (w * h * 3)
    rows[calls, 7:9] = uv[calls]
    return Outcome(values=rows, evaluated=np.ones(len(faces), bool))
