"""A terminal summary with rich: colour where the terminal supports it
(rich decides, and honours NO_COLOR), plain text otherwise."""
from __future__ import annotations

import io
from pathlib import Path

from rich import box

from ..i18n import _, ngettext
from rich.console import Console, Group
from rich.padding import Padding
from rich.panel import Panel
from rich.table import Table
from rich.text import Text

from ..grading.results import BUILD_ERROR, GradeResult
from .text import points, seconds
from .markdown import check_points
from .view import (STATE_ERROR, STATE_FAILED, STATE_INFO, STATE_PARTIAL,
                   STATE_PASSED, STATE_SKIPPED, ReportView, build_view,
                   check_state)

STATE_STYLE = {
    STATE_PASSED: ("✓", "green"),
    STATE_PARTIAL: ("◐", "yellow"),
    STATE_FAILED: ("✗", "red"),
    STATE_ERROR: ("!", "magenta"),
    STATE_SKIPPED: ("-", "dim"),
    STATE_INFO: ("i", "cyan"),
}
LOG_LINES = 15   # compiler messages shown in the terminal; the reports have all
# Line breaks and tabs inside one line of the summary, shown as their escapes:
# a submission's exception text must not start a line of its own (a forged
# "# Score: 100/100"), as every file report already escapes it. The view has
# cleaned every other control character (text.clean).
_ONE_LINE = str.maketrans({"\n": "\\n", "\r": "\\r", "\t": "\\t", "\u2028": "\\u2028", "\u2029": "\\u2029",
                           "\x0b": "\\v", "\x0c": "\\f", "\x85": "\\x85"})


def one_line(text: str) -> str:
    return str(text).translate(_ONE_LINE)


def _score_style(view: ReportView) -> str:
    if view.max_score <= 0:
        return "dim"
    fraction = view.score / view.max_score
    return "green" if fraction >= 0.999 else "yellow" if fraction >= 0.5 else "red"


def summary(view: ReportView, report_paths: dict[str, Path] | None = None) -> Group:
    parts = []
    head = Text.assemble(
        (one_line(view.submission), "bold"), "  ",
        (f"{points(view.score)} / {points(view.max_score)}", f"bold {_score_style(view)}"),
        "  ", (view.status_text, "dim" if view.status == "graded" else "bold red"),
        "  ", (f"({seconds(view.execution_time_s)})", "dim"))
    parts.append(head)
    parts.append(Text(_("your code ran under: %(isolation)s") % {"isolation": view.isolation_text}, style="dim"))
    if view.status_explanation:
        parts.append(Text(one_line(view.status_explanation), style="red"))
    for w in view.warnings:
        parts.append(Text.assemble((_("warning: "), "bold yellow"), one_line(w)))

    if view.status == BUILD_ERROR and view.build_log.strip():
        lines = view.build_log.strip().splitlines()
        shown = "\n".join(lines[:LOG_LINES])
        more = ("\n" + _("... %(count)d more lines in the reports") % {"count": len(lines) - LOG_LINES}
                if len(lines) > LOG_LINES else "")
        parts.append(Panel(Text(shown + more), title=_("compiler messages"), box=box.ROUNDED,
                           border_style="red", expand=False))

    if view.checks:
        table = Table(box=box.SIMPLE_HEAD, show_edge=False, pad_edge=False)
        table.add_column("", no_wrap=True)
        table.add_column("#", style="dim", no_wrap=True)
        table.add_column(_("check"))
        table.add_column(_("points"), justify="right", no_wrap=True)
        for c in view.checks:
            mark, style = STATE_STYLE[check_state(c)]
            # Text, not str: rich would read "[...]" in a string as markup.
            table.add_row(Text(mark, style=style), Text(c.number), Text(one_line(c.title)),
                          Text(check_points(c), style=style))
        parts.append(table)
    for h in view.hidden:
        parts.append(Text(ngettext("%(count)d hidden check (%(points)s points), %(when)s",
                                   "%(count)d hidden checks (%(points)s points), %(when)s", h.count)
                          % {"count": h.count, "points": points(h.max_score), "when": h.when}, style="dim"))

    for group in view.diagnoses:
        faces = f" [{', '.join(group.faces)}]" if group.faces else ""
        parts.append(Text.assemble(("• ", "red"), (one_line(group.info.title), "bold"),
                                   (one_line(f"  {group.info.id}{faces}"), "dim")))
        for d in group.findings:
            where = f"{d.face}: " if d.face else ""
            parts.append(Padding(Text(one_line(f"{where}{d.detail}")), (0, 0, 0, 4), expand=False))
        parts.append(Padding(Text.assemble((_("what to do: "), "cyan"), one_line(group.info.what_to_do)),
                             (0, 0, 0, 4), expand=False))

    if report_paths:
        parts.append(Text(_("reports:"), style="dim"))
        for name in sorted(report_paths):
            parts.append(Text(f"  {report_paths[name]}", style="dim"))
    return Group(*parts)


def print_summary(result: GradeResult, console: Console | None = None,
                  report_paths: dict[str, Path] | None = None,
                  include_hidden: bool = False) -> None:
    # highlight=False: rich must not colour numbers inside the student's text.
    console = console or Console(highlight=False)
    console.print(summary(build_view(result, include_hidden), report_paths), highlight=False)


def summary_text(result: GradeResult, width: int = 100, include_hidden: bool = False) -> str:
    """The summary as plain text (no colour), e.g. for logs and tests."""
    console = Console(width=width, color_system=None, force_terminal=False, record=True,
                      file=io.StringIO(), highlight=False)
    print_summary(result, console, include_hidden=include_hidden)
    return "\n".join(line.rstrip() for line in console.export_text().splitlines()) + "\n"
