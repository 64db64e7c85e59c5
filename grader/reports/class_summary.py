"""The class summary grade-all writes beside the gradebook: summary.md,
summary.html (self-contained, charts embedded, a link to every student's
report) and the two charts (score histogram, speed against accuracy).

Student names are folder and archive names chosen by students, and the
error of an ungradable row can quote them: hostile text. So summary.md
escapes them as Markdown, summary.html is rendered with raw HTML disabled
plus a Content-Security-Policy that allows no script, and chart labels
never reach matplotlib's mathtext ($...$ in a name once crashed grade-all).

    write_summary(rows, out)   rows: grade_all.Row, in gradebook order
"""
from __future__ import annotations

import base64
import html
from collections import Counter
from pathlib import Path
from urllib.parse import quote

from ..results import UNGRADABLE
from .text import clean, md_code, md_escape, md_fence

HISTOGRAM = "summary_histogram.png"
SPEED_CHART = "summary_speed_accuracy.png"
STUDENT_REPORT = "report.html"
# The page needs inline styles and data: images, nothing else: no script,
# no request anywhere (a student's report is a relative link, which
# default-src does not govern).
CSP = "default-src 'none'; img-src data:; style-src 'unsafe-inline'; base-uri 'none'; form-action 'none'"


def check_names(rows) -> list[str]:
    """Check columns in rubric order (the order results.json lists them)."""
    names: list[str] = []
    for r in rows:
        names += [n for n in r.checks if n not in names]
    return names


def plain_label(text: str, limit: int = 28) -> str:
    """A string matplotlib draws as it is: an unescaped $ would start
    mathtext (and a bad expression raises while drawing). Cut to `limit`
    characters, so that a long name cannot push the legend off the chart."""
    text = clean(text).replace("\n", " ")
    if len(text) > limit:
        text = text[: limit - 1] + "…"
    return text.replace("$", r"\$")


def _histogram(rows, path: Path) -> None:
    from matplotlib.figure import Figure   # the Figure API: no pyplot global state
    top = max([r.max_score for r in rows] + [1.0])
    fig = Figure(figsize=(6.4, 3.2), dpi=100)
    ax = fig.subplots()
    graded = [r.score for r in rows if r.status != UNGRADABLE]
    ax.hist(graded, bins=20, range=(0, top), color="#4a7bd0", edgecolor="white")
    ax.set_xlim(0, top)
    ax.set_xlabel("score")
    ax.set_ylabel("submissions")
    ungradable = len(rows) - len(graded)
    ax.set_title(f"Scores of {len(graded)} submissions" + (f" ({ungradable} ungradable, not shown)" if ungradable else ""))
    ax.yaxis.get_major_locator().set_params(integer=True)
    fig.tight_layout()
    fig.savefig(path, metadata={"Software": None})


def _score_colour(score: float, top: float) -> str:
    fraction = score / top if top > 0 else 0.0
    return "#2e9d48" if fraction >= 0.999 else "#e0a21b" if fraction >= 0.5 else "#d1382c"


def _speed_chart(rows, path: Path) -> int:
    """Every submission the speed check timed, as a point on the study's
    chart (docs/study/): time per lookup against the RMS error on the
    study's environment, coloured by score. Returns how many points it drew."""
    import matplotlib
    from ..study import chart
    from ..study.run import read_csv
    from ..study import STUDY_CSV
    methods = read_csv(STUDY_CSV) if STUDY_CSV.is_file() else []
    top = max([r.max_score for r in rows] + [1.0])
    points = [{"label": plain_label(r.student), chart.TIME_COLUMN: r.metrics["ns_per_lookup"],
               "uniform_smooth_rms": r.metrics["uniform_smooth_rms"], "color": _score_colour(r.score, top)}
              for r in rows if r.metrics.get("ns_per_lookup", 0) > 0 and r.metrics.get("uniform_smooth_rms", 0) > 0]
    # An instructor's matplotlibrc with usetex would hand names to LaTeX.
    with matplotlib.rc_context({"text.usetex": False}):
        chart.draw(methods, points, path, panels=chart.PANELS[:1],
                   title=f"Speed against accuracy: {len(points)} submissions")
    return len(points)


def _diagnosis_counts(rows) -> list[tuple[str, str, int]]:
    from ..diagnoses import describe
    counts = Counter(d for r in rows for d in r.diagnoses)

    def title(d: str) -> str:
        try:
            return describe(d).title
        except KeyError:   # an id from an older grader's results.json
            return d
    return [(d, title(d), n) for d, n in counts.most_common()]


