"""The class summary grade-all writes beside the gradebook: summary.md,
summary.html and the two charts (score histogram, speed against accuracy).

summary.html is the page an instructor reads: the class at a glance, what
needs their attention (ungradable students, results worth grading again,
roster mismatches), a table of students with score, status and first
diagnosis (each linking to its report), the charts, and similar submissions
grouped into clusters, each collapsed. It is styled by report.html's own
stylesheet (grader/reports/html.py), self-contained (charts embedded).

Student names are folder and archive names chosen by students, and the
error of an ungradable row can quote them: hostile text. So summary.md
escapes them as Markdown, summary.html is rendered with raw HTML disabled
plus a Content-Security-Policy that allows no script, and chart labels
never reach matplotlib's mathtext ($...$ in a name once crashed grade-all).

    write_summary(rows, out)   rows: grade_all.Row, in gradebook order
"""
from __future__ import annotations

from collections import Counter
from pathlib import Path
from urllib.parse import quote

from ..course.class_files import MISSING
from ..grading.results import BUILD_ERROR, GRADED, TIMEOUT, UNGRADABLE
from ..i18n import N_, Translated, _, ngettext
from .text import clean, md_code, md_escape, md_fence, points

HISTOGRAM = "summary_histogram.png"
SPEED_CHART = "summary_speed_accuracy.png"
STUDENT_REPORT = "report.html"

# A row's status as the page shows it (gradebook.csv and summary.json keep the id):
# short, for the status column's pill in either language.
STATUS_WORDS = Translated({
    GRADED: N_("graded"),
    BUILD_ERROR: N_("compile error"),
    TIMEOUT: N_("timed out"),
    UNGRADABLE: N_("ungradable"),
    MISSING: N_("nothing handed in"),
})
# The roster's lists, in the order the page shows them.
ROSTER_LISTS = (("missing", N_("Handed in nothing")), ("unmatched", N_("Submissions matching no one on the roster")),
                ("left_out", N_("Left out of the roster")))
GRADER_FAILED = N_("Could not be graded (the grader failed, not the student)")
NO_DIAGNOSES = N_("None: no submission was found at fault.")
NO_PAIR = N_("No pair reaches that share.")
SKIPPED_INTRO = N_("What the class folder held besides submissions, and why each was left out.")


def status_word(status: str) -> str:
    return STATUS_WORDS.get(status, status)


def status_counts(rows) -> str:
    """"4 graded, 1 timed out": each status with its number of students."""
    counts = Counter(r.status for r in rows)
    return _(", ").join(f"{n} {status_word(s)}" for s, n in sorted(counts.items()))
