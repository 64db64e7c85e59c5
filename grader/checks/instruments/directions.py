"""The direction sets the fetchColor checks sweep.

Every set is a named (n, 3) float64 array. The deterministic sets cover what
matters for a cube map: the whole sphere evenly (Fibonacci), each face on a
grid, every edge and corner exactly (ties), the axes, and lengths far from
1. The random set is seeded per grading run (grader.checks.context), so
expected outputs cannot be memorised; points are decided on the others.
"""
from __future__ import annotations

import itertools

import numpy as np

from ...i18n import N_

GOLDEN_ANGLE = np.pi * (3.0 - np.sqrt(5.0))


def fibonacci_sphere(n: int) -> np.ndarray:
    """n nearly uniform unit directions (the Fibonacci lattice)."""
    i = np.arange(n, dtype=np.float64)
    z = 1.0 - (2.0 * i + 1.0) / n
    r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    phi = i * GOLDEN_ANGLE
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def face_grids(k: int) -> np.ndarray:
    """A k x k grid of face-plane points on each of the six faces (cube surface
    points, so the major component is exactly 1), open interval (-1, 1)."""
    t = (np.arange(k) + 0.5) / k * 2.0 - 1.0
    a, b = np.meshgrid(t, t, indexing="ij")
    a, b = a.ravel(), b.ravel()
    one = np.ones_like(a)
    out = []
    for axis in range(3):
        for sign in (1.0, -1.0):
            d = np.empty((len(a), 3))
            others = [i for i in range(3) if i != axis]
            d[:, axis] = sign * one
            d[:, others[0]] = a
            d[:, others[1]] = b
            out.append(d)
    return np.concatenate(out)


def axes() -> np.ndarray:
    return np.concatenate([np.eye(3), -np.eye(3)])


def corners() -> np.ndarray:
    """The 8 cube corners: three-way ties."""
    return np.array(list(itertools.product((1.0, -1.0), repeat=3)))


def edges(k: int) -> np.ndarray:
    """k points along each of the 12 edges (two-way ties), corners excluded."""
    t = (np.arange(k) + 0.5) / k * 2.0 - 1.0
    out = []
    for free in range(3):
        tied = [i for i in range(3) if i != free]
        for s0, s1 in itertools.product((1.0, -1.0), repeat=2):
            d = np.zeros((k, 3))
            d[:, free] = t
            d[:, tied[0]] = s0
            d[:, tied[1]] = s1
            out.append(d)
    return np.concatenate(out)


def scaled(dirs: np.ndarray, exponents=(-30, -10, -3, 3, 10, 30)) -> np.ndarray:
    """The same directions at lengths 10^e: the answer must not depend on length."""
    return np.concatenate([dirs * 10.0 ** e for e in exponents])


def random_directions(n: int, seed: int) -> np.ndarray:
    """n random unit directions from a seeded generator."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


# The one set drawn per grading run: judged and shown, never scored on its own
# (grader.checks.sweeps says why).
RANDOM_SET = N_("random (this run)")
# The deterministic set it is held to: both are even over the sphere.
FIBONACCI_SET = N_("Fibonacci sphere")


def sweep_sets(seed: int, fibonacci: int = 100_000) -> dict[str, np.ndarray]:
    """Every set the sweep check runs, by name (the names appear in reports,
    read out with grader.i18n._; the English names are the keys)."""
    return {
        FIBONACCI_SET: fibonacci_sphere(fibonacci),
        N_("face grids"): face_grids(24),
        N_("axes"): axes(),
        N_("edges (ties)"): edges(16),
        N_("corners (ties)"): corners(),
        N_("lengths 1e-30 to 1e30"): scaled(fibonacci_sphere(500)),
        RANDOM_SET: random_directions(20_000, seed),
    }


def tied_axes(dirs: np.ndarray, relative: float = 2.0 ** -20) -> np.ndarray:
    """(n, 3) bool: the components whose magnitude is within `relative` of the
    largest. Two or more True means the direction is on (or within float32
    rounding of) an edge or corner, where every touching face is correct.
    2^-20 covers a student computing in float (2^-24) with a margin."""
    a = np.abs(dirs)
    m = a.max(axis=1, keepdims=True)
    return a >= m * (1.0 - relative)
