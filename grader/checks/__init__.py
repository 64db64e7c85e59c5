"""The grading checks: one module per rubric entry.

Each check is a function `run(ctx) -> CheckResult` registered with @check,
check50 style: its docstring's first line is the sentence the student reads,
and its dependencies are declared, so a check whose prerequisite failed is
skipped with a reason instead of piling up errors. Points, partial credit and
visibility live in grader/rubric.toml, not here.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Callable

from ..results import CheckResult


@dataclass(frozen=True)
class Check:
    name: str
    title: str
    run: Callable[..., CheckResult]
    depends: tuple[str, ...] = ()


REGISTRY: dict[str, Check] = {}

# Modules holding checks, in the order they run and appear in reports.
MODULES = ("read_texture", "sweeps", "diagnosis", "arrows", "stability", "renders", "speed")


def check(name: str, depends: tuple[str, ...] = ()):
    def register(fn):
        title = (fn.__doc__ or name).strip().splitlines()[0]
        REGISTRY[name] = Check(name, title, fn, depends)
        return fn
    return register


def all_checks() -> list[Check]:
    for module in MODULES:
        importlib.import_module(f"{__name__}.{module}")
    return list(REGISTRY.values())