# The page needs inline styles and data: images, nothing else: no script,
# no request anywhere (a student's report is a relative link, which
# default-src does not govern).
CSP = "default-src 'none'; img-src data:; style-src 'unsafe-inline'; base-uri 'none'; form-action 'none'"
# What the class page adds to report.html's stylesheet.
CLASS_CSS = """
table.students td { vertical-align: top; }
/* Fixed columns: a long name wraps in its own column instead of pushing
   status and diagnosis off the page (the table once needed scrolling at 1280 px). */
table.checks.students { table-layout: fixed; width: 100%; }
table.checks.students th.c-who { width: 30%; }
table.checks.students th.c-pts { width: 13rem; }     /* rem: a th's own font is smaller */
table.checks.students th.c-state { width: 9.5rem; }
table.checks.students th { white-space: nowrap; }
table.checks.students td.who { overflow-wrap: anywhere; }
.students .who > a, .students .who { font-weight: 600; }
.students .wholine { font-weight: 400; font-size: .78rem; color: var(--muted); margin-top: .15em; }
.students .fileline { font-family: var(--mono, monospace); }
.students .diag { color: var(--muted); overflow-wrap: anywhere; }
.students .diag strong { color: var(--text); font-weight: 500; }
/* The bar goes above the number rather than over the next column when the cell is narrow. */
table.checks.students td.pts { white-space: normal; }
.students td.pts .score { white-space: nowrap; }
table.checks.points th, table.checks.points td { overflow-wrap: normal; }
.students .who { font-weight: 600; }
.students .diag { color: var(--muted); }
.students .diag strong { color: var(--text); font-weight: 500; }
.wide { overflow-x: auto; }
.wide table.checks { width: auto; min-width: 100%; }
.cluster { background: var(--card); border: 1px solid var(--border); border-left: 5px solid var(--partial);
  border-radius: 12px; padding: 12px 18px; margin: 12px 0; }
.cluster > summary { cursor: pointer; font-weight: 600; }
.cluster .pair-title { margin: 1em 0 .3em; font-weight: 600; }
.passage { margin: .4em 0 .8em; }
.passage > summary { cursor: pointer; color: var(--muted); }
.side-by-side { display: grid; grid-template-columns: repeat(auto-fit, minmax(320px, 1fr)); gap: 12px; }
.side-by-side pre { max-height: 24em; overflow: auto; }
ul.plain { padding-left: 1.2em; margin: .4em 0; }
/* A phone: each student two lines, the name with score and status on the
   first, the diagnosis under them; no column is off to the side. */
@media (max-width: 640px) {
  table.checks.students thead { display: none; }
  table.checks.students, table.checks.students tbody { display: block; }
  table.checks.students tr { display: grid; grid-template-columns: 1fr auto auto; column-gap: 8px;
    align-items: baseline; padding: 8px 12px; border-bottom: 1px solid var(--border); }
  table.checks.students td { display: block; border: 0; padding: 0; min-width: 0; }
  table.checks.students td.diag { grid-column: 1 / -1; margin-top: .2em; }
  table.checks.students .bar, table.checks.students .fileline { display: none; }
}
"""


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
    import matplotlib
    from ..study import chart
    with matplotlib.rc_context(chart._font_settings()):   # the study chart's fonts: Japanese needs its own
        _draw_histogram(rows, path)


def _draw_histogram(rows, path: Path) -> None:
    from matplotlib.figure import Figure   # the Figure API: no pyplot global state
    top = max([r.max_score for r in rows] + [1.0])
    fig = Figure(figsize=(6.4, 3.2), dpi=100)
    ax = fig.subplots()
    graded = [r.score for r in rows if r.status != UNGRADABLE]
    ax.hist(graded, bins=20, range=(0, top), color="#4a7bd0", edgecolor="white")
    ax.set_xlim(0, top)
    ax.set_xlabel(_("score"))
    ax.set_ylabel(_("submissions"))
    ungradable = len(rows) - len(graded)
    title = ngettext("Scores of %(count)d submission", "Scores of %(count)d submissions", len(graded)) % {
        "count": len(graded)}
    if ungradable:
        title += " " + _("(%(count)d ungradable, not shown)") % {"count": ungradable}
    ax.set_title(title)
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
    points = [{"label": plain_label(display_name(r)), chart.TIME_COLUMN: r.metrics["ns_per_lookup"],
               "uniform_smooth_rms": r.metrics["uniform_smooth_rms"], "color": _score_colour(r.score, top)}
              for r in rows if r.metrics.get("ns_per_lookup", 0) > 0 and r.metrics.get("uniform_smooth_rms", 0) > 0]
    # An instructor's matplotlibrc with usetex would hand names to LaTeX.
    with matplotlib.rc_context({"text.usetex": False}):
        chart.draw(methods, points, path, panels=chart.PANELS[:1],
                   title=ngettext("Speed against accuracy: %(count)d submission",
                                  "Speed against accuracy: %(count)d submissions", len(points)) % {"count": len(points)})
    return len(points)


def language_code() -> str:
    from ..i18n import language
    return language()


def _diagnosis_counts(rows) -> list[tuple[str, str, int]]:
    counts = Counter(d for r in rows for d in r.diagnoses)
    return [(d, _diagnosis_title(d), n) for d, n in counts.most_common()]


def report_link(student: str) -> str:
    """The relative URL of a student's report.html (the name percent-encoded,
    so no character of it can end the attribute or change the path)."""
    return f"{quote(student, safe='')}/{STUDENT_REPORT}"


def entry_text(value) -> str:
    """One entry of grade-all's summary data (a name, or a student: "name (id, email)") as plain text."""
    if isinstance(value, dict):
        extra = ", ".join(str(value[k]) for k in ("id", "email") if value.get(k) not in (None, ""))
        return str(value.get("name") or _("(no name)")) + (f" ({extra})" if extra else "")
    return str(value)


