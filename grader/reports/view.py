"""What a report may show: the one place the visibility rule is applied.

Gradescope hides a test entry by its visibility, but our own reports
(report.md, report.html, junit.xml, the terminal, the top-level output of
results.json) are read as they are. So they are built from a ReportView:
for students (the default) it holds only checks whose visibility is
"visible", and the diagnoses, artifacts and figures of those checks. A check
marked "hidden", "after_due_date" or "after_published" (or anything else) is
reduced to its count and points. Instructors ask for include_hidden=True.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..grading import catalogue
from ..i18n import N_, Translated, _
from ..grading.results import (BUILD_ERROR, ERROR, FAILED, GRADED, PASSED, SKIPPED, TIMEOUT, UNGRADABLE,
                               CheckResult, Diagnosis, GradeResult, TexelHit)
from .text import clean, figure, tidy_numbers, truncate_middle

VISIBLE = "visible"
# A diagnosis or warning can quote the submission (an exception's message,
# up to the worker's 64 KiB): shown up to this many characters.
TEXT_LIMIT = 2000

# The sentence a report shows for a submission's overall status.
STATUS_TEXT = Translated({
    GRADED: N_("graded"),
    BUILD_ERROR: N_("did not compile"),
    TIMEOUT: N_("timed out"),
    UNGRADABLE: N_("could not be graded"),
})

# What a student is told when the status is not a plain "graded".
STATUS_EXPLANATION = Translated({
    BUILD_ERROR: N_("Your code did not compile, so the checks could not run. "
                    "The compiler's messages are below."),
    TIMEOUT: N_("Your code took longer than the time allowed on some calls: they were "
                "stopped (or, once the grading's time was used up, not run) and count as wrong."),
    UNGRADABLE: N_("This submission could not be graded because of a problem in "
                   "the grader, not in your code. The score shown is not final: "
                   "please tell your instructor."),
})

# When a hidden check's results are shown, in Gradescope's terms.
HIDDEN_WHEN = Translated({
    "hidden": N_("not shown to students"),
    "after_due_date": N_("shown after the due date"),
    "after_published": N_("shown when grades are published"),
})

# Per-check states for display (finer than Gradescope's passed/failed).
# "info": a check worth no points (e.g. the diagnosis from position-encoding
# textures) says what it found; it neither passes nor fails.
STATE_PASSED, STATE_PARTIAL, STATE_FAILED, STATE_ERROR, STATE_SKIPPED, STATE_INFO = (
    "passed", "partial", "failed", "not run", "skipped", "info")

# How the submission's code was kept from the grader (GradeResult.isolation,
# set from grader.worker's runner), in words for every report.
ISOLATION_TEXT = Translated({
    "bubblewrap": N_("bubblewrap sandbox"),
    "privilege-drop": N_("separate unprivileged user with a system-call filter"),
    "unsafe-none": N_("no sandbox (--unsafe-no-sandbox, or the student kit's self-check on your own machine, where bubblewrap is missing)"),
    # The kit's self-check where bubblewrap is missing (grader.kit.selfcheck): the student's own code, at home.
    "own-machine": N_("no sandbox (your own code on your own machine)"),
    "": N_("none needed (no code of the submission ran)"),
})


# Each check in the score table, in a few words; its docstring's sentence
# (CheckResult.title) heads its details.
CHECK_LABEL = Translated({
    "read_texture": N_("readTexture: bilinear interpolation"),
    "fetch_sweep": N_("fetchColor: face and (u, v) for every direction"),
    "diagnosis": N_("fetchColor: what it does on each face"),
    "arrows": N_("Test map: the arrows point along +x, +y, +z"),
    "stability": N_("fetchColor: zero, NaN, tiny, huge and tied directions"),
    "renders": N_("Full renders look like the reference"),
    "speed": N_("Speed"),
})

# The one count a report gives for a mistake, by its kind: how many of the
# cases of the check that judges that function it gets wrong, worded as the
# check's own first line words it ("21041 of 126662 directions give...").
COUNTED_BY = {"mapping": "fetch_sweep", "filtering": "read_texture"}
COUNT_TEXT = Translated({
    "fetch_sweep": N_("%(wrong)d of %(total)d directions give the wrong colour."),
    "read_texture": N_("%(wrong)d of %(total)d readTexture calls give the wrong colour."),
})

# Words the checks' details use, one line each (shown with the details).
GLOSSARY = Translated({
    "fibonacci": N_("Fibonacci sphere: directions spread evenly over the whole sphere."),
    "ulp": N_("ulp: the smallest step a number can take; moved by one ulp means as close as it gets."),
    "ssim": N_("SSIM: how alike two pictures are in structure; 1 means identical."),
    "flip": N_("FLIP: how different two pictures look to a person; 0 means identical."),
    "protocol": N_("protocol: the time the grader's own messages to your code take, taken out of your time."),
    "pareto": N_("speed against accuracy: each line is one lookup method; further left is faster, lower is more accurate."),
})

# What a check without output says, by its status.
DEFAULT_OUTPUT = Translated({
    ERROR: N_("This check could not run because of a problem in the grader, not in your code."),
    SKIPPED: N_("This check did not run because a check it depends on failed."),
})


def check_label(check: CheckResult) -> str:
    """The check's name in the score table."""
    return CHECK_LABEL[check.name] if check.name in CHECK_LABEL else check.title


