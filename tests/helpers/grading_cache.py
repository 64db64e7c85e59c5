"""One real grading per (submission, options, isolation) per test session.

Many test files grade the same zoo submission with the same options (the
zoo's verdicts, the word counts, the Japanese reports, a control beside an
attack): each such grading takes seconds. `grade_once` has
grader.grading.grade.grade's signature and answers with the GradeResult of the first
such grading in this session, whichever xdist worker ran it: the grading is
done once, under a file lock, in a folder all workers share
(tests/helpers/session_once.py; outside a test session every call grades).

What keys a grading is all that grade() reads: the submission's name and
bytes (every file of a folder), the options with the language they choose,
the rubric's bytes, the GRADER_* environment (the secret, the language), and
why bubblewrap cannot run here (sandbox_problem(), None when it can: a fake
failing bwrap on PATH makes it privilege-drop mode).

Each caller gets its own copy: the result is unpickled afresh, its reports
and pictures are copied into the caller's out_dir (as grade() writes them
there; only the pictures when write_reports=False) and its artifacts point
there, so a test may change what it gets. The language is set as grade()
leaves it. Tests that grade twice on purpose (determinism, load, two modes
compared) call grade() itself, as must tests that monkeypatch the grader.
"""
from __future__ import annotations

import dataclasses
import hashlib
import os
import shutil
from pathlib import Path

from grader import i18n
from grader.grading import score
from grader.grading.grade import GradeOptions, grade
from grader.grading.results import GradeResult
from grader.intake import student_name
from grader.worker import sandbox

import session_once
from session_once import once

OUT = "out"
IMAGES = "images"


def _files(submission: Path) -> list[tuple[str, bytes]]:
    if submission.is_dir():
        return [(str(p.relative_to(submission)), p.read_bytes())
                for p in sorted(submission.rglob("*")) if p.is_file()]
    return [(submission.name, submission.read_bytes())]


def grading_key(submission: Path, options: GradeOptions) -> str:
    """What decides a grading's result: the same key, the same grading."""
    rubric = score.load_rubric(options.rubric)
    chosen = dataclasses.replace(options, lang=i18n.choose(options.lang, rubric))
    files = _files(submission)
    digest = hashlib.sha256()
    for part in (student_name(submission), *(f"{n}\0" for n, _ in files),
                 repr(dataclasses.replace(chosen, rubric=Path(options.rubric).resolve())),
                 repr(sorted((k, v) for k, v in os.environ.items() if k.startswith("GRADER_"))),
                 repr(sandbox.sandbox_problem())):
        digest.update(part.encode() + b"\1")
    for _, data in files:
        digest.update(hashlib.sha256(data).digest())
    digest.update(Path(options.rubric).read_bytes())
    return digest.hexdigest()[:24]


def grade_once(submission: Path, out_dir: Path, options: GradeOptions | None = None,
               write_reports: bool = True) -> GradeResult:
    """grader.grading.grade.grade, done once per key in this session (see above)."""
    if session_once.FOLDER is None:
        return grade(submission, out_dir, options, write_reports)
    submission, out_dir = Path(submission), Path(out_dir)
    options = options or GradeOptions()
    key = f"grading-{grading_key(submission, options)}"
    result = once(key, lambda folder: grade(submission, folder / OUT, options, write_reports=True))
    return _hand_out(result, session_once.FOLDER / key / OUT, out_dir, options, write_reports)


def _hand_out(result: GradeResult, cached: Path, out_dir: Path, options: GradeOptions,
              write_reports: bool) -> GradeResult:
    """The result as grade(..., out_dir) leaves it: reports (or only the
    pictures) in out_dir, artifacts pointing there, the language set."""
    out_dir.mkdir(parents=True, exist_ok=True)
    if write_reports:
        shutil.copytree(cached, out_dir, dirs_exist_ok=True)
    elif (cached / IMAGES).is_dir():
        shutil.copytree(cached / IMAGES, out_dir / IMAGES, dirs_exist_ok=True)
    for check in result.checks:
        check.artifacts = {name: out_dir / Path(path).relative_to(cached)
                           if Path(path).is_relative_to(cached) else path
                           for name, path in check.artifacts.items()}
    i18n.set_language(i18n.choose(options.lang, score.load_rubric(options.rubric)))
    return result