def first_diagnosis(row) -> str:
    """The id of the first thing the report names (its cause comes first), or ""."""
    return getattr(row, "first_diagnosis", "") or (row.diagnoses[0] if row.diagnoses else "")


def _diagnosis_title(d: str) -> str:
    from ..grading.catalogue import describe
    try:
        return describe(d).title
    except KeyError:   # an id from an older grader's results.json
        return d


def similarity_clusters(pairs: list[dict]) -> list[dict]:
    """The listed pairs grouped into clusters of students (connected by any
    listed pair), the most similar cluster first: a copy passed around a
    group shows as one group, not as every pair in it."""
    parent: dict[str, str] = {}

    def root(x: str) -> str:
        while parent.setdefault(x, x) != x:
            x = parent[x]
        return x
    for p in pairs:
        a, b = root(str(p.get("a", ""))), root(str(p.get("b", "")))
        if a != b:
            parent[max(a, b)] = min(a, b)
    groups: dict[str, dict] = {}
    for p in pairs:
        g = groups.setdefault(root(str(p.get("a", ""))), {"students": set(), "pairs": []})
        g["students"] |= {str(p.get("a", "")), str(p.get("b", ""))}
        g["pairs"].append(p)
    out = [{"students": sorted(g["students"]), "similarity": max(float(p.get("similarity", 0)) for p in g["pairs"]),
            "pairs": sorted(g["pairs"], key=lambda p: (-float(p.get("similarity", 0)), str(p.get("a")), str(p.get("b"))))}
           for g in groups.values()]
    return sorted(out, key=lambda c: (-c["similarity"], c["students"]))


def _skipped_section(skipped) -> list[str]:
    if not skipped:
        return []
    lines = ["", "## " + _("Entries that were not graded"), "", _(SKIPPED_INTRO), ""]
    lines += [f"- {md_code(str(e.get('entry', '')))}: {md_escape(str(e.get('reason', '')))}" for e in skipped]
    return lines


def _roster_section(roster) -> list[str]:
    if not roster:
        return []
    lines = ["", "## " + _("Roster"), "", md_code(str(roster.get("file", ""))) + ": " + _roster_counts(roster) + "."]
    for key, title in ROSTER_LISTS:
        entries = roster.get(key) or []
        if entries:
            lines += ["", f"**{_(title)}:**", ""]
            lines += [f"- {md_escape(entry_text(e), line_start=True)}" for e in entries]
    return lines


def _similarity_section(similarity) -> list[str]:
    """The clusters of similar submissions, each pair's shares and shared
    passages (at most MAX_PASSAGES per pair, cut to a length: never whole
    files). Passages are the students' code: fenced, never rendered."""
    if not similarity:
        return []
    pairs = similarity.get("pairs") or []
    lines = ["", "## " + _("Most similar pairs"), "", _similarity_intro(similarity, md_escape, md_code), ""]
    if not pairs:
        lines.append(_(NO_PAIR))
    for n, cluster in enumerate(similarity_clusters(pairs), 1):
        lines += ["", "### " + _cluster_title(n, cluster, md_escape), ""]
        for p in cluster["pairs"]:
            a, b = str(p.get("a", "")), str(p.get("b", ""))
            lines += [f"**{_pair_title(a, b, p, md_escape)}**: {_pair_shares(a, b, p, md_escape)}", ""]
            for passage in p.get("passages") or []:
                for side, name in (("a", a), ("b", b)):
                    first, last = _lines(passage, side)
                    lines += [_("%(name)s, lines %(first)d-%(last)d:") % {"name": md_escape(name), "first": first,
                                                                          "last": last}, "",
                              md_fence(str(passage.get(f"{side}_text", "")), "cpp"), ""]
    not_compared = similarity.get("not_compared") or []
    if not_compared:
        lines += ["", "**" + _("Not compared:") + "**", ""]
        lines += [f"- {md_escape(str(e.get('student', '')), line_start=True)}: {md_escape(str(e.get('reason', '')))}"
                  for e in not_compared]
    return lines