def check_output(check: CheckResult) -> str:
    """The check's output (Markdown), or a sentence saying why there is none.
    Numbers printed as numpy reprs are rewritten as people write them."""
    return tidy_numbers(clean(check.output)).strip() or DEFAULT_OUTPUT.get(check.status, "")


def _numbers(values, decimals: int | None = None) -> str:
    """(a, b, c): four significant digits, or a fixed number of decimals
    without trailing zeros (texels to 1/100, u and v to 1/10000)."""
    def one(v: float) -> str:
        if decimals is None or not math.isfinite(v):
            return figure(float(v))
        text = f"{v:.{decimals}f}".rstrip("0").rstrip(".")
        return "0" if text == "-0" else text
    return "(" + ", ".join(one(float(v)) for v in values) + ")"


def hit_text(hit: TexelHit) -> str:
    """Where a lookup landed, in the handout's terms."""
    if not hit.face and hit.address is not None:
        return _("an address %(offset)s floats after the first face's first texel, where no face starts, at "
                 "(u, v) = %(uv)s") % {"offset": f"{hit.address:.0f}", "uv": _numbers(hit.uv, 4)}
    if not hit.face:
        return _("a colour that is in no face of the texture")
    return _("face %(face)s at texel %(texel)s, (u, v) = %(uv)s") % {
        "face": clean(hit.face), "texel": _numbers(hit.texel, 2), "uv": _numbers(hit.uv, 4)}


def mismatch_groups(check: CheckResult) -> list[tuple[str, list[tuple[str, str, str]], int]]:
    """The check's worst cases as plain text, by group, in order:
    (group, [(lookup, what it should do, what it did)], how many more);
    "should" and "did" read after "should" and "yours": "sample face +X at
    texel (6.57, 31), (u, v) = ..." / "sampled ...", or "give colour (...)"
    / "gave ..." where the texture does not say where a colour came from."""
    groups: dict[str, list[tuple[str, str, str]]] = {}
    for m in check.mismatches:
        should = (_("sample %(where)s") % {"where": hit_text(m.expected_at)} if m.expected_at
                  else _("give colour %(colour)s") % {"colour": _numbers(m.expected)})
        got = (_("sampled %(where)s") % {"where": hit_text(m.got_at)} if m.got_at
               else _("gave colour %(colour)s") % {"colour": _numbers(m.got)})
        groups.setdefault(clean(m.group), []).append((clean(m.call), should, got))
    out = []
    for group, rows in groups.items():
        total = check.mismatch_counts.get(group, len(rows))
        out.append((group, rows, max(0, total - len(rows))))
    return out


def is_informational(check: CheckResult) -> bool:
    """Worth no points: what it says is information, not a verdict."""
    return check.max_score <= 0 and check.status in (PASSED, FAILED)


def is_visible(check: CheckResult) -> bool:
    """Only "visible" is visible: an unknown visibility is treated as hidden."""
    return check.visibility == VISIBLE


def check_state(check: CheckResult) -> str:
    if is_informational(check):
        return STATE_INFO
    if check.status == PASSED:
        return STATE_PASSED
    if check.status == ERROR:
        return STATE_ERROR
    if check.status == SKIPPED:
        return STATE_SKIPPED
    if check.status == FAILED and check.score > 0:
        return STATE_PARTIAL
    return STATE_FAILED


@dataclass
class DiagnosisGroup:
    """All findings with one id, with the catalogue's words for it."""
    info: catalogue.DiagnosisInfo
    findings: list[Diagnosis] = field(default_factory=list)

    @property
    def faces(self) -> list[str]:
        return sorted({d.face for d in self.findings if d.face})


@dataclass
class HiddenSummary:
    count: int
    max_score: float
    when: str          # "shown after the due date", ...


