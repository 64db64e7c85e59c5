"""report.md: a summary fit for a CI job summary (GitHub renders it as is).

Also the top-level `output` of results.json (summary(), without the score
table, which Gradescope draws itself from the tests).

Text from the submission is inert here: plain strings go through md_escape
(or md_fence for logs), a check's Markdown output through inert_markdown,
and the only raw HTML is our own <details>/<summary>, whose text is HTML-
escaped (GitHub does not apply Markdown inside an HTML block, so a
backslash escape there would show as a backslash).
"""
from __future__ import annotations

from html import escape

from ..i18n import _, ngettext
from ..grading.results import BUILD_ERROR, GRADED, CheckResult
from .text import clean, inert_markdown, md_code, md_escape, md_fence, points, truncate_middle
from .view import (GLOSSARY, STATE_ERROR, STATE_FAILED, STATE_INFO, STATE_PARTIAL,
                   STATE_PASSED, STATE_SKIPPED, TEXT_LIMIT, DiagnosisGroup, ReportView,
                   check_label, check_output, check_state, mismatch_groups)

STATE_ICON = {
    STATE_PASSED: "✅",
    STATE_PARTIAL: "🟡",
    STATE_FAILED: "❌",
    STATE_ERROR: "⚠️",
    STATE_SKIPPED: "⏭️",
    STATE_INFO: "ℹ️",
}


def check_points(check: CheckResult) -> str:
    if check_state(check) == STATE_INFO:
        return _("no points")
    return f"{points(check.score)} / {points(check.max_score)}"


def html_text(text: str) -> str:
    """Plain text inside our raw HTML (<summary>): HTML-escaped, one line."""
    return escape(clean(text).replace("\n", " "), quote=False)   # element text, not an attribute


def all_correct(view: ReportView) -> str:
    if view.hidden:
        return _("Every visible check passed.")
    return _("Everything the grader checks is correct. Well done!")


def _score_line(view: ReportView) -> str:
    parts = ["**" + _("Score: %(score)s / %(max_score)s") % {"score": points(view.score), "max_score": points(view.max_score)}
             + "**"]
    if view.status != GRADED or view.refused:
        parts.append(view.status_text)
    if view.passed_line:
        parts.append(view.passed_line)
    return " · ".join(parts)


def _hidden_note(view: ReportView, about_score: bool = True) -> list[str]:
    lines = []
    for h in view.hidden:
        values = {"count": h.count, "points": points(h.max_score), "when": h.when}
        if about_score:
            text = ngettext("%(count)d more check (%(points)s points) is %(when)s; it is not counted in the score above",
                            "%(count)d more checks (%(points)s points) are %(when)s; they are not counted in the score above",
                            h.count) % values
        else:
            text = ngettext("%(count)d more check (%(points)s points) is %(when)s",
                            "%(count)d more checks (%(points)s points) are %(when)s", h.count) % values
        lines.append(f"_{text}._")
    return lines


def score_table(view: ReportView) -> list[str]:
    lines = [f"| | # | {_('Check')} | {_('Points')} |", "|:-:|:--|:--|--:|"]
    for c in view.checks:
        state = check_state(c)
        lines.append(f"| {STATE_ICON[state]} | {md_escape(c.number)} | "
                     f"{md_escape(check_label(c))} | {check_points(c)} |")
    lines.append(f"| | | **{_('Total')}** | **{points(view.score)} / {points(view.max_score)}** |")
    return lines


def mistake_heading(group: DiagnosisGroup) -> str:
    """The mistake's title, with the faces it was found on."""
    faces = ", ".join(group.faces)
    return f"{group.info.title} ({faces})" if faces else group.info.title


# Findings a student needs in front of them: the line a build refusal names,
# the input that crashed. The mapping and filtering findings restate the
# title in numbers; they wait in the collapsed part.
FINDINGS_SHOWN = ("build", "runtime")


def _findings(group: DiagnosisGroup) -> list[str]:
    lines = []
    for d in group.findings:
        where = f"**{md_escape(d.face)}:** " if d.face else ""
        hint = f" _{md_escape(truncate_middle(d.hint, TEXT_LIMIT))}_" if d.hint else ""
        detail = truncate_middle(d.detail, TEXT_LIMIT)
        lines.append(f"- {where}{md_escape(detail, line_start=not where)}{hint}")
    return lines


def diagnosis_section(group: DiagnosisGroup, level: str = "###", count: str = "",
                      collapsible: bool = True) -> list[str]:
    """One mistake: its title, one short paragraph (the count, what to do),
    and, collapsed, what was found and why it matters (left out where
    <details> cannot be used: Gradescope's summary has raw HTML off, and
    the check's own output says what was found)."""
    info = group.info
    shown = info.kind in FINDINGS_SHOWN
    lines = [f"{level} {md_escape(mistake_heading(group))}", ""]
    if shown:
        lines += _findings(group) + [""]
    lead = f"{md_escape(count)} " if count else ""
    lines += [f"{lead}**{_('What to do:')}** {info.what_to_do}", ""]
    if not collapsible:
        return lines
    more = [] if shown else _findings(group) + [""]
    more += [info.explanation, "", _("Its id: %(id)s") % {"id": md_code(info.id)}, ""]
    lines += [f"<details><summary>{html_text(_('More about this mistake'))}</summary>", "", *more,
              "</details>", ""]
    return lines