def _similarity_intro(similarity, text, code) -> str:
    """The similarity section's first paragraph; `text` and `code` escape
    what the data holds for the page's format."""
    words = {"count": int(similarity.get("compared", 0)),
             "tool": text(str(similarity.get("tool") or _("a similarity tool"))),
             "share": f"{float(similarity.get('min_listed', 0)):.0%}"}
    if similarity.get("boilerplate"):
        words["template"] = code(str(similarity["boilerplate"]))
        return _("%(count)d submissions compared with %(tool)s, the template (%(template)s) not counted; pairs "
                 "sharing at least %(share)s are listed, grouped into clusters of students. A high share is a "
                 "reason to look, not a verdict.") % words
    return _("%(count)d submissions compared with %(tool)s; pairs sharing at least %(share)s are listed, grouped "
             "into clusters of students. A high share is a reason to look, not a verdict.") % words


def _cluster_title(n: int, cluster: dict, text) -> str:
    return ngettext("Cluster %(n)d: %(names)s (%(count)d student, up to %(share)s)",
                    "Cluster %(n)d: %(names)s (%(count)d students, up to %(share)s)", len(cluster["students"])) % {
        "n": n, "names": _(", ").join(text(s) for s in cluster["students"]), "count": len(cluster["students"]),
        "share": f"{cluster['similarity']:.0%}"}


def _pair_title(a: str, b: str, p: dict, text) -> str:
    return _("%(a)s and %(b)s: %(share)s") % {"a": text(a), "b": text(b),
                                              "share": f"{float(p.get('similarity', 0)):.0%}"}


def _pair_shares(a: str, b: str, p: dict, text) -> str:
    return _("%(share_a)s of %(a)s's code and %(share_b)s of %(b)s's, %(tokens)d tokens in common.") % {
        "share_a": f"{float(p.get('share_a', 0)):.0%}", "a": text(a), "share_b": f"{float(p.get('share_b', 0)):.0%}",
        "b": text(b), "tokens": int(p.get("shared_tokens", 0))}


def _roster_counts(roster: dict) -> str:
    students, matched = int(roster.get("students", 0)), int(roster.get("matched", 0))
    return ngettext("%(students)d student, %(matched)d matched to a submission",
                    "%(students)d students, %(matched)d matched to a submission", students) % {
        "students": students, "matched": matched}


def _marks_line(graded: list[float], top: float) -> str:
    """"Median score 7 of 10; 2 full marks, 1 at zero"."""
    full, zero = sum(s >= top for s in graded), sum(s == 0 for s in graded)
    return (_("Median score %(median)s of %(top)s") % {"median": points(median(graded)), "top": points(top)}
            + _("; ") + ngettext("%(count)d full mark", "%(count)d full marks", full) % {"count": full}
            + _(", ") + _("%(count)d at zero") % {"count": zero})


def _lines(passage: dict, side: str) -> tuple[int, int]:
    first, last = (list(passage.get(f"{side}_lines") or [0, 0]) + [0, 0])[:2]
    return int(first), int(last)


def _score_cell(r) -> str:
    return f"{points(r.score)} / {points(r.max_score)}"


