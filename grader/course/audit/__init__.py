"""The audit of the grader itself: how many wrong lookups does a rubric let through?

Mutation analysis (`python -m grader audit`): the course's correct solutions
are changed one token at a time (mutants.py); each mutant's truth is decided
by brute force against the reference, independently of the checks (truth.py);
then the mutants are graded as a class with the course's rubric (grading.py);
the report (report.py) says which wrong mutants got full marks (escaped),
which equivalent ones were marked down (false fails), and what each check
alone catches.

The unchanged solutions are judged and graded too, as controls: the truth
must call each equivalent and the grader give it full marks, or the audit's
figures mean nothing (the report says so first).
"""
from __future__ import annotations

import os
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path

from ... import PROJECT_ROOT
from ...grading import score
from .grading import Graded, check_points, grade_folder
from .mutants import Mutant, all_mutants, sample, solution_name, solution_source
from .truth import NOT_COMPILING, UNJUDGED, Truth, truth_of

DEFAULT_SOLUTIONS = (PROJECT_ROOT / "examples" / "perfect",
                     *sorted((PROJECT_ROOT / "tests" / "submissions" / "correct").glob("*.cpp")))


@dataclass
class Audited:
    """One mutant (or control) with its truth and its grade (None when not graded)."""
    mutant: Mutant | None
    name: str                 # the mutant's id, or the control's solution name
    truth: Truth
    graded: Graded | None = None


@dataclass
class AuditResult:
    mutants: list[Audited]
    controls: list[Audited]
    rubric: Path
    checks: dict[str, float]                       # the rubric's points per check
    settings: dict = field(default_factory=dict)   # seed, counts, quick, jobs
    seconds: dict[str, float] = field(default_factory=dict)   # per phase


def _pool(jobs: int):
    import concurrent.futures as futures
    import multiprocessing
    return futures.ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("spawn"))


def _judge_all(paths: dict[str, Path], jobs: int, sandbox, allow_unsafe: bool, progress: bool) -> dict[str, Truth]:
    truths: dict[str, Truth] = {}
    bar = _Bar(progress, "judging", len(paths))
    with _pool(jobs) as pool:
        pending = {pool.submit(truth_of, path, sandbox, allow_unsafe): name for name, path in paths.items()}
        import concurrent.futures as futures
        for done in futures.as_completed(pending):
            try:
                truths[pending[done]] = done.result()
            except Exception as e:   # the harness failed on this one: listed, never dropped, never a verdict
                truths[pending[done]] = Truth(UNJUDGED, example=f"{type(e).__name__}: {e}"[:300])
            bar.advance()
    bar.close()
    return {name: truths[name] for name in paths}


def run_audit(solutions: list[Path] | None = None, *, mutants: int | None = 200, seed: int = 0,
              jobs: int | None = None, out: Path | None = None, rubric: Path | None = None, quick: bool = False,
              sandbox: bool | None = None, allow_unsafe: bool = False, allow_stale: bool = False,
              progress: bool = True, chosen: list[Mutant] | None = None) -> AuditResult:
    """Audit the grader on mutants of `solutions` (default: the course's
    correct ones): `mutants` of them drawn with `seed` (None: all), or exactly
    `chosen`. Everything is written under `out` (mutant sources, the grading
    of each, audit.json, audit.html). Raises score.RubricError for a bad
    rubric and grader.grading.fixtures.StaleFixtures, before any work."""
    rubric = Path(rubric or score.RUBRIC).resolve()
    checks = check_points(rubric)                     # raises RubricError, before any work
    if not allow_stale:
        from ...grading.fixtures import check_stale
        check_stale()
    solutions = [Path(s) for s in (solutions or DEFAULT_SOLUTIONS)]
    for s in solutions:
        if not solution_source(s).is_file():
            raise FileNotFoundError(f"{s}: not a .cpp file or a folder with EnvironmentMap.cpp")
    jobs = max(1, jobs or os.cpu_count() or 1)
    out = Path(out or PROJECT_ROOT / "out" / "audit")
    began = time.monotonic()
    every = all_mutants(solutions)
    picked = list(chosen) if chosen is not None else sample(every, mutants, seed)
    seconds = {"enumerate": time.monotonic() - began}

    # Sources on disk: the build and grade-all take files. Controls first.
    sources = out / "sources"
    shutil.rmtree(sources, ignore_errors=True)
    sources.mkdir(parents=True)
    paths: dict[str, Path] = {}
    controls, texts = [], set()
    for s in solutions:
        name, text = "control-" + solution_name(s), solution_source(s).read_text()
        if name in paths or text in texts:   # the same solution twice (idiomatic.cpp is examples/perfect)
            continue
        texts.add(text)
        paths[name] = sources / f"{name}.cpp"
        paths[name].write_text(text)
        controls.append(name)
    for m in picked:
        paths[m.id] = sources / f"{m.id}.cpp"
        paths[m.id].write_text(m.source)

    t = time.monotonic()
    truths = _judge_all(paths, jobs, sandbox, allow_unsafe, progress)
    seconds["truth"] = time.monotonic() - t

    # Grade what compiled (a file that does not compile scores 0 by construction).
    to_grade = out / "graded-sources"
    shutil.rmtree(to_grade, ignore_errors=True)
    to_grade.mkdir(parents=True)
    for name, truth in truths.items():
        if truth.klass not in (NOT_COMPILING, UNJUDGED):
            shutil.copyfile(paths[name], to_grade / paths[name].name)
    t = time.monotonic()
    options = {"sandbox": sandbox, "quick": quick, "allow_stale": True, "allow_unsafe": allow_unsafe}
    graded = grade_folder(to_grade, out / "graded", rubric, jobs, options, progress) if any(to_grade.iterdir()) else {}
    seconds["grading"] = time.monotonic() - t
    seconds["total"] = time.monotonic() - began

    by_id = {m.id: m for m in picked}
    result = AuditResult(
        mutants=[Audited(by_id[n], n, truths[n], graded.get(n)) for n in paths if n in by_id],
        controls=[Audited(None, n, truths[n], graded.get(n)) for n in controls],
        rubric=rubric, checks=checks,
        settings={"seed": seed, "requested": mutants, "available": len(every), "sampled": len(picked),
                  "solutions": [solution_name(s) for s in solutions], "quick": quick, "jobs": jobs,
                  "cpus": os.cpu_count()},
        seconds={k: round(v, 2) for k, v in seconds.items()})
    from .report import write_reports
    write_reports(result, out)
    return result


class _Bar:
    """A rich progress bar on stderr, or nothing."""

    def __init__(self, enabled: bool, label: str, total: int):
        self.bar = None
        if enabled:
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
            self.bar = Progress(TextColumn(label), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                                console=Console(stderr=True))
            self.bar.__enter__()
            self.task = self.bar.add_task("", total=total)

    def advance(self) -> None:
        if self.bar:
            self.bar.update(self.task, advance=1)

    def close(self) -> None:
        if self.bar:
            self.bar.__exit__(None, None, None)