@dataclass
class ReportView:
    submission: str
    status: str
    score: float
    max_score: float
    checks: list[CheckResult]
    hidden: list[HiddenSummary]
    diagnoses: list[DiagnosisGroup]
    warnings: list[str]
    build_log: str
    execution_time_s: float
    source_sha256: str
    complete: bool         # True when hidden checks are included
    isolation: str = "unknown"   # an ISOLATION_TEXT key, or what the runner said

    @property
    def isolation_text(self) -> str:
        return ISOLATION_TEXT.get(self.isolation, self.isolation or _("unknown"))

    @property
    def scored_checks(self) -> list[CheckResult]:
        """The checks "N of M checks passed" counts: informational ones are not."""
        return [c for c in self.checks if not is_informational(c)]

    @property
    def passed_line(self) -> str:
        scored = self.scored_checks
        passed = sum(check_state(c) == STATE_PASSED for c in scored)
        return _("%(passed)d of %(total)d checks passed") % {"passed": passed, "total": len(scored)} if scored else ""

    @property
    def refused(self) -> bool:
        """Not built because the build refused the submission (an include, a call
        into the reference, an unreadable upload...), not because it failed to compile."""
        return self.status == BUILD_ERROR and any(
            g.info.kind == "build" and g.info.id != "build-error" for g in self.diagnoses)

    @property
    def status_text(self) -> str:
        return _("not built") if self.refused else STATUS_TEXT.get(self.status, self.status)

    @property
    def status_explanation(self) -> str:
        if self.refused:
            return _("Your submission was refused before it could be built or run, so the checks "
                     "could not run: the diagnosis below says why and what to do.")
        return STATUS_EXPLANATION.get(self.status, "")

    def mistake_count(self, kind: str) -> str:
        """The count of wrong cases that a mistake of this kind costs, as the
        sentence the summary shows (the judging check's own numbers), or ""."""
        name = COUNTED_BY.get(kind)
        check = next((c for c in self.checks if c.name == name), None)
        if check is None or "cases" not in check.metrics or "matched" not in check.metrics:
            return ""
        total, matched = int(check.metrics["cases"]), int(check.metrics["matched"])
        if matched >= total:
            return ""
        return COUNT_TEXT[name] % {"wrong": total - matched, "total": total}

    @property
    def instructor_facts(self) -> list[str]:
        """What only an instructor needs: how the code was isolated, the
        grader's warnings. Reports put these in their instructor section."""
        return [_("Your code ran under: %(isolation)s.") % {"isolation": self.isolation_text}, *self.warnings]

    def counts(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for check in self.checks:
            state = check_state(check)
            out[state] = out.get(state, 0) + 1
        return out

    def artifact(self, name: str) -> Path | None:
        for check in self.checks:
            if name in check.artifacts:
                return Path(check.artifacts[name])
        return None

    def artifacts(self) -> list[tuple[CheckResult, str, Path]]:
        """Every artifact of the shown checks, in check order then name order."""
        return [(c, name, Path(c.artifacts[name]))
                for c in self.checks for name in sorted(c.artifacts)]

    def metric(self, name: str) -> float | None:
        for check in self.checks:
            if name in check.metrics:
                return check.metrics[name]
        return None


def group_diagnoses(found: list[Diagnosis]) -> list[DiagnosisGroup]:
    groups: dict[str, DiagnosisGroup] = {}
    for d in found:
        groups.setdefault(d.id, DiagnosisGroup(catalogue.describe(d.id))).findings.append(d)
    return [groups[k] for k in sorted(groups, key=catalogue.sort_key)]


def build_view(result: GradeResult, include_hidden: bool = False) -> ReportView:
    shown = [c for c in result.checks if include_hidden or is_visible(c)]
    withheld = [] if include_hidden else [c for c in result.checks if not is_visible(c)]

    hidden: dict[str, HiddenSummary] = {}
    for c in withheld:
        when = HIDDEN_WHEN.get(c.visibility, HIDDEN_WHEN["hidden"])
        h = hidden.setdefault(when, HiddenSummary(0, 0.0, when))
        h.count += 1
        h.max_score += c.max_score

    if withheld:
        # The total would reveal how the hidden checks went.
        score = sum(c.score for c in shown)
        max_score = sum(c.max_score for c in shown)
    else:
        score, max_score = result.score, result.max_score

    seen, found = set(), []
    for c in shown:
        for d in c.diagnoses:
            key = (d.id, d.face, d.detail)
            if key not in seen:
                seen.add(key)
                # clean(): a detail quotes the submission (an exception's text), and
                # the terminal prints it as is: escapes there moved the cursor.
                found.append(replace(d, detail=truncate_middle(clean(d.detail), TEXT_LIMIT),
                                     hint=truncate_middle(clean(d.hint), TEXT_LIMIT)))

    return ReportView(
        submission=clean(result.submission),
        status=result.status,
        score=score,
        max_score=max_score,
        checks=shown,
        hidden=sorted(hidden.values(), key=lambda h: h.when),
        diagnoses=group_diagnoses(found),
        warnings=[truncate_middle(clean(w), TEXT_LIMIT) for w in result.warnings],
        build_log=clean(result.build_log),
        execution_time_s=result.execution_time_s,
        source_sha256=result.source_sha256,
        complete=include_hidden,
        # Older results (and tests) may not carry it.
        isolation=clean(str(getattr(result, "isolation", "unknown"))),
    )
