"""The mutants graded as a class: through grade-all itself (grader.course.grade_all),
with the course's rubric or the one given, so the audit measures exactly what
grading a class does."""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path

from ...grading import score


@dataclass
class Graded:
    score: float
    max_score: float
    status: str
    checks: dict[str, float] = field(default_factory=dict)   # rubric name -> points scored
    lost: list[str] = field(default_factory=list)            # checks scored below their points
    diagnoses: list[str] = field(default_factory=list)
    error: str = ""

    @property
    def full_marks(self) -> bool:
        return not self.error and self.max_score > 0 and self.score >= self.max_score - 1e-9


def check_points(rubric: Path) -> dict[str, float]:
    """Each check's points in the rubric, in its order."""
    return {name: float(entry["points"]) for name, entry in score.load_rubric(rubric).get("checks", {}).items()}


def grade_folder(folder: Path, out: Path, rubric: Path, jobs: int, options: dict,
                 progress: bool = True) -> dict[str, Graded]:
    """{submission name: Graded} for every .cpp in `folder`, graded into `out`
    by grade-all (resumable: what is graded under the same key is kept)."""
    # The one place the audit reaches grade-all (its module may move: fix the path here).
    from ..grade_all import grade_all
    points = check_points(rubric)
    # grade-all's key has the rubric's path, not its text (its own rubric is
    # in the grader's files): a copy named by its hash makes an edited rubric
    # regrade everything.
    text = Path(rubric).read_bytes()
    keyed = Path(out).parent / f"rubric-{hashlib.sha256(text).hexdigest()[:16]}.toml"
    keyed.parent.mkdir(parents=True, exist_ok=True)
    keyed.write_bytes(text)
    rows = grade_all(folder, out, jobs, dict(options, rubric=str(keyed)), progress)
    graded = {}
    for r in rows:
        lost = [name for name, p in points.items() if p > 0 and name in r.checks and r.checks[name] < p - 1e-9]
        lost += [name for name, p in points.items() if p > 0 and name not in r.checks]   # did not run
        graded[r.student] = Graded(r.score, r.max_score, r.status, dict(r.checks), lost, list(r.diagnoses),
                                   r.error)
    return graded
