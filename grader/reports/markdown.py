"""report.md: a summary fit for a CI job summary (GitHub renders it as is).

Also the top-level `output` of results.json (summary(), without the score
table, which Gradescope draws itself from the tests).
"""
from __future__ import annotations

from ..results import BUILD_ERROR
from .text import md_escape, md_fence, points, truncate_middle
from .view import (STATE_ERROR, STATE_FAILED, STATE_PARTIAL, STATE_PASSED,
                   STATE_SKIPPED, DiagnosisGroup, ReportView, check_output,
                   check_state)

STATE_ICON = {
    STATE_PASSED: "✅",
    STATE_PARTIAL: "🟡",
    STATE_FAILED: "❌",
    STATE_ERROR: "⚠️",
    STATE_SKIPPED: "⏭️",
}


def all_correct(view: ReportView) -> str:
    if view.hidden:
        return "Every visible check passed."
    return "Everything the grader checks is correct. Well done!"


def _score_line(view: ReportView) -> str:
    counts = view.counts()
    passed = counts.get(STATE_PASSED, 0)
    return (f"**Score: {points(view.score)} / {points(view.max_score)}** · "
            f"{view.status_text} · {passed} of {len(view.checks)} checks passed")


def _warnings(view: ReportView) -> list[str]:
    return [f"> **Warning:** {md_escape(w)}" for w in view.warnings]


def _hidden_note(view: ReportView, about_score: bool = True) -> list[str]:
    lines = []
    for h in view.hidden:
        many = h.count != 1
        text = (f"{h.count} more check{'s' if many else ''} ({points(h.max_score)} points) "
                f"{'are' if many else 'is'} {h.when}")
        if about_score:
            text += f"; {'they are' if many else 'it is'} not counted in the score above"
        lines.append(f"_{text}._")
    return lines


def score_table(view: ReportView) -> list[str]:
    lines = ["| | # | Check | Points |", "|:-:|:--|:--|--:|"]
    for c in view.checks:
        state = check_state(c)
        lines.append(f"| {STATE_ICON[state]} | {md_escape(c.number)} | "
                     f"{md_escape(c.title)} | {points(c.score)} / {points(c.max_score)} |")
    lines.append(f"| | | **Total** | **{points(view.score)} / {points(view.max_score)}** |")
    return lines


def diagnosis_section(group: DiagnosisGroup, level: str = "###") -> list[str]:
    info = group.info
    lines = [f"{level} {md_escape(info.title)} (`{info.id}`)", ""]
    for d in group.findings:
        where = f"**{md_escape(d.face)}:** " if d.face else ""
        hint = f" _{md_escape(d.hint)}_" if d.hint else ""
        lines.append(f"- {where}{md_escape(d.detail)}{hint}")
    lines += ["", info.explanation, "", f"**What to do:** {info.what_to_do}", ""]
    return lines


def _diagnoses(view: ReportView, level: str) -> list[str]:
    if not view.diagnoses:
        return []
    lines = [f"{level} What to fix", ""]
    for group in view.diagnoses:
        lines += diagnosis_section(group, level + "#")
    return lines


def _build_log(view: ReportView, level: str) -> list[str]:
    if not view.build_log.strip():
        return []
    log = md_fence(truncate_middle(view.build_log), "text")
    if view.status == BUILD_ERROR:
        return [f"{level} Compiler messages", "", log, ""]
    return ["<details><summary>Compiler messages (warnings)</summary>", "", log, "",
            "</details>", ""]


def _details(view: ReportView) -> list[str]:
    lines = []
    for c in view.checks:
        output = check_output(c)
        if not output:
            continue
        state = check_state(c)
        summary = (f"{STATE_ICON[state]} {md_escape(c.number)} {md_escape(c.title)}: "
                   f"{points(c.score)} / {points(c.max_score)}")
        lines += [f"<details><summary>{summary}</summary>", "",
                  truncate_middle(output), "", "</details>", ""]
    return ["## Details of each check", ""] + lines if lines else []


def _head(view: ReportView) -> list[str]:
    lines = []
    if view.status_explanation:
        lines += [f"**{view.status_explanation}**", ""]
    if view.warnings:
        lines += _warnings(view) + [""]
    return lines


def render(view: ReportView) -> str:
    """The whole report.md."""
    lines = [f"# Environment mapping: {md_escape(view.submission)}", "",
             _score_line(view), ""]
    lines += _head(view)
    if view.status == BUILD_ERROR:
        lines += _build_log(view, "##")
    if view.checks:
        lines += ["## Checks", ""] + score_table(view) + [""]
    if view.hidden:
        lines += _hidden_note(view) + [""]
    lines += _diagnoses(view, "##")
    if not view.diagnoses and view.checks and view.score >= view.max_score:
        lines += [all_correct(view), ""]
    if view.status != BUILD_ERROR:
        lines += _build_log(view, "##")
    lines += _details(view)
    return "\n".join(lines).rstrip("\n") + "\n"


def summary(view: ReportView) -> str:
    """The top-level output of results.json: what to fix, in a few lines.
    Gradescope shows the score and each test's own output beside it."""
    lines = _head(view)
    lines += _build_log(view, "###") if view.status == BUILD_ERROR else []
    lines += _diagnoses(view, "###")
    if view.hidden:
        lines += _hidden_note(view, about_score=False) + [""]
    if not lines:
        lines = ["All visible checks passed." if view.score >= view.max_score
                 else "See each check below for details."]
    return "\n".join(lines).rstrip("\n") + "\n"
