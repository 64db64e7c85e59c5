"""Where the checks get the reference's answers: one small interface.

Every check asks the reference the same few questions: the lookup's (which
face and (u, v) a direction falls on, the handout's fetch and readTexture
over given texels) and the renderer's (a map's faces, a scene's camera paths,
the image they resolve to). In the grader the answers come from the live C
reference (`LiveReference`). The student kit cannot hold the lookup, so it
receives the lookup's answers instead: `Recorder` wraps the live reference
while the grader's own checks run on the kit's fixed public inputs at
kit-build time and keeps every lookup answer, keyed by a digest of the
question; `Replay` answers from that file in the kit. The renderer's answers
are computed in both places (`Renderer`: cross.c, rgbe.c, scene.c, render.c,
which the kit ships and builds; they depend on the submission's colours, or
are too large to record). A new check asks through `current()` and works in
both places without extra work.

A question the recording did not see (an input that depends on the
submission's answers, or a kit built from other inputs) raises
`MissingAnswer` naming it: the kit never guesses an answer.
"""
from __future__ import annotations

import contextlib
import hashlib
import io
import os
import zipfile
from pathlib import Path
from typing import Iterator, Protocol

import numpy as np

from . import library


class Oracle(Protocol):
    def direction_to_face(self, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...
    def fetch(self, texels: np.ndarray, dirs: np.ndarray, filter: str = "bilinear") -> np.ndarray: ...
    def read_texture(self, texels: np.ndarray, faces, uv: np.ndarray, filter: str = "bilinear") -> np.ndarray: ...
    def load_cross(self, path: str | os.PathLike) -> np.ndarray: ...
    def trace(self, scene: str | os.PathLike, size: tuple[int, int], spp: int) -> library.Escapes: ...
    def resolve(self, escapes: library.Escapes, rgb: np.ndarray) -> np.ndarray: ...


class Renderer:
    """The renderer's questions, computed by the C library (no lookup in them)."""

    def load_cross(self, path):
        return library.CubeMap.load_cross(path).faces

    def trace(self, scene, size, spp):
        loaded = library.Scene.load(scene)
        loaded.set_resolution(*size)
        loaded.set_samples(spp)
        return loaded.trace()

    def resolve(self, escapes, rgb):
        return escapes.resolve(rgb)


class LiveReference(Renderer):
    """The C reference (grader.envmap.library), exactly as the checks called it before."""

    def direction_to_face(self, dirs):
        return library.direction_to_face(dirs)

    def fetch(self, texels, dirs, filter="bilinear"):
        return library.CubeMap(texels).fetch(dirs, filter)

    def read_texture(self, texels, faces, uv, filter="bilinear"):
        return library.CubeMap(texels).read_texture(faces, uv, filter)


def _digest(method: str, *parts) -> str:
    """A question's key: the method and the exact bytes, dtype and shape of
    each argument."""
    h = hashlib.sha256(method.encode())
    for part in parts:
        a = np.ascontiguousarray(part)
        h.update(f"|{a.dtype.str}{a.shape}|".encode())
        h.update(a.tobytes())
    return h.hexdigest()[:32]


class MissingAnswer(LookupError):
    """The recorded answers hold nothing for this question."""


def _question(method: str, args: tuple) -> str:
    if method in ("fetch", "read_texture"):
        texels, *rest = args
        return _digest(method, np.ascontiguousarray(texels, np.float32), *rest)
    return _digest(method, *args)


def _pack(answer) -> tuple[np.ndarray, ...]:
    return tuple(answer) if isinstance(answer, tuple) else (answer,)


class _ByQuestion:
    """The lookup's questions in one normal form, each handed to `_respond`."""

    def direction_to_face(self, dirs):
        return self._respond("direction_to_face", np.ascontiguousarray(dirs, np.float64).reshape(-1, 3))

    def fetch(self, texels, dirs, filter="bilinear"):
        return self._respond("fetch", texels, np.ascontiguousarray(dirs, np.float64).reshape(-1, 3), filter)

    def read_texture(self, texels, faces, uv, filter="bilinear"):
        uv = np.ascontiguousarray(uv, np.float64).reshape(-1, 2)
        return self._respond("read_texture", texels, np.asarray(np.broadcast_to(faces, (len(uv),)), np.int32), uv, filter)


class Recorder(_ByQuestion):
    """An oracle that asks `inner` and keeps every lookup answer (for the kit)."""

    def __init__(self, inner: Oracle):
        self.inner = inner
        self.answers: dict[str, tuple[np.ndarray, ...]] = {}

    def _respond(self, method, *args):
        answer = getattr(self.inner, method)(*args)
        self.answers.setdefault(f"{method}:{_question(method, args)}", _pack(answer))
        return answer

    def load_cross(self, path):
        return self.inner.load_cross(path)

    def trace(self, scene, size, spp):
        return self.inner.trace(scene, size, spp)

    def resolve(self, escapes, rgb):
        return self.inner.resolve(escapes, rgb)

    def save(self, path: Path) -> None:
        """One .npz: each answer's arrays as `<method>:<digest>/<i>.npy`,
        byte-stable (fixed member times, unlike np.savez: the kit's zip is
        reproducible)."""
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
            for key, parts in self.answers.items():
                for i, a in enumerate(parts):
                    member = io.BytesIO()
                    np.lib.format.write_array(member, np.ascontiguousarray(a), allow_pickle=False)
                    z.writestr(zipfile.ZipInfo(f"{key}/{i}.npy", date_time=(2026, 1, 1, 0, 0, 0)),
                               member.getvalue(), zipfile.ZIP_DEFLATED)


class Replay(_ByQuestion, Renderer):
    """An oracle that answers the lookup's questions only from a Recorder's file."""

    def __init__(self, path: Path):
        self.answers: dict[str, list[np.ndarray]] = {}
        with np.load(path) as data:
            for name in sorted(data.files, key=lambda n: (n.rsplit("/", 1)[0], int(n.rsplit("/", 1)[1]))):
                self.answers.setdefault(name.rsplit("/", 1)[0], []).append(data[name])

    def _respond(self, method, *args):
        key = f"{method}:{_question(method, args)}"
        if key not in self.answers:
            raise MissingAnswer(f"no recorded reference answer for {method} on these inputs "
                                f"(the kit answers only its own fixed public inputs)")
        arrays = [a.copy() for a in self.answers[key]]
        return tuple(arrays) if len(arrays) > 1 else arrays[0]


_current: list[Oracle] = [LiveReference()]


def current() -> Oracle:
    """The oracle the checks ask now (the live reference unless `using` says otherwise)."""
    return _current[-1]


@contextlib.contextmanager
def using(oracle: Oracle) -> Iterator[Oracle]:
    """Ask `oracle` inside the block (the kit's Replay, the kit build's Recorder)."""
    _current.append(oracle)
    try:
        yield oracle
    finally:
        _current.pop()
