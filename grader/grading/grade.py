"""Grade one submission: build -> isolated worker -> checks -> score -> reports.

`grade()` always returns a GradeResult and always writes the reports, whatever
the submission does; a failure of the harness itself makes the result
"ungradable" (never a zero charged to the student). An instructor's problem
found before grading starts is raised as a typed error (StaleFixtures,
RubricError, SandboxUnavailable) for the command line to turn into an exit
status; library code never exits.
"""
from __future__ import annotations

import hashlib
import os
import time
from dataclasses import dataclass
from pathlib import Path

from . import score
from ..checks import Check, ordered_checks, run_checks
from ..checks.context import CheckContext
from .catalogue import CATALOGUE
from .results import BUILD_ERROR, FAILED, TIMEOUT, UNGRADABLE, CheckResult, Diagnosis, GradeResult


@dataclass
class GradeOptions:
    sanitize: bool = False          # AddressSanitizer build of the submission
    sandbox: bool | None = None     # None: use it when this machine supports it
    allow_stale: bool = False       # grade even when fixtures/ is stale
    quick: bool = False             # smaller direction sets (tests of the harness)
    rubric: Path = score.RUBRIC
    only: tuple[str, ...] = ()      # run only these checks
    include_hidden: bool = True     # reports show hidden checks (instructors); False for students
    allow_unsafe: bool = False      # run student code even when no sandbox is possible (grader.worker)
    lang: str | None = None         # students' language; None: the rubric's grading.language (grader.i18n)
    seed: int | None = None         # a fixed public seed instead of the secret's (the kit's inputs)


def run_seed(secret: str, source_sha256: str) -> int:
    """The seed of the random checks: reproducible for one submission, not
    guessable without the course secret."""
    digest = hashlib.sha256(f"{secret}\0{source_sha256}".encode()).digest()
    return int.from_bytes(digest[:8], "little") >> 1


def grade(submission: Path, out_dir: Path, options: GradeOptions | None = None, write_reports: bool = True) -> GradeResult:
    """Grade one submission (see the module docstring). Its workers and
    compilers are charged to one memory cgroup of its own where the machine
    offers one, and the grader's own process asks not to be the OOM
    killer's choice (grader/worker/memory.py)."""
    from ..worker import memory
    memory.protect_grader()
    with memory.grading_cgroup():
        return _grade(submission, out_dir, options, write_reports)


def _grade(submission: Path, out_dir: Path, options: GradeOptions | None, write_reports: bool) -> GradeResult:
    from ..build.compiler import HarnessBuildError
    from ..build import build_submission
    from ..intake import student_name
    options = options or GradeOptions()
    started = time.monotonic()
    submission = Path(submission)
    rubric = score.load_rubric(options.rubric)      # raises RubricError
    from ..i18n import choose, set_language
    set_language(choose(options.lang, rubric))
    result = GradeResult(submission=student_name(submission))
    checks = ordered_checks(rubric)                  # the rubric's order is the run order
    entries = rubric.get("checks", {})
    unknown = [n for n in options.only if n not in entries]
    if unknown:
        raise score.RubricError(f"no such check: {', '.join(unknown)} (the checks are: {', '.join(entries)})")
    selected = [c for c in checks if c.name in options.only] if options.only else checks

    if not options.allow_stale:
        from .fixtures import check_stale
        check_stale()                                # raises StaleFixtures; the CLI says what to run
    result.warnings += _environment_warnings()

    try:
        build = build_submission(submission, sanitize=options.sanitize)
    except HarnessBuildError as e:   # our own sources failed to build: not the student's fault
        result.status = UNGRADABLE
        from ..build.compiler import BuildConfinementError
        # Confinement: our files are open to the compiler's uid, so nothing of
        # the student's was built; its message says what to close.
        result.warnings.append(str(e) if isinstance(e, BuildConfinementError)
                               else f"The grader could not build its own files: {e}")
        score.apply(result, rubric)
        if write_reports:
            from ..reports import write_all
            write_all(result, out_dir, include_hidden=options.include_hidden)
        return result
    result.build_log = build.log
    result.warnings += list(build.notes)
    result.source_sha256 = build.sha256 or ""
    if not build.ok:
        result.status = BUILD_ERROR
        result.build_timed_out = bool(build.timed_out)
        from ..i18n import _
        first = build.log.strip().splitlines()[0] if build.log.strip() else _("the submission did not compile")
        for c in selected:
            cr = CheckResult(c.name, _(c.title), status=FAILED, fraction=0.0,
                             output=_("Not run: the submission did not build."))
            result.checks.append(cr)
        # grader.build names the kind of build failure; its words are in grader/grading/catalogue.py.
        diagnosis_id = getattr(build, "diagnosis_id", "build-error")
        if diagnosis_id not in CATALOGUE:   # the grader's bug, like a check's unknown id: not the student's zero
            result.status = UNGRADABLE
            result.warnings.append(f"The build named the problem {diagnosis_id!r}, which grader/grading/catalogue.py "
                                   "does not describe: the grader's mistake, tell your instructor.")
        elif result.checks:
            result.checks[0].diagnoses.append(Diagnosis(diagnosis_id, first))
    else:
        secret = os.environ.get("GRADER_SECRET", rubric.get("grading", {}).get("secret", ""))
        seed = run_seed(secret, result.source_sha256) if options.seed is None else options.seed
        _run_checks(result, checks, selected, build.library, options, seed, out_dir, entries)

    drop_consequences(result)
    score.apply(result, rubric)
    result.execution_time_s = time.monotonic() - started
    if write_reports:
        from ..reports import write_all
        write_all(result, out_dir, include_hidden=options.include_hidden)
        write_harness_log(result, out_dir)
    return result


