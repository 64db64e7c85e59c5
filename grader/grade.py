"""Grade one submission: build -> isolated worker -> checks -> score -> reports.

`grade()` always returns a GradeResult and always writes the reports, whatever
the submission does; a failure of the harness itself makes the result
"ungradable" (never a zero charged to the student).
"""
from __future__ import annotations

import hashlib
import os
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

from . import score
from .checks import all_checks
from .checks.context import CheckContext
from .results import BUILD_ERROR, ERROR, FAILED, SKIPPED, TIMEOUT, UNGRADABLE, CheckResult, Diagnosis, GradeResult


@dataclass
class GradeOptions:
    sanitize: bool = False          # AddressSanitizer build of the submission
    sandbox: bool | None = None     # None: use it when this machine supports it
    allow_stale: bool = False       # grade even when fixtures/ is stale
    quick: bool = False             # smaller direction sets (tests of the harness)
    rubric: Path = score.RUBRIC
    only: tuple[str, ...] = ()      # run only these checks
    include_hidden: bool = True     # reports show hidden checks (instructors); False for students


def run_seed(secret: str, source_sha256: str) -> int:
    """The seed of the random checks: reproducible for one submission, not
    guessable without the course secret."""
    digest = hashlib.sha256(f"{secret}\0{source_sha256}".encode()).digest()
    return int.from_bytes(digest[:8], "little") >> 1


def grade(submission: Path, out_dir: Path, options: GradeOptions | None = None, write_reports: bool = True) -> GradeResult:
    from .build import HarnessBuildError, build_submission
    from .grade_all import student_name
    options = options or GradeOptions()
    started = time.monotonic()
    submission = Path(submission)
    rubric = score.load_rubric(options.rubric)
    result = GradeResult(submission=student_name(submission))
    checks = all_checks()
    if options.only:
        checks = [c for c in checks if c.name in options.only]
    entries = rubric.get("checks", {})
    checks = [c for c in checks if c.name in entries] if entries else checks

    if not options.allow_stale:
        from .fixtures import StaleFixtures, check_stale
        try:
            check_stale()
        except StaleFixtures as e:
            raise SystemExit(str(e))

    try:
        build = build_submission(submission, sanitize=options.sanitize)
    except HarnessBuildError as e:   # our own sources failed to build: not the student's fault
        result.status = UNGRADABLE
        result.warnings.append(f"The grader could not build its own files: {e}")
        score.apply(result, rubric)
        if write_reports:
            from .reports import write_all
            write_all(result, out_dir, include_hidden=options.include_hidden)
        return result
    result.build_log = build.log
    result.warnings += list(build.notes)
    result.source_sha256 = build.sha256 or ""
    if not build.ok:
        result.status = BUILD_ERROR
        first = build.log.strip().splitlines()[0] if build.log.strip() else "the submission did not compile"
        for c in checks:
            cr = CheckResult(c.name, c.title, status=FAILED, fraction=0.0, output="Not run: the submission did not build.")
            result.checks.append(cr)
        result.checks[0].diagnoses.append(Diagnosis("build-error", first))
    else:
        secret = os.environ.get("GRADER_SECRET", rubric.get("grading", {}).get("secret", ""))
        _run_checks(result, checks, build.library, options, run_seed(secret, result.source_sha256), out_dir, entries)

    drop_consequences(result)
    score.apply(result, rubric)
    result.execution_time_s = time.monotonic() - started
    if write_reports:
        from .reports import write_all
        write_all(result, out_dir, include_hidden=options.include_hidden)
    return result


def drop_consequences(result: GradeResult) -> None:
    """Leave out symptoms (a render that differs, a seam) when their cause was found."""
    from .diagnoses import CONSEQUENCES
    if any(d.id not in CONSEQUENCES for d in result.diagnoses):
        for check in result.checks:
            check.diagnoses = [d for d in check.diagnoses if d.id not in CONSEQUENCES]


def _run_checks(result: GradeResult, checks, library: Path, options: GradeOptions, seed: int, out_dir: Path,
                settings: dict) -> None:
    from .worker.lookups import open_lookups
    with open_lookups(library, sandbox=options.sandbox, sanitize=options.sanitize) as lookups:
        if getattr(lookups, "warning", None):
            result.warnings.append(lookups.warning)
        ctx = CheckContext(lookups=lookups, seed=seed, artifacts=out_dir / "images",
                           quick=options.quick, settings=settings)
        statuses: dict[str, str] = {}
        for c in checks:
            blocked = [d for d in c.depends if statuses.get(d) in (ERROR, SKIPPED)]
            if blocked:
                cr = CheckResult(c.name, c.title, status=SKIPPED, fraction=0.0,
                                 output=f"Not run: it needs {', '.join(blocked)}, which could not run.")
            else:
                t0 = time.monotonic()
                try:
                    cr = c.run(ctx)
                except Exception:  # the harness failed, not the student
                    cr = CheckResult(c.name, c.title, status=ERROR, fraction=0.0,
                                     output="The grader itself failed on this check; this is not your fault. "
                                            "Your instructor has been told.\n\n```\n" + traceback.format_exc(limit=4) + "```")
                cr.duration_s = time.monotonic() - t0
            statuses[c.name] = cr.status
            result.checks.append(cr)
    # The gradebook's status column: a submission that hung somewhere is flagged.
    if any(d.id == "timeout" for d in result.diagnoses):
        result.status = TIMEOUT