def report_link(student: str) -> str:
    """The relative URL of a student's report.html (the name percent-encoded,
    so no character of it can end the attribute or change the path)."""
    return f"{quote(student, safe='')}/{STUDENT_REPORT}"


def _item(value) -> str:
    """One entry of grade-all's summary data (a name, or a small record) as plain text."""
    if isinstance(value, dict):
        return ", ".join(f"{k} {v}" for k, v in value.items() if v not in (None, ""))
    return str(value)


def _skipped_section(skipped) -> list[str]:
    if not skipped:
        return []
    lines = ["", "## Entries that were not graded", "",
             "What the class folder held besides submissions, and why each was left out.", ""]
    lines += [f"- {md_code(str(e.get('entry', '')))}: {md_escape(str(e.get('reason', '')))}" for e in skipped]
    return lines


def _roster_section(roster) -> list[str]:
    if not roster:
        return []
    lines = ["", "## Roster", "",
             f"{md_code(str(roster.get('file', '')))}: {int(roster.get('students', 0))} students, "
             f"{int(roster.get('matched', 0))} matched to a submission."]
    for key, title in (("missing", "Handed in nothing"), ("unmatched", "Submissions matching no one on the roster")):
        entries = roster.get(key) or []
        if entries:
            lines += ["", f"**{title}:**", ""]
            lines += [f"- {md_escape(_item(e), line_start=True)}" for e in entries]
    return lines


def _similarity_section(similarity) -> list[str]:
    """The most similar pairs and their shared passages. Passages are the
    students' code: fenced, never rendered."""
    if not similarity:
        return []
    pairs = similarity.get("pairs") or []
    lines = ["", "## Most similar pairs", "",
             f"{int(similarity.get('compared', 0))} submissions compared with "
             f"{md_escape(str(similarity.get('tool', 'a similarity tool')))}"
             + (f", the template ({md_code(str(similarity['boilerplate']))}) not counted"
                if similarity.get("boilerplate") else "")
             + f"; pairs sharing at least {float(similarity.get('min_listed', 0)):.0%} are listed. "
             "A high share is a reason to look, not a verdict.", ""]
    if not pairs:
        lines.append("No pair reaches that share.")
    for p in pairs:
        a, b = str(p.get("a", "")), str(p.get("b", ""))
        lines += ["", f"### {md_escape(a)} and {md_escape(b)}: {float(p.get('similarity', 0)):.0%}", "",
                  f"{float(p.get('share_a', 0)):.0%} of {md_escape(a)}'s code and "
                  f"{float(p.get('share_b', 0)):.0%} of {md_escape(b)}'s, "
                  f"{int(p.get('shared_tokens', 0))} tokens in common.", ""]
        for passage in p.get("passages") or []:
            for side, name in (("a", a), ("b", b)):
                first, last = (list(passage.get(f"{side}_lines") or [0, 0]) + [0, 0])[:2]
                lines += [f"{md_escape(name)}, lines {int(first)}-{int(last)}:", "",
                          md_fence(str(passage.get(f"{side}_text", "")), "cpp"), ""]
    not_compared = similarity.get("not_compared") or []
    if not_compared:
        lines += ["", "**Not compared:**", ""]
        lines += [f"- {md_escape(str(e.get('student', '')), line_start=True)}: {md_escape(str(e.get('reason', '')))}"
                  for e in not_compared]
    return lines