def summary_markdown(rows, charted: int, linked: set[str] | None = None, data: dict | None = None) -> str:
    """summary.md. `linked`: students whose report.html exists (they get a
    link). `data`: grade-all's summary data (skipped entries, roster,
    similarity), all of it the students' or the instructor's text."""
    linked = linked or set()
    data = data or {}
    graded = [r.score for r in rows if r.status != UNGRADABLE]
    lines = ["# " + _("Class summary"), "",
             _submissions_count(rows) + _(": ") + md_escape(status_counts(rows)) + "."]
    if graded:
        lines.append(_marks_line(graded, max(r.max_score for r in rows)) + ".")
    failed = [r for r in rows if r.error]
    if failed:
        lines += ["", "## " + _(GRADER_FAILED), ""]
        lines += [f"- {md_escape(r.student, line_start=True)}: {md_escape(r.error)}" for r in failed]
    lines += ["", "## " + _("Students"), "",
              f"| {_('Student')} | {_('Score')} | {_('Status')} | {_('First diagnosis')} |", "|---|---:|---|---|"]
    for r in rows:
        who = md_escape(display_name(r))
        name = f"[{who}](<{report_link(r.student)}>)" if r.student in linked else f"{who} " + _("(no report)")
        d = first_diagnosis(r)
        diagnosis = f"{md_escape(_diagnosis_title(d))} ({md_code(d)})" if d else ""
        lines.append(f"| {name} | {_score_cell(r)} | {md_escape(status_word(r.status))} | {diagnosis} |")
    lines += ["", f"![{_('Scores')}]({HISTOGRAM})", "", "## " + _("Most common diagnoses"), ""]
    counted = _diagnosis_counts(rows)
    if counted:
        lines += [f"| {_('Diagnosis')} | {_('What it means')} | {_('Submissions')} |", "|---|---|---:|"]
        lines += [f"| {md_code(d)} | {md_escape(title)} | {n} |" for d, title, n in counted]
    else:
        lines.append(_(NO_DIAGNOSES))
    lines += ["", "## " + _("Speed against accuracy"), "", _speed_caption(charted), "",
              f"![{_('Speed against accuracy')}]({SPEED_CHART})"]
    lines += _skipped_section(data.get("skipped"))
    lines += _roster_section(data.get("roster"))
    lines += _similarity_section(data.get("similarity"))
    return "\n".join(lines) + "\n"


