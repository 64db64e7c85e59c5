"""Parametrized cases whose marks are chosen by case id, written beside the
cases: `cases(NAMES, slow={"a", "b"})`. A mark naming an id no case has
fails at collection, so a renamed case cannot slip into another tier."""
from __future__ import annotations

import pytest


def cases(values, ids=None, **marks: set[str]) -> list:
    """Each value as a pytest.param with id `ids(value)` (else `str(value)`,
    or the values joined with '-' for a tuple, unpacked into the argnames;
    a repeated id numbered as pytest numbers it), marked with every mark
    whose set holds its id."""
    values = list(values)
    names = [ids(v) if callable(ids) else "-".join(map(str, v)) if isinstance(v, tuple) else str(v) for v in values]
    # A name given twice is numbered in order, as pytest numbers it (crashing0, crashing1).
    numbered = [f"{n}{names[:i].count(n)}" if names.count(n) > 1 else n for i, n in enumerate(names)]
    params, seen = [], set()
    for value, case_id in zip(values, numbered):
        seen.add(case_id)
        chosen = [getattr(pytest.mark, name) for name, wanted in marks.items() if case_id in wanted]
        args = value if isinstance(value, tuple) else (value,)
        params.append(pytest.param(*args, marks=chosen, id=case_id))
    unknown = {case for wanted in marks.values() for case in wanted} - seen
    if unknown:
        raise ValueError(f"marks name cases that do not exist: {sorted(unknown)}")
    return params
