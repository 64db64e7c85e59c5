"""The class summary grade-all writes beside the gradebook: summary.md,
summary.html and the two charts (score histogram, speed against accuracy).

summary.html is the page an instructor reads: the class at a glance, what
needs their attention (ungradable students, results worth grading again,
roster mismatches), a table of students with score, status and first
diagnosis (each linking to its report), the charts, and similar submissions
grouped into clusters, each collapsed. Its markup is templates/summary.html
(in report.html's shell, page.html, with the one stylesheet, report.css),
self-contained (charts embedded); this module gives the template plain
values: the rows, counts, sentences and links.

Student names are folder and archive names chosen by students, and the
error of an ungradable row can quote them: hostile text. So summary.md
escapes them as Markdown; summary.html prints them through the template
engine, which escapes every value (templating.py), never as template source,
behind a Content-Security-Policy that allows no script; and chart labels
never reach matplotlib's mathtext ($...$ in a name once crashed grade-all).

    write_summary(rows, out)   rows: grade_all.Row, in gradebook order
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import quote

from markupsafe import Markup

from ..course.class_files import MISSING, skip_reason_text
from ..course.roster import left_out_text
from ..grading.results import BUILD_ERROR, GRADED, TIMEOUT, UNGRADABLE
from ..i18n import N_, Translated, _, ngettext
from .html import STATE_MARK, embedded_image, percent, score_class
from .templating import render_page
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
CSP = Markup("default-src 'none'; img-src data:; style-src 'unsafe-inline'; base-uri 'none'; form-action 'none'")


def translated(text) -> str:
    """A sentence grade-all keeps in English in summary.json, in the current
    language when it is one of the catalogue's (an error's message, made in
    other words, stays as it is)."""
    return _(str(text)) if text else ""     # gettext("") is the catalogue's header


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
    lines += [f"- {md_code(str(e.get('entry', '')))}: {md_escape(skip_reason_text(e))}" for e in skipped]
    return lines


def _roster_section(roster) -> list[str]:
    if not roster:
        return []
    lines = ["", "## " + _("Roster"), "", md_code(str(roster.get("file", ""))) + ": " + _roster_counts(roster) + "."]
    for key, title in ROSTER_LISTS:
        entries = roster.get(key) or []
        if entries:
            lines += ["", f"**{_(title)}:**", ""]
            text = left_out_text if key == "left_out" else entry_text
            lines += [f"- {md_escape(text(e), line_start=True)}" for e in entries]
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
        lines += [f"- {md_escape(str(e.get('student', '')), line_start=True)}: "
                  f"{md_escape(translated(e.get('reason')))}" for e in not_compared]
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
# templates/summary.html is the page; what follows gives it plain values
# (the template engine escapes every one).

@dataclass(frozen=True)
class FirstDiagnosis:
    id: str
    title: str
    more: int           # how many other diagnoses the row has


@dataclass(frozen=True)
class StudentLine:
    """One line of the students table."""
    name: str                       # the roster's name, else the folder's
    href: str                       # the report's link, "" when it has none
    ids: str                        # the roster's id and email
    file: str                       # the folder's name when the name is the roster's
    score: str                      # "63.93 / 100", "" when there are no points (ungradable)
    bar: tuple[str, str] | None     # the points bar: (colour class, fill)
    state: str                      # the status pill's colour class
    mark: str
    status: str                     # the status in words
    diagnosis: FirstDiagnosis | None
    error: str                      # why the grader could not grade it


def _status_class(r) -> str:
    """The status pill's colour: the points' when graded."""
    if r.status == UNGRADABLE:
        return "skipped"
    if r.status != GRADED:
        return "failed"
    return score_class(r.score, r.max_score, r.status) if r.max_score > 0 else "failed"


def _href(student: str, linked: set[str]) -> str:
    return report_link(student) if student in linked else ""


def _hero(rows) -> dict:
    graded = [r.score for r in rows if r.status != UNGRADABLE]
    top = max([r.max_score for r in rows] + [0.0])
    mid = median(graded) if graded else 0.0
    return {"count": _submissions_count(rows), "statuses": status_counts(rows),
            "marks": _marks_line(graded, top) if graded and top > 0 else "",
            "ring_class": score_class(mid, top, GRADED), "fill": percent(mid, top),
            "median": _("Median score %(median)s of %(top)s") % {"median": points(mid), "top": points(top)},
            "points": points(mid), "top": points(top)}


def _attention(rows, data: dict) -> dict:
    """What needs the instructor: ungradable students, results worth grading
    again, kept timeouts, roster mismatches."""
    names = {r.student: display_name(r) for r in rows}    # the roster's names, as the table shows them
    grade_again = kept = None
    again = data.get("grade_again") or {}
    if again.get("students"):
        n = len(again["students"])
        said = ngettext("%(count)d result says %(statuses)s", "%(count)d results say %(statuses)s", n) % {
            "count": n, "statuses": _(" or ").join(status_word(s) for s in again.get("statuses", []))}
        why = ngettext("which another process can cause: running grade-all again grades it again",
                       "which another process can cause: running grade-all again grades them again", n)
        grade_again = (said, why, _(", ").join(names.get(s, s) for s in again["students"]))
    own = data.get("own_timeouts") or {}
    if own.get("students"):
        n = len(own["students"])
        kept = (ngettext("%(count)d timeout kept", "%(count)d timeouts kept", n) % {"count": n},
                "; ".join(names.get(s, s) for s in own["students"]), translated(own.get("why")))
    roster = data.get("roster") or {}
    lists = [("passed" if key == "left_out" else "partial", _(title),
              [left_out_text(x) if key == "left_out" else entry_text(x) for x in roster[key]])
             for key, title in ROSTER_LISTS if roster.get(key)]
    return {"ungradable": [(r.student, r.error) for r in rows if r.error], "grade_again": grade_again,
            "kept": kept, "roster": lists}


def display_name(r) -> str:
    """Who a row is, as the instructor knows them: the roster's name, else
    the folder or archive name (a Canvas download's "doejane_12345_..." is
    nobody's name, so it comes second, in the line under the name)."""
    return getattr(r, "name", "") or r.student


def _student_line(r, linked: set[str]) -> StudentLine:
    """Who (the roster's name first; its id and email, and the entry of the
    class folder it was matched to when that is not the name, under it),
    score, status, the first diagnosis."""
    d = first_diagnosis(r)
    # The bar says the points (a timeout that kept 98 of 100 is not red); the pill says the status.
    bar = (score_class(r.score, r.max_score, GRADED), percent(r.score, r.max_score)) if r.max_score > 0 else None
    state = _status_class(r)
    return StudentLine(
        name=display_name(r), href=_href(r.student, linked),
        ids=" · ".join(x for x in (getattr(r, "student_id", ""), getattr(r, "email", "")) if x),
        file=r.student if getattr(r, "name", "") and r.student != r.name else "",   # a phone leaves it out
        score=_score_cell(r) if r.max_score > 0 else "", bar=bar,
        state=state, mark=STATE_MARK[state], status=status_word(r.status),
        diagnosis=FirstDiagnosis(d, _diagnosis_title(d), len(set(r.diagnoses) - {d})) if d else None,
        error=r.error)


def _points_table(rows, linked: set[str]) -> dict:
    """Every check's points, as in gradebook.csv (the page collapses it: it is
    wide): gradebook.csv's column names, the check's words on hover."""
    from .view import CHECK_LABEL
    names = check_names(rows)
    return {"checks": [(n, CHECK_LABEL.get(n, n)) for n in names],
            "rows": [(r.student, _href(r.student, linked),
                      [points(r.checks[n]) if n in r.checks else "" for n in names], " ".join(r.diagnoses))
                     for r in rows]}


def _similarity_page(similarity) -> dict | None:
    """Clusters of similar students; in each, its pairs and their longest
    shared passages (the page collapses both)."""
    if not similarity:
        return None
    pairs = similarity.get("pairs") or []
    clusters = []
    for n, cluster in enumerate(similarity_clusters(pairs), 1):
        shown = []
        for p in cluster["pairs"]:
            a, b = str(p.get("a", "")), str(p.get("b", ""))
            passages = []
            for passage in p.get("passages") or []:
                (fa, la), (fb, lb) = _lines(passage, "a"), _lines(passage, "b")
                said = _("shared passage: %(a)s lines %(fa)d-%(la)d, %(b)s lines %(fb)d-%(lb)d") % {
                    "a": a, "fa": fa, "la": la, "b": b, "fb": fb, "lb": lb}
                passages.append((said, str(passage.get("a_text", "")), str(passage.get("b_text", ""))))
            shown.append({"title": _pair_title(a, b, p, str), "shares": _pair_shares(a, b, p, str),
                          "passages": passages})
        clusters.append({"title": _cluster_title(n, cluster, str), "pairs": shown})
    return {"intro": _similarity_intro(similarity, str, str), "clusters": clusters,
            "not_compared": [(str(x.get("student", "")), translated(x.get("reason")))
                             for x in similarity.get("not_compared") or []]}


def summary_html(rows, out: Path, linked: set[str] | None = None, data: dict | None = None,
                 charted: int = 0) -> str:
    """The class page (templates/summary.html): self-contained, in report.html's style."""
    linked = linked or set()
    data = data or {}
    roster = data.get("roster")
    return render_page(
        "summary.html", CSP=CSP, hero=_hero(rows), attention=_attention(rows, data),
        students=[_student_line(r, linked) for r in rows], points=_points_table(rows, linked),
        charts={"histogram": embedded_image(out / HISTOGRAM), "speed": embedded_image(out / SPEED_CHART),
                "speed_caption": _speed_caption(charted)},
        diagnoses=_diagnosis_counts(rows),
        skipped=[(str(x.get("entry", "")), skip_reason_text(x)) for x in data.get("skipped") or []],
        roster={"file": str(roster.get("file", "")), "counts": _roster_counts(roster),
                "lms_files": _(", ").join(roster.get("lms_files") or [])} if roster else None,
        similarity=_similarity_page(data.get("similarity")),
        footer_files=_(", ").join(["gradebook.csv", *((roster or {}).get("lms_files") or []), "summary.json",
                                   "summary.md"]),
        GRADER_FAILED=GRADER_FAILED, NO_DIAGNOSES=NO_DIAGNOSES, NO_PAIR=NO_PAIR, SKIPPED_INTRO=SKIPPED_INTRO)


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
