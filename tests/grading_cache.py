"""One real grading per (submission, options, isolation) per test session.

Many test files grade the same zoo submission with the same options (the
zoo's verdicts, the word counts, the Japanese reports, a control beside an
attack): each such grading takes seconds. `grade_once` has
grader.grade.grade's signature and answers with the GradeResult of the first
such grading in this session, whichever xdist worker ran it: the grading is
done once, under a file lock, in a folder all workers share (FOLDER, set by
tests/conftest.py for the session; unset, every call grades).

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
import fcntl
import hashlib
import os
import pickle
import shutil
from pathlib import Path

from grader import i18n, score
from grader.grade import GradeOptions, grade
from grader.results import GradeResult
from grader.submissions import student_name
from grader.worker import sandbox

RESULT = "result.pickle"
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
    digest = hashlib.sha256()
    for part in (student_name(submission), *(f"{n}\0" for n, _ in _files(submission)),
                 repr(dataclasses.replace(chosen, rubric=Path(options.rubric).resolve())),
                 repr(sorted((k, v) for k, v in os.environ.items() if k.startswith("GRADER_"))),
                 repr(sandbox.sandbox_problem())):
        digest.update(part.encode() + b"\1")
    for _, data in _files(submission):
        digest.update(hashlib.sha256(data).digest())
    digest.update(Path(options.rubric).read_bytes())
    return digest.hexdigest()[:24]


FOLDER: Path | None = None


def grade_once(submission: Path, out_dir: Path, options: GradeOptions | None = None,
               write_reports: bool = True) -> GradeResult:
    """grader.grade.grade, done once per key in this session (see above)."""
    if FOLDER is None:
        return grade(submission, out_dir, options, write_reports)
    return GradingCache(FOLDER).grade(submission, out_dir, options, write_reports)


class GradingCache:
    def __init__(self, folder: Path):
        self.folder = Path(folder)

    def grade(self, submission: Path, out_dir: Path, options: GradeOptions | None = None,
              write_reports: bool = True) -> GradeResult:
        submission, out_dir = Path(submission), Path(out_dir)
        options = options or GradeOptions()
        entry = self.folder / grading_key(submission, options)
        self.folder.mkdir(parents=True, exist_ok=True)
        with open(f"{entry}.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)    # the other worker waits for this grading, then reads it
            if not (entry / RESULT).exists():
                result = grade(submission, entry / OUT, options, write_reports=True)
                (entry / f"{RESULT}.tmp").write_bytes(pickle.dumps(result))
                (entry / f"{RESULT}.tmp").replace(entry / RESULT)
        result = pickle.loads((entry / RESULT).read_bytes())
        return self._hand_out(result, entry / OUT, out_dir, options, write_reports)

    @staticmethod
    def _hand_out(result: GradeResult, cached: Path, out_dir: Path, options: GradeOptions,
                  write_reports: bool) -> GradeResult:
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