def mistake_counts(view: ReportView) -> dict[int, str]:
    """Which mistake carries which count (view.mistake_count): the only one
    of its kind carries its kind's count; several of one kind share one
    line before them (index -1 - the first one's index)."""
    by_kind: dict[str, list[int]] = {}
    for i, g in enumerate(view.diagnoses):
        by_kind.setdefault(g.info.kind, []).append(i)
    out = {}
    for kind, where in by_kind.items():
        text = view.mistake_count(kind)
        if text:
            out[where[0] if len(where) == 1 else -1 - where[0]] = text
    return out


def _diagnoses(view: ReportView, level: str, collapsible: bool = True) -> list[str]:
    if not view.diagnoses:
        return []
    counts = mistake_counts(view)
    lines = [f"{level} {_('What to fix first')}", ""]
    for i, group in enumerate(view.diagnoses):
        if -1 - i in counts:
            lines += [md_escape(counts[-1 - i]), ""]
        lines += diagnosis_section(group, level + "#", counts.get(i, ""), collapsible)
    return lines


def _build_log(view: ReportView, level: str) -> list[str]:
    if not view.build_log.strip():
        return []
    log = md_fence(truncate_middle(view.build_log), "text")
    if view.status == BUILD_ERROR:
        return [f"{level} {_('Compiler messages')}", "", log, ""]
    return []   # warnings only: in the instructor's section


def worst_cases(check: CheckResult) -> list[str]:
    """The check's worst cases (CheckResult.mismatches) as a Markdown list."""
    lines = []
    for group, rows, more in mismatch_groups(check):
        if group:
            lines += ["**" + _("Worst cases, %(group)s:") % {"group": md_escape(_(group))} + "**", ""]
        else:
            lines += ["**" + _("Worst cases:") + "**", ""]
        lines += ["- " + _("%(call)s: should %(should)s; yours %(got)s") % {
                      "call": md_escape(call, line_start=True), "should": md_escape(should), "got": md_escape(got)}
                  for call, should, got in rows]
        if more:
            lines.append("- " + _("... and %(more)d more") % {"more": more})
        lines.append("")
    return lines


def _details(view: ReportView) -> list[str]:
    lines = []
    for c in view.checks:
        output = check_output(c)
        cases = worst_cases(c)
        if not output and not cases:
            continue
        state = check_state(c)
        summary = html_text(f"{STATE_ICON[state]} {c.number} {c.title} {check_points(c)}")
        body = [inert_markdown(truncate_middle(output)), ""] if output else []
        lines += [f"<details><summary>{summary}</summary>", "", *body, *cases,
                  "</details>", ""]
    if not lines:
        return []
    glossary = [f"- {md_escape(line, line_start=True)}" for line in GLOSSARY.values()]
    return [f"<details><summary>{html_text(_('Details of each check'))}</summary>", "", *lines,
            "**" + _("Words the details use:") + "**", "", *glossary, "", "</details>", ""]


def _head(view: ReportView) -> list[str]:
    lines = []
    if view.status_explanation:
        lines += [f"**{view.status_explanation}**", ""]
    return lines


def instructor_section(view: ReportView) -> list[str]:
    """Harness facts (isolation, the grader's warnings, compiler warnings):
    collapsed, for an instructor."""
    facts = [f"- {md_escape(f, line_start=True)}" for f in view.instructor_facts]
    log = ([_("Compiler messages (warnings):"), "", md_fence(truncate_middle(view.build_log), "text"), ""]
           if view.build_log.strip() and view.status != BUILD_ERROR else [])
    return [f"<details><summary>{html_text(_('For your instructor'))}</summary>", "", *facts, "", *log,
            "</details>", ""]


def render(view: ReportView) -> str:
    """The whole report.md: what to fix first, the score table; the
    details and the instructor's section collapsed."""
    lines = ["# " + _("Environment mapping: %(submission)s") % {"submission": md_escape(view.submission)}, "",
             _score_line(view), ""]
    lines += _head(view)
    if view.status == BUILD_ERROR:
        lines += _build_log(view, "##")
    lines += _diagnoses(view, "##")
    if not view.diagnoses and view.checks and view.score >= view.max_score:
        lines += [all_correct(view), ""]
    if view.checks:
        lines += [f"## {_('Checks')}", ""] + score_table(view) + [""]
    if view.hidden:
        lines += _hidden_note(view) + [""]
    lines += _details(view)
    lines += instructor_section(view)
    return "\n".join(lines).rstrip("\n") + "\n"


def summary(view: ReportView) -> str:
    """The top-level output of results.json: what to fix, in a few lines.
    Gradescope shows the score and each test's own output beside it."""
    lines = _head(view)
    lines += _build_log(view, "###") if view.status == BUILD_ERROR else []
    lines += _diagnoses(view, "###", collapsible=False)
    if view.hidden:
        lines += _hidden_note(view, about_score=False) + [""]
    if not lines:
        lines = [_("All visible checks passed.") if view.score >= view.max_score
                 else _("See each check below for details."), ""]
    return "\n".join(lines).rstrip("\n") + "\n"