def summary_markdown(rows, charted: int, linked: set[str] | None = None, data: dict | None = None) -> str:
    """summary.md. `linked`: students whose report.html exists (they get a
    link). `data`: grade-all's summary data (skipped entries, roster,
    similarity), all of it the students' or the instructor's text."""
    linked = linked or set()
    data = data or {}
    statuses = Counter(r.status for r in rows)
    graded = [r.score for r in rows if r.status != UNGRADABLE]
    lines = ["# Class summary", "",
             f"{len(rows)} submissions: " + ", ".join(f"{n} {md_escape(s)}" for s, n in sorted(statuses.items())) + "."]
    if graded:
        ordered = sorted(graded)
        median = (ordered[(len(ordered) - 1) // 2] + ordered[len(ordered) // 2]) / 2
        top = max(r.max_score for r in rows)
        lines.append(f"Median score {median:g} / {top:g}; "
                     f"{sum(s >= top for s in graded)} full marks, {sum(s == 0 for s in graded)} at zero.")
    lines += ["", f"![score histogram]({HISTOGRAM})", "", "## Most common diagnoses", ""]
    counted = _diagnosis_counts(rows)
    if counted:
        lines += ["| diagnosis | what it means | submissions |", "|---|---|---:|"]
        lines += [f"| {md_code(d)} | {md_escape(title)} | {n} |" for d, title, n in counted]
    else:
        lines.append("None: no submission was found at fault.")
    lines += ["", "## Speed against accuracy", "",
              f"{charted} submissions measured by the speed check (stars: green full marks, amber half "
              "or more, red less), on the study's chart of the lookup methods (docs/study/). "
              "Submissions that crashed or did not build have no point.", "",
              f"![speed against accuracy]({SPEED_CHART})"]
    failed = [r for r in rows if r.error]
    if failed:
        lines += ["", "## Could not be graded (the grader failed, not the student)", ""]
        lines += [f"- {md_escape(r.student, line_start=True)}: {md_escape(r.error)}" for r in failed]
    lines += ["", "## Students' reports", ""]
    for r in rows:
        if r.student in linked:
            lines.append(f"- [{md_escape(r.student)}](<{report_link(r.student)}>)")
        else:
            lines.append(f"- {md_escape(r.student, line_start=True)} (no report)")
    lines += _skipped_section(data.get("skipped"))
    lines += _roster_section(data.get("roster"))
    lines += _similarity_section(data.get("similarity"))
    return "\n".join(lines) + "\n"


def summary_html(rows, markdown_text: str, out: Path, linked: set[str] | None = None) -> str:
    """summary.md as one self-contained page (charts embedded), and the
    gradebook as a table whose student names link to their reports."""
    from markdown_it import MarkdownIt
    linked = linked or set()
    # Raw HTML off: whatever escaping summary.md missed still shows as text.
    body = MarkdownIt("commonmark", {"html": False}).enable("table").render(markdown_text)
    for name in (HISTOGRAM, SPEED_CHART):
        data = base64.b64encode((out / name).read_bytes()).decode()
        body = body.replace(f'src="{name}"', f'src="data:image/png;base64,{data}"')
    names = check_names(rows)
    # A roster (grade-all --roster) adds who each student is.
    who = [k for k in ("student_id", "name", "email") if any(getattr(r, k, "") for r in rows)]
    head = "".join(f"<th>{html.escape(h.replace('_', ' '))}</th>"
                   for h in ["student", *who, "score", "status", *names, "diagnoses"])
    lines = []
    for r in rows:
        student = html.escape(clean(r.student))
        if r.student in linked:
            student = f'<a href="{html.escape(report_link(r.student))}">{student}</a>'
        cells = [student, *[html.escape(clean(str(getattr(r, k, "")))) for k in who],
                 f"{r.score:g} / {r.max_score:g}", html.escape(r.status),
                 *[f"{r.checks[n]:g}" if n in r.checks else "" for n in names], html.escape(" ".join(r.diagnoses))]
        cls = ' class="bad"' if r.status != "graded" else ""
        lines.append(f"<tr{cls}>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    table = (f'<h2>Gradebook</h2><div class="wide"><table><thead><tr>{head}</tr></thead>'
             f"<tbody>{''.join(lines)}</tbody></table></div>")
    style = ("body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}"
             "table{border-collapse:collapse;margin:1em 0}th,td{border:1px solid #ccc;padding:3px 8px;"
             "text-align:left;font-variant-numeric:tabular-nums}td:nth-child(2){white-space:nowrap}th{background:#f3f3f3}tr.bad td{background:#fdeeee}"
             "img{max-width:100%}.wide{overflow-x:auto}p,li,td:first-child{overflow-wrap:anywhere}"
             # A phone: a table wider than the screen scrolls by itself, the page does not.
             "table{display:block;overflow-x:auto;max-width:100%}"
             "@media (max-width:600px){body{margin:1em auto;padding:0 8px}}")
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f'<meta http-equiv="Content-Security-Policy" content="{CSP}">'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>Class summary</title><style>{style}</style></head><body>{body}{table}</body></html>\n")


def write_summary(rows, out: Path, data: dict | None = None) -> None:
    """summary.md and summary.html: score histogram, most common diagnoses,
    every submission on the speed-against-accuracy chart, a link to every
    student's report; with grade-all's `data`, the entries it skipped, the
    roster's matches and the most similar pairs."""
    from . import write_atomic
    out = Path(out)
    _histogram(rows, out / HISTOGRAM)
    charted = _speed_chart(rows, out / SPEED_CHART)
    linked = {r.student for r in rows if (out / r.student / STUDENT_REPORT).is_file()}
    text = summary_markdown(rows, charted, linked, data)
    write_atomic(out / "summary.md", text)
    write_atomic(out / "summary.html", summary_html(rows, text, out, linked))
