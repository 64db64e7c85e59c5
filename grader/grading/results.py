"""What grading produces: the values that flow from checks to score to reports.

Checks return CheckResult; grading/score.py fills in points from the rubric; reports/
turn a GradeResult into files. Nothing here runs a check or formats a report.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

# Statuses a check can end in. "error" means the harness failed, not the
# student: it makes the submission ungradable rather than scoring zero.
PASSED, FAILED, ERROR, SKIPPED = "passed", "failed", "error", "skipped"

# Overall statuses of a graded submission (the gradebook's status column).
GRADED, BUILD_ERROR, TIMEOUT, UNGRADABLE = "graded", "build-error", "timeout", "ungradable"


@dataclass(frozen=True)
class Diagnosis:
    """One named mistake: a stable id (docs/diagnoses.md lists them all), the
    face it applies to (a FACE_NAMES entry, or None), and a sentence for the
    student. `hint` says what to do about it."""
    id: str
    detail: str
    face: str | None = None
    hint: str = ""
    # For a worker's failure: what stopped it, as the worker saw it. "code":
    # the code's own doing (its CPU-time limit used up, or it stopped
    # itself); "grader": only the grader's wall-clock bound or shared time
    # budget, which a busy machine reaches too; "": not a stop, or not known.
    # Not in results.json: grade-all keeps it in its record (.grade.json).
    stopped_by: str = ""

    def as_json(self) -> dict:
        out = {"id": self.id, "detail": self.detail}
        if self.face is not None:
            out["face"] = self.face
        return out


@dataclass(frozen=True)
class TexelHit:
    """Where a lookup landed in a texture that encodes texel positions
    (checks/instruments/textures.py, coordinate_faces), decoded from the colour it
    returned, so a report can say "face, texel, (u, v)" instead of printing
    colours that mean nothing to a student."""
    face: str                      # a FACE_NAMES entry; "" when the colour is not one of the texture's
    texel: tuple[float, float]     # lattice position p = (u W, v H), in texels
    uv: tuple[float, float]
    address: float | None = None   # with face "": a recorded call's address, in floats from the first
                                   # face's first texel, where no face starts


@dataclass(frozen=True)
class Mismatch:
    """One of a check's worst cases, as data (reports format it).
    `call` is the lookup as the student would write it (grader text, but
    reports escape it like anything else)."""
    call: str                                  # e.g. "fetchColor(Vector3(1, 0.5, 0))"
    expected: tuple[float, ...]                # the reference's colour
    got: tuple[float, ...]                     # the submission's colour (may hold NaN)
    expected_at: TexelHit | None = None        # set when the texture encodes positions
    got_at: TexelHit | None = None
    group: str = ""                            # e.g. "Fibonacci sphere"


@dataclass
class CheckResult:
    name: str                      # rubric key, e.g. "read_texture"
    title: str                     # the sentence the student reads
    status: str = PASSED
    fraction: float = 1.0          # share of cases passed, 0..1 (score.py turns it into points)
    # The share of its points the check can earn after its prerequisites'
    # findings (grader.checks.Needs.credit), 0..1; score.py multiplies it in.
    credit: float = 1.0
    output: str = ""               # Markdown, for the student
    diagnoses: list[Diagnosis] = field(default_factory=list)
    artifacts: dict[str, Path] = field(default_factory=dict)  # e.g. "render_submission": PNG path
    metrics: dict[str, float] = field(default_factory=dict)   # figures for reports and charts
    duration_s: float = 0.0
    # A harness error's traceback: for the instructor (logs), never shown to a student.
    error_log: str = ""
    # Worst cases as data, worst first (reports show them under the output);
    # mismatch_counts: group -> how many mismatches in all, for "... and N more".
    mismatches: list[Mismatch] = field(default_factory=list)
    mismatch_counts: dict[str, int] = field(default_factory=dict)
    # Filled in by score.py from the rubric:
    score: float = 0.0
    max_score: float = 0.0
    visibility: str = "visible"
    tags: list[str] = field(default_factory=list)
    number: str = ""


@dataclass
class GradeResult:
    submission: str                # a display name (folder or file name)
    status: str = GRADED
    checks: list[CheckResult] = field(default_factory=list)
    score: float = 0.0
    max_score: float = 0.0
    build_log: str = ""            # compiler messages, trimmed
    warnings: list[str] = field(default_factory=list)   # e.g. "sandbox unavailable: ..."
    execution_time_s: float = 0.0
    source_sha256: str = ""
    # How the submission's code was isolated (grader.worker: "bubblewrap",
    # "privilege-drop", "unsafe-none"); "" when none of it ran (build failed).
    isolation: str = ""
    # The build was stopped at its deadline (not cached: a resumed
    # grade-all builds it again, grader/course/grade_all.py).
    build_timed_out: bool = False

    @property
    def diagnoses(self) -> list[Diagnosis]:
        seen, out = set(), []
        for check in self.checks:
            for d in check.diagnoses:
                key = (d.id, d.face, d.detail)
                if key not in seen:
                    seen.add(key)
                    out.append(d)
        return out