HARNESS_LOG = "harness-errors.log"


def write_harness_log(result: GradeResult, out_dir: Path) -> Path | None:
    """The tracebacks of checks the grader failed on, for the instructor
    (reports tell the student only that the grader failed)."""
    failed = [c for c in result.checks if c.error_log]
    if not failed:
        return None
    path = Path(out_dir) / HARNESS_LOG
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(f"== check {c.name} ({result.submission})\n{c.error_log}\n" for c in failed))
    return path


def drop_consequences(result: GradeResult) -> None:
    """Leave out symptoms (a render that differs, a seam) when their cause was
    found. What the speed check finds (time, the timing faces) causes no
    picture, and the kit does not run it: it decides nothing here. A read
    outside the face in other checks is left out where state kept between
    calls was found (a face size or address kept from faces set earlier:
    such code reads past the smaller faces set later, with clamps that are
    right for the old size; "clamp both lattice points" would mislead)."""
    from .catalogue import CONSEQUENCES, STATE_CAUSES
    if any(d.id not in CONSEQUENCES for c in result.checks if c.name != "speed" for d in c.diagnoses):
        for check in result.checks:
            check.diagnoses = [d for d in check.diagnoses if d.id not in CONSEQUENCES]
    found = {d.id: c.name for c in result.checks for d in c.diagnoses if d.id in STATE_CAUSES}
    if found:
        for check in result.checks:
            if check.name not in found.values():
                check.diagnoses = [d for d in check.diagnoses if d.id != "out-of-bounds-read"]


def _environment_warnings() -> list[str]:
    """Versions that differ from those the fixtures were made with
    (grader.grading.fixtures.environment_warnings)."""
    from . import fixtures
    return list(fixtures.environment_warnings())


def _open_lookups(library: Path, options: GradeOptions):
    """The submission's isolated lookups (grader.worker); raises
    SandboxUnavailable when no isolation is possible and unsafe is not allowed."""
    from ..worker.lookups import open_lookups
    return open_lookups(library, sandbox=options.sandbox, sanitize=options.sanitize, allow_unsafe=options.allow_unsafe)


def _run_checks(result: GradeResult, checks: list[Check], selected: list[Check], library: Path,
                options: GradeOptions, seed: int, out_dir: Path, settings: dict) -> None:
    with _open_lookups(library, options) as lookups:
        prepare = getattr(lookups, "prepare_next", None)     # the first worker set up while the checks begin
        if prepare is not None:
            prepare()
        ctx = CheckContext(lookups=lookups, seed=seed, artifacts=out_dir / "images",
                           quick=options.quick, settings=settings)
        try:
            result.checks += run_checks(checks, ctx, [c.name for c in selected]).results
        finally:
            # Workers start lazily: their warnings exist once the checks have run.
            result.isolation = str(getattr(lookups, "isolation", "") or "")
            result.warnings += [w for w in getattr(lookups, "warnings", []) if w not in result.warnings]
    # The gradebook's status column: a submission that hung somewhere is flagged.
    if any(d.id == "timeout" for d in result.diagnoses):
        result.status = TIMEOUT
