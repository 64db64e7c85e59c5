"""The sweep's random set (issue 30): it scores nothing while it agrees with
the Fibonacci sphere, and it is the share when a fetchColor answers the
public directions better than others (tests/fake_lookups.py, in-process)."""
from __future__ import annotations

import numpy as np

from fake_lookups import FakeLookups
from grader.checks import all_checks, run_checks
from grader.checks.context import CheckContext
from grader.checks.instruments.directions import RANDOM_SET, sweep_sets
from grader.grading.results import FAILED


class KnowsThePublicSets(FakeLookups):
    """The handout's lookup on the fixed sets' directions, black elsewhere."""

    def __init__(self):
        super().__init__()
        from grader.checks.fetch_sweep import SECOND_SIZE_DIRECTIONS
        from grader.checks.instruments.directions import fibonacci_sphere
        known = np.concatenate([d for name, d in sweep_sets(0, fibonacci=20_000).items() if name != RANDOM_SET]
                               + [fibonacci_sphere(SECOND_SIZE_DIRECTIONS)])    # the second face size's fixed set
        self.known = {tuple(d) for d in known}

    def fetch(self, dirs, placement="end"):
        out = super().fetch(dirs, placement)
        dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
        out.values[[tuple(d) not in self.known for d in dirs]] = 0.0
        return out


def sweep(lookups, tmp_path, seed):
    checks = all_checks()
    ctx = CheckContext(lookups=lookups, seed=seed, artifacts=tmp_path, quick=True)
    return run_checks([checks["read_texture"], checks["fetch_sweep"]], ctx).results[1]


def test_the_random_set_scores_nothing_while_it_agrees(tmp_path):
    """Another draw, the same share: one face wrong scores alike under two seeds."""
    first, second = (sweep(FakeLookups(fetch={"+X": "u-flipped"}), tmp_path, seed) for seed in (1, 2))
    assert first.fraction == second.fraction < 1
    assert first.metrics["random_share"] != second.metrics["random_share"]
    assert "held to the Fibonacci sphere" in first.output


def test_answering_only_the_public_directions_is_scored_on_the_random_ones(tmp_path):
    result = sweep(KnowsThePublicSets(), tmp_path, 1)
    assert result.metrics["matched"] == result.metrics["cases"]          # every fixed direction right ...
    assert result.status == FAILED and result.fraction == result.metrics["random_share"] < 0.01   # ... counts for nothing
    assert "better than others" in result.output