def median(values: list[float]) -> float:
    ordered = sorted(values)
    return (ordered[(len(ordered) - 1) // 2] + ordered[len(ordered) // 2]) / 2


def _submissions_count(rows) -> str:
    return ngettext("%(count)d submission", "%(count)d submissions", len(rows)) % {"count": len(rows)}


def _speed_caption(charted: int) -> str:
    return ngettext("%(count)d submission measured by the speed check (stars: green full marks, amber half or "
                    "more, red less), on the study's chart of the lookup methods (docs/study/). Submissions that "
                    "crashed or did not build have no point.",
                    "%(count)d submissions measured by the speed check (stars: green full marks, amber half or "
                    "more, red less), on the study's chart of the lookup methods (docs/study/). Submissions that "
                    "crashed or did not build have no point.", charted) % {"count": charted}


# ---- summary.html -----------------------------------------------------------------


def _status_class(r) -> str:
    if r.status == UNGRADABLE:
        return "skipped"
    if r.status != GRADED:
        return "failed"
    fraction = r.score / r.max_score if r.max_score > 0 else 0.0
    return "passed" if fraction >= 0.999 else "partial" if fraction >= 0.5 else "failed"


def _student_link(r, linked: set[str]) -> str:
    from .html import e
    name = e(r.student)
    return f'<a href="{e(report_link(r.student))}">{name}</a>' if r.student in linked else name


def _hero(rows) -> str:
    from .html import _score_class, e
    graded = [r.score for r in rows if r.status != UNGRADABLE]
    top = max([r.max_score for r in rows] + [0.0])
    mid = median(graded) if graded else 0.0
    pct = 0.0 if top <= 0 else max(0.0, min(100.0, 100 * mid / top))
    marks = " · " + _marks_line(graded, top) if graded and top > 0 else ""
    median_text = _("Median score %(median)s of %(top)s") % {"median": points(mid), "top": points(top)}
    return f"""
<header class="hero">
  <div class="who">
    <p class="eyebrow">{e(_("Cube-map environment mapping · class summary"))}</p>
    <h1>{e(_submissions_count(rows))}</h1>
    <p class="meta">{e(status_counts(rows))}{e(marks)}</p>
  </div>
  <div class="ring {_score_class(mid, top, GRADED)}" style="--p:{pct:.1f}" role="img"
       aria-label="{e(median_text)}">
    <div><strong>{e(points(mid))}</strong><span>{e(_("of %(top)s") % {"top": points(top)})}</span></div>
  </div>
</header>"""


def _attention(rows, data: dict) -> str:
    """Callouts for what needs the instructor: ungradable students, results
    worth grading again, roster mismatches."""
    from .html import e
    out = []
    failed = [r for r in rows if r.error]
    if failed:
        items = "".join(f"<li><strong>{e(r.student)}</strong>: {e(r.error)}</li>" for r in failed)
        out.append(f'<div class="callout failed"><strong>{e(_(GRADER_FAILED))}.</strong>'
                   f'<ul class="plain">{items}</ul></div>')
    names = {r.student: display_name(r) for r in rows}    # the roster's names, as the table shows them
    again = data.get("grade_again") or {}
    if again.get("students"):
        n = len(again["students"])
        said = ngettext("%(count)d result says %(statuses)s", "%(count)d results say %(statuses)s", n) % {
            "count": n, "statuses": _(" or ").join(status_word(s) for s in again.get("statuses", []))}
        why = ngettext("which another process can cause: running grade-all again grades it again",
                       "which another process can cause: running grade-all again grades them again", n)
        out.append(f'<div class="callout partial"><strong>{e(said)}</strong>{e(_(", "))}{e(why)}{e(_(": "))}'
                   f'{e(_(", ").join(names.get(s, s) for s in again["students"]))}.</div>')
    own = data.get("own_timeouts") or {}
    if own.get("students"):
        n = len(own["students"])
        kept = ngettext("%(count)d timeout kept", "%(count)d timeouts kept", n) % {"count": n}
        out.append(f'<div class="callout passed"><strong>{e(kept)}</strong> '
                   f'({e("; ".join(names.get(s, s) for s in own["students"]))}){e(_(": "))}'
                   f'{e(_(own.get("why", "")) if own.get("why") else "")}{e(_("."))}</div>')
    roster = data.get("roster") or {}
    for key, title in ROSTER_LISTS:
        entries = roster.get(key) or []
        if entries:
            items = "".join(f"<li>{e(entry_text(x))}</li>" for x in entries)
            cls = "passed" if key == "left_out" else "partial"
            out.append(f'<div class="callout {cls}"><strong>{e(_(title))} ({len(entries)}).</strong>'
                       f'<ul class="plain">{items}</ul></div>')
    return "\n".join(out)


def display_name(r) -> str:
    """Who a row is, as the instructor knows them: the roster's name, else
    the folder or archive name (a Canvas download's "doejane_12345_..." is
    nobody's name, so it comes second, in the line under the name)."""
    return getattr(r, "name", "") or r.student


def _who_line(r) -> str:
    """The muted line under a name: the roster's id and email, and the
    entry of the class folder it was matched to (when that is not the name)."""
    from .html import e
    ids = " · ".join(e(x) for x in (getattr(r, "student_id", ""), getattr(r, "email", "")) if x)
    out = f'<div class="wholine">{ids}</div>' if ids else ""
    if getattr(r, "name", "") and r.student != r.name:   # a phone leaves the file out (the link goes there)
        out += f'<div class="wholine fileline">{e(r.student)}</div>'
    return out


def _students_table(rows, linked: set[str]) -> str:
    """One line per student: who (the roster's name first), score, status,
    the first diagnosis. Fixed columns, so the diagnosis is never pushed off
    to the right of a long name; a phone stacks it under the name."""
    from .html import STATE_MARK, e
    body = []
    for r in rows:
        cls = _status_class(r)
        pct = 0.0 if r.max_score <= 0 else max(0.0, min(100.0, 100 * r.score / r.max_score))
        # The bar says the points (a timeout that kept 98 of 100 is not red); the pill says the status.
        points_cls = "passed" if pct >= 99.9 else "partial" if pct >= 50 else "failed"
        bar = f'<span class="bar {points_cls}"><span style="width:{pct:.1f}%"></span></span>' if r.max_score > 0 else ""
        d = first_diagnosis(r)
        more = len(set(r.diagnoses) - {d})
        diagnosis = (f'<strong>{e(_diagnosis_title(d))}</strong> <span class="id">{e(d)}</span>'
                     + (f' <span class="more">{e(_("(+%(count)d more)") % {"count": more})}</span>' if more else "")
                     ) if d else ""
        if r.error:
            diagnosis = e(r.error)
        mark = {"passed": STATE_MARK["passed"], "failed": STATE_MARK["failed"],
                "partial": STATE_MARK["partial"]}.get(cls, "–")
        name = e(display_name(r))
        link = f'<a href="{e(report_link(r.student))}">{name}</a>' if r.student in linked else name
        body.append(f'<tr><td class="who">{link}{_who_line(r)}</td>'
                    f'<td class="pts">{bar}<span class="score">{e(_score_cell(r)) if r.max_score > 0 else "–"}</span></td>'
                    f'<td class="state"><span class="pill {cls}">{mark} {e(status_word(r.status))}</span></td>'
                    f'<td class="diag">{diagnosis}</td></tr>')
    return f"""
<section>
  <h2>{e(_("Students"))}</h2>
  <table class="checks students">
    <thead><tr><th class="c-who">{e(_("Student"))}</th><th class="pts c-pts">{e(_("Score"))}</th>
      <th class="c-state">{e(_("Status"))}</th><th>{e(_("First diagnosis"))}</th></tr></thead>
    <tbody>{"".join(body)}</tbody>
  </table>
</section>"""


def _points_table(rows, linked: set[str]) -> str:
    """Every check's points, as in gradebook.csv: collapsed (it is wide)."""
    from .html import e
    names = check_names(rows)
    if not names:
        return ""
    from .view import CHECK_LABEL
    # gradebook.csv's column names; the check's words on hover
    head = "".join(f'<th class="pts" title="{e(CHECK_LABEL.get(n, n))}">{e(n)}</th>' for n in names)
    body = "".join(f"<tr><td>{_student_link(r, linked)}</td>"
                   + "".join(f'<td class="pts">{e(points(r.checks[n])) if n in r.checks else ""}</td>' for n in names)
                   + f'<td>{e(" ".join(r.diagnoses))}</td></tr>' for r in rows)
    return f"""
<section>
  <details class="log"><summary>{e(_("Points per check, and every diagnosis (as in gradebook.csv)"))}</summary>
  <div class="wide"><table class="checks points">
    <thead><tr><th>{e(_("Student"))}</th>{head}<th>{e(_("Diagnoses"))}</th></tr></thead>
    <tbody>{body}</tbody>
  </table></div></details>
</section>"""


def _charts(out: Path, charted: int) -> str:
    from .html import _figure, e
    return f"""
<section>
  <h2>{e(_("Scores and speed"))}</h2>
  <div class="pair">
    {_figure(out / HISTOGRAM, _("Scores"), _("ungradable submissions are not shown"))}
    {_figure(out / SPEED_CHART, _("Speed against accuracy"), _speed_caption(charted))}
  </div>
</section>"""


def _diagnoses_table(rows) -> str:
    from .html import e
    counted = _diagnosis_counts(rows)
    if not counted:
        return f'<section><h2>{e(_("Most common diagnoses"))}</h2><p>{e(_(NO_DIAGNOSES))}</p></section>'
    body = "".join(f'<tr><td><code>{e(d)}</code></td><td>{e(title)}</td><td class="pts">{n}</td></tr>'
                   for d, title, n in counted)
    return f"""
<section>
  <h2>{e(_("Most common diagnoses"))}</h2>
  <table class="checks">
    <thead><tr><th>{e(_("Diagnosis"))}</th><th>{e(_("What it means"))}</th>
      <th class="pts">{e(_("Submissions"))}</th></tr></thead>
    <tbody>{body}</tbody>
  </table>
</section>"""


def _skipped_html(skipped) -> str:
    from .html import e
    if not skipped:
        return ""
    items = "".join(f"<li><code>{e(x.get('entry', ''))}</code>: {e(x.get('reason', ''))}</li>" for x in skipped)
    return (f"<section><h2>{e(_('Entries that were not graded'))}</h2><p>{e(_(SKIPPED_INTRO))}</p>"
            f'<ul class="plain">{items}</ul></section>')


def _roster_html(roster) -> str:
    from .html import e
    if not roster:
        return ""
    files = roster.get("lms_files") or []
    imports = ("<p>" + e(_("Import-ready grade files beside this page: %(files)s (Canvas, Moodle, Gradescope; "
                           "the roster's students only).") % {"files": _(", ").join(files)}) + "</p>") if files else ""
    return (f"<section><h2>{e(_('Roster'))}</h2><p><code>{e(roster.get('file', ''))}</code>{e(_(': '))}"
            + e(_roster_counts(roster)) + " "
            + e(_("(who handed in nothing, and submissions matching no one, are listed at the top).")) + "</p>"
            f"{imports}</section>")


def _similarity_html(similarity) -> str:
    """Clusters of similar students, each collapsed; in each, its pairs and
    their longest shared passages side by side (collapsed too)."""
    from .html import e
    if not similarity:
        return ""
    pairs = similarity.get("pairs") or []
    parts = [f"<section><h2>{e(_('Most similar pairs'))}</h2><p>{_similarity_intro(similarity, e, e)}</p>"]
    if not pairs:
        parts.append(f"<p>{e(_(NO_PAIR))}</p>")
    for n, cluster in enumerate(similarity_clusters(pairs), 1):
        inner = []
        for p in cluster["pairs"]:
            a, b = str(p.get("a", "")), str(p.get("b", ""))
            inner.append(f'<p class="pair-title">{_pair_title(a, b, p, e)}</p><p>{_pair_shares(a, b, p, e)}</p>')
            for passage in p.get("passages") or []:
                (fa, la), (fb, lb) = _lines(passage, "a"), _lines(passage, "b")
                said = _("shared passage: %(a)s lines %(fa)d-%(la)d, %(b)s lines %(fb)d-%(lb)d") % {
                    "a": a, "fa": fa, "la": la, "b": b, "fb": fb, "lb": lb}
                inner.append(f'<details class="passage"><summary>{e(said)}</summary><div class="side-by-side">'
                             f'<pre><code>{e(passage.get("a_text", ""))}</code></pre>'
                             f'<pre><code>{e(passage.get("b_text", ""))}</code></pre></div></details>')
        parts.append(f'<details class="cluster"><summary>{_cluster_title(n, cluster, e)}</summary>'
                     f'{"".join(inner)}</details>')
    not_compared = similarity.get("not_compared") or []
    if not_compared:
        items = "".join(f"<li>{e(x.get('student', ''))}: {e(x.get('reason', ''))}</li>" for x in not_compared)
        parts.append(f'<p><strong>{e(_("Not compared:"))}</strong></p><ul class="plain">{items}</ul>')
    return "".join(parts) + "</section>"


def _footer(data: dict) -> str:
    from .html import e
    files = ["gradebook.csv", *((data.get("roster") or {}).get("lms_files") or []), "summary.json", "summary.md"]
    return f'<footer>{e(_("beside this page: %(files)s") % {"files": _(", ").join(files)})}</footer>'


def summary_html(rows, out: Path, linked: set[str] | None = None, data: dict | None = None,
                 charted: int = 0) -> str:
    """The class page: self-contained, in report.html's style."""
    from .html import CSS, e
    linked = linked or set()
    data = data or {}
    body = "\n".join(s for s in (
        _hero(rows), _attention(rows, data), _students_table(rows, linked), _points_table(rows, linked),
        _charts(out, charted), _diagnoses_table(rows), _skipped_html(data.get("skipped")),
        _roster_html(data.get("roster")), _similarity_html(data.get("similarity")), _footer(data)) if s)
    return f"""<!DOCTYPE html>
<html lang="{language_code()}">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta http-equiv="Content-Security-Policy" content="{CSP}">
<meta name="color-scheme" content="light dark">
<title>{e(_("Class summary"))}</title>
<style>{CSS}{CLASS_CSS}</style>
</head>
<body>
<main>
{body}
</main>
</body>
</html>
"""


def write_summary(rows, out: Path, data: dict | None = None) -> None:
    """summary.md and summary.html: the students with score, status and
    first diagnosis (a link to every report), score histogram, most common
    diagnoses, every submission on the speed-against-accuracy chart; with
    grade-all's `data`, the entries it skipped, the roster's matches and the
    clusters of similar submissions."""
    from . import write_atomic
    out = Path(out)
    _histogram(rows, out / HISTOGRAM)
    charted = _speed_chart(rows, out / SPEED_CHART)
    linked = {r.student for r in rows if (out / r.student / STUDENT_REPORT).is_file()}
    text = summary_markdown(rows, charted, linked, data)
    write_atomic(out / "summary.md", text)
    write_atomic(out / "summary.html", summary_html(rows, out, linked, data, charted))
