"""Points from the rubric (grader/grading/rubric.toml) for checks that have run."""
from __future__ import annotations

import tomllib
from pathlib import Path

from ..checks import shown
from .results import ERROR, FAILED, GRADED, PASSED, SKIPPED, UNGRADABLE, GradeResult

RUBRIC = Path(__file__).with_name("rubric.toml")
VISIBILITIES = {"visible", "hidden", "after_due_date", "after_published"}
PARTIAL = {"fraction", "all"}


class RubricError(Exception):
    pass


def load_rubric(path: Path = RUBRIC, checks: dict | None = None) -> dict:
    """The rubric, validated against the checks (default: every registered
    check, grader.checks.all_checks()): a mistake in it is the instructor's,
    reported as such."""
    try:
        rubric = tomllib.loads(Path(path).read_text())
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise RubricError(f"{path}: {e}") from e
    language = rubric.get("grading", {}).get("language", "en")
    from ..i18n import LANGUAGES
    if language not in LANGUAGES:
        raise RubricError(f"{path}: grading.language must be one of {list(LANGUAGES)}")
    for name, entry in rubric.get("checks", {}).items():
        if not isinstance(entry.get("points"), (int, float)) or entry["points"] < 0:
            raise RubricError(f"{path}: checks.{name}.points must be a number >= 0")
        if entry.get("partial", "fraction") not in PARTIAL:
            raise RubricError(f"{path}: checks.{name}.partial must be one of {sorted(PARTIAL)}")
        if entry.get("visibility", "visible") not in VISIBILITIES:
            raise RubricError(f"{path}: checks.{name}.visibility must be one of {sorted(VISIBILITIES)}")
    if checks is None:
        from ..checks import all_checks
        checks = all_checks()
    check_names(rubric, checks, path)
    return rubric


def check_names(rubric: dict, checks: dict, path: Path | str = "rubric") -> None:
    """Every check has exactly one entry, and the rubric's order (the run
    order) lists each check after the checks it requires."""
    listed = list(rubric.get("checks", {}))
    unknown = [n for n in listed if n not in checks]
    if unknown:
        raise RubricError(f"{path}: {', '.join(f'checks.{n}' for n in unknown)} "
                          f"{'is not a check' if len(unknown) == 1 else 'are not checks'} "
                          f"(the checks are: {', '.join(sorted(checks))})")
    missing = [n for n in checks if n not in listed]
    if missing:
        raise RubricError(f"{path}: no entry for {', '.join(f'checks.{n}' for n in missing)}; every check needs "
                          "one (points = 0 and visibility = \"hidden\" to keep it out of the score)")
    position = {n: i for i, n in enumerate(listed)}
    for name in listed:
        for pre in checks[name].prerequisites:
            if position[pre] > position[name]:
                raise RubricError(f"{path}: checks.{name} requires checks.{pre}, which is listed after it; "
                                  f"checks run in the rubric's order, so move [checks.{pre}] above [checks.{name}]")


def apply(result: GradeResult, rubric: dict) -> GradeResult:
    """Fill in each check's points and the totals; a harness error anywhere
    makes the submission ungradable (never a zero charged to the student)."""
    entries = rubric.get("checks", {})
    for number, check in enumerate(result.checks, start=1):
        entry = entries.get(check.name, {})
        check.max_score = float(entry.get("points", 0))
        check.visibility = entry.get("visibility", "visible")
        check.tags = list(entry.get("tags", []))
        check.number = str(number)
        if check.status in (ERROR, SKIPPED):
            check.score = 0.0
            continue
        # Shares as the reports print them (grader.checks.shown): the numbers shown are the numbers used.
        if entry.get("partial", "fraction") == "all":
            found = 1.0 if check.fraction >= 1.0 and check.status != FAILED else 0.0
        else:
            found = shown(min(max(check.fraction, 0.0), 1.0))
        # What it found, times what its prerequisites let it earn (grader.checks.Needs.credit).
        credit = shown(min(max(check.credit, 0.0), 1.0))
        check.score = round(check.max_score * found * credit, 2)
        if credit < 1.0 and check.status == PASSED:
            check.status = FAILED       # not all its points: reports show it partial, the output says why
        if check.status == FAILED and check.score >= check.max_score > 0:
            # A failed check never shows full points: rounding made one wrong
            # direction of 126,662 (or six black axes) 30 / 30.
            check.score = round(max(check.max_score - 0.01, 0.0), 2)
    # The checks that were run (all of them, unless grading was restricted to
    # some, e.g. the visible ones): hidden points never enter a student's total.
    names = {c.name for c in result.checks} or set(entries)
    result.max_score = float(sum(float(e.get("points", 0)) for n, e in entries.items() if n in names))
    result.score = round(sum(c.score for c in result.checks), 2)
    if result.status == GRADED and any(c.status == ERROR for c in result.checks):
        result.status = UNGRADABLE
    return result
