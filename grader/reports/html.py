"""report.html: one self-contained page a student opens in any browser.

Images are embedded as data URIs and the CSS is inline; there is no
JavaScript and nothing is fetched (a Content-Security-Policy says so, which
also neutralises anything that slipped through escaping). Everything the
student controls (compiler messages, printed output, exception messages,
the submission's name) is escaped; check outputs are Markdown made inert
(text.inert_markdown) and rendered with raw HTML, links and images off.
"""
from __future__ import annotations

import base64
import re
import struct
from html import escape
from pathlib import Path

from markdown_it import MarkdownIt

from ..i18n import N_, Translated, _, language, ngettext
from ..grading.results import BUILD_ERROR, UNGRADABLE, CheckResult
from .markdown import FINDINGS_SHOWN, all_correct, check_points, mistake_counts, mistake_heading
from .pictures import RENDER_PICTURES
from .text import clean, figure, inert_markdown, points, seconds, truncate_middle
from .view import (GLOSSARY, STATE_ERROR, STATE_FAILED, STATE_INFO, STATE_PARTIAL,
                   STATE_PASSED, STATE_SKIPPED, DiagnosisGroup, ReportView,
                   check_label, check_output, check_state, mismatch_groups)

# Artifacts the page places in their own sections; others go with their check.
RENDER_ARTIFACT = re.compile(rf"^({'|'.join(RENDER_PICTURES)})(?:[_:./-](.+))?$")
ARROWS_ARTIFACT = "arrows"
CHART_ARTIFACT = "speed_accuracy_chart"

# Figures people can read without knowing the metric's name.
METRIC_LABELS = {   # (label, meaning), read out through _()
    "ssim": ("SSIM", N_("1 means identical")),
    "flip_mean": (N_("FLIP mean error"), N_("0 means identical")),
    "ns_per_lookup": (N_("time per lookup"), N_("nanoseconds")),
    "speed_ratio": (N_("time relative to the reference"), N_("1 means as fast")),
}
# Metrics the speed card shows (once the lookup works): the details leave
# them out then rather than repeat them. The renders' figures (SSIM, FLIP)
# are only in the details, with the glossary.
PLACED_METRIC = re.compile(r"^(?:ns_per_lookup|speed_ratio)$")

STATE_CLASS = {
    STATE_PASSED: "passed", STATE_PARTIAL: "partial", STATE_FAILED: "failed",
    STATE_ERROR: "error", STATE_SKIPPED: "skipped", STATE_INFO: "info",
}
# The state words in the pills (view.STATE_* are keys, not words).
STATE_WORD = Translated({
    STATE_PASSED: N_("passed"), STATE_PARTIAL: N_("partial"), STATE_FAILED: N_("failed"),
    STATE_ERROR: N_("not run"), STATE_SKIPPED: N_("skipped"), STATE_INFO: N_("info"),
})
# Fonts with Japanese glyphs after the Latin ones (packages.txt installs
# fonts-noto-cjk or fonts-ipafont-gothic for the pictures; browsers have their own).
SANS = ('system-ui, -apple-system, "Segoe UI", Roboto, "Noto Sans", "Liberation Sans", '
        '"Hiragino Sans", "Hiragino Kaku Gothic ProN", "Yu Gothic", Meiryo, "Noto Sans CJK JP", '
        '"Noto Sans JP", "IPAexGothic", "IPAGothic", sans-serif')
STATE_MARK = {
    STATE_PASSED: "✓", STATE_PARTIAL: "◐", STATE_FAILED: "✗",
    STATE_ERROR: "!", STATE_SKIPPED: "–", STATE_INFO: "i",
}

# Raw HTML, links and images off: inert_markdown already shows any output
# that would form them as literal text; this is the second lock.
_markdown = (MarkdownIt("commonmark", {"html": False}).enable(["table", "strikethrough"])
             .disable(["image", "link", "autolink", "reference"]))


def e(text: object) -> str:
    """Escape any text for HTML, attribute values included."""
    return escape(clean(str(text)), quote=True)


def markdown_html(text: str) -> str:
    return _markdown.render(inert_markdown(truncate_middle(text)))


def catalogue_html(text: str) -> str:
    """The catalogue's sentences are Markdown (formulas in `code`)."""
    return _markdown.renderInline(text)


# ---- images -----------------------------------------------------------------

def _image_mime(data: bytes) -> str | None:
    if data.startswith(b"\x89PNG\r\n\x1a\n"):
        return "image/png"
    if data.startswith(b"\xff\xd8\xff"):
        return "image/jpeg"
    head = data[:512].lstrip()
    if head.startswith(b"<svg") or (head.startswith(b"<?xml") and b"<svg" in data[:4096]):
        return "image/svg+xml"
    return None


def _png_size(data: bytes) -> tuple[int, int] | None:
    if data.startswith(b"\x89PNG\r\n\x1a\n") and data[12:16] == b"IHDR":
        return struct.unpack(">II", data[16:24])
    return None


def image_tag(path: Path | None, alt: str, css_class: str = "") -> str:
    """An <img> with the file embedded, or a placeholder saying it is missing."""
    try:
        data = Path(path).read_bytes() if path is not None else b""
    except OSError:
        data = b""
    mime = _image_mime(data)
    if mime is None:
        return f'<div class="missing" role="img" aria-label="{e(alt)}">{e(_("image not available"))}</div>'
    size = _png_size(data)
    dims = f' width="{size[0]}" height="{size[1]}"' if size else ""
    cls = f' class="{css_class}"' if css_class else ""
    uri = f"data:{mime};base64,{base64.b64encode(data).decode('ascii')}"
    return f'<img{cls} src="{uri}" alt="{e(alt)}"{dims}>'


def _figure(path: Path | None, caption: str, note: str = "", css_class: str = "") -> str:
    note_html = f'<span class="note">{e(note)}</span>' if note else ""
    return (f"<figure>{image_tag(path, caption, css_class)}"
            f"<figcaption>{e(caption)}{note_html}</figcaption></figure>")


# ---- sections ---------------------------------------------------------------

def _score_class(score: float, max_score: float, status: str) -> str:
    if max_score <= 0 or status == UNGRADABLE:   # no verdict to colour
        return "skipped"
    fraction = score / max_score
    return "passed" if fraction >= 0.999 else "partial" if fraction >= 0.5 else "failed"


def _header(view: ReportView) -> str:
    pct = 0.0 if view.max_score <= 0 else max(0.0, min(100.0, 100 * view.score / view.max_score))
    status_cls = "passed" if view.status == "graded" else "failed"
    checks_line = e(view.passed_line)
    return f"""
<header class="hero">
  <div class="who">
    <p class="eyebrow">{e(_("Cube-map environment mapping · feedback"))}</p>
    <h1>{e(view.submission)}</h1>
    <p class="meta"><span class="badge {status_cls}">{e(view.status_text)}</span>
      {checks_line}</p>
  </div>
  <div class="ring {_score_class(view.score, view.max_score, view.status)}" style="--p:{pct:.1f}"
       role="img" aria-label="{e(_("score %(score)s of %(max_score)s") % {"score": points(view.score), "max_score": points(view.max_score)})}">
    <div><strong>{e(points(view.score))}</strong><span>{e(_("of %(max_score)s") % {"max_score": points(view.max_score)})}</span></div>
  </div>
</header>"""


def _notices(view: ReportView) -> str:
    out = []
    if view.status_explanation:
        out.append(f'<div class="callout failed"><strong>{e(_("%(status)s.") % {"status": view.status_text.capitalize()})}</strong> '
                   f"{e(view.status_explanation)}</div>")
    return "\n".join(out)


def _pill(state: str) -> str:
    return (f'<span class="pill {STATE_CLASS[state]}">{STATE_MARK[state]} '
            f'<span class="word">{e(STATE_WORD[state])}</span></span>')


def _score_table(view: ReportView) -> str:
    if not view.checks and not view.hidden:
        return ""
    rows = []
    for c in view.checks:
        state = check_state(c)
        pct = 0.0 if c.max_score <= 0 else max(0.0, min(100.0, 100 * c.score / c.max_score))
        bar = ("" if state == STATE_INFO else
               f'<span class="bar {STATE_CLASS[state]}"><span style="width:{pct:.1f}%"></span></span>')
        rows.append(
            f"<tr><td>{_pill(state)}</td><td class=\"num\">{e(c.number)}</td>"
            f"<td>{e(check_label(c))}</td>"
            f'<td class="pts">{bar}{e(check_points(c))}</td></tr>')
    for h in view.hidden:
        more = ngettext("%(count)d more check, %(when)s; not counted here",
                        "%(count)d more checks, %(when)s; not counted here", h.count) % {"count": h.count, "when": h.when}
        rows.append(f'<tr class="hidden-row"><td><span class="pill skipped">{e(_("hidden"))}</span></td><td></td>'
                    f"<td>{e(more)}</td><td class=\"pts\">"
                    f"{e(_('%(points)s points') % {'points': points(h.max_score)})}</td></tr>")
    rows.append(f'<tr class="total"><td></td><td></td><td>{e(_("Total"))}</td>'
                f'<td class="pts">{e(points(view.score))} / {e(points(view.max_score))}</td></tr>')
    return f"""
<section>
  <h2>{e(_("Checks"))}</h2>
  <table class="checks">
    <thead><tr><th>{e(_("Result"))}</th><th class="num">#</th><th>{e(_("Check"))}</th><th class="pts">{e(_("Points"))}</th></tr></thead>
    <tbody>
      {"".join(rows)}
    </tbody>
  </table>
</section>"""


def _diagnosis_card(group: DiagnosisGroup, count: str = "") -> str:
    """One mistake: its title, one short paragraph (the count, what to do),
    and, collapsed, what was found and why it matters (markdown.diagnosis_section)."""
    info = group.info
    findings = []
    for d in group.findings:
        where = f'<span class="chip">{e(d.face)}</span> ' if d.face else ""
        hint = f' <em class="hint">{e(d.hint)}</em>' if d.hint else ""
        findings.append(f"<li>{where}{e(d.detail)}{hint}</li>")
    findings_html = f'<ul class="findings">{"".join(findings)}</ul>'
    shown = info.kind in FINDINGS_SHOWN
    kind = "partial" if info.kind in ("speed",) else "failed"
    lead = f"{e(count)} " if count else ""
    return f"""
<article class="diagnosis {kind}">
  <h3>{e(mistake_heading(group))}</h3>
  {findings_html if shown else ""}
  <p class="todo">{lead}<strong>{e(_("What to do:"))}</strong> {catalogue_html(info.what_to_do)}</p>
  <details class="more"><summary>{e(_("More about this mistake"))}</summary>
  {"" if shown else findings_html}
  <p>{catalogue_html(info.explanation)}</p>
  <p class="note">{e(_("Its id: %(id)s") % {"id": ""})}<code class="id">{e(info.id)}</code></p>
  </details>
</article>"""


def _diagnoses(view: ReportView) -> str:
    if not view.diagnoses:
        if view.checks and view.score >= view.max_score:
            return (f'<section><div class="callout passed"><strong>{e(_("All correct."))}</strong> '
                    f"{e(all_correct(view))}</div></section>")
        return ""
    counts = mistake_counts(view)
    cards = []
    for i, group in enumerate(view.diagnoses):
        if -1 - i in counts:
            cards.append(f"<p>{e(counts[-1 - i])}</p>")
        cards.append(_diagnosis_card(group, counts.get(i, "")))
    return f'<section><h2>{e(_("What to fix first"))}</h2>{"".join(cards)}</section>'


def _render_groups(view: ReportView) -> dict[str, tuple[CheckResult, dict[str, Path]]]:
    groups: dict[str, tuple[CheckResult, dict[str, Path]]] = {}
    for check, name, path in view.artifacts():
        m = RENDER_ARTIFACT.match(name)
        if m:
            groups.setdefault(m.group(2) or "", (check, {}))[1][m.group(1)] = path
    return groups


def _figures_line(items: list[tuple[str, float | None]]) -> str:
    parts = []
    for name, value in items:
        if value is None:
            continue
        label, meaning = METRIC_LABELS.get(name, (name, ""))
        label, meaning = _(label), _(meaning) if meaning else ""
        meaning_html = f' <span class="note">({e(meaning)})</span>' if meaning else ""
        parts.append(f"<span><strong>{e(label)}</strong> {e(figure(value))}{meaning_html}</span>")
    return f'<p class="figures">{"".join(parts)}</p>' if parts else ""


def _renders(view: ReportView) -> str:
    groups = _render_groups(view)
    if not groups:
        return ""
    blocks = []
    for suffix in sorted(groups):
        check, paths = groups[suffix]
        title = f"<h3>{e(suffix.replace('_', ' '))}</h3>" if suffix else ""
        figs = "".join(_figure(paths.get(name), _(picture.caption), _(picture.note), "pixels")
                       for name, picture in RENDER_PICTURES.items() if name in paths)
        blocks.append(f'<div class="render-set">{title}<div class="renders">{figs}</div></div>')
    return f"<section><h2>{e(_('Renders'))}</h2>{''.join(blocks)}</section>"


def _arrows_and_speed(view: ReportView) -> str:
    cards = []
    arrows = view.artifact(ARROWS_ARTIFACT)
    if arrows is not None:
        cards.append(
            f'<div class="card"><h2>{e(_("Axis arrows"))}</h2>'
            + _figure(arrows, _("The test map rendered with your code"),
                      _("red, green and blue arrows must point along +x, +y and +z"), "pixels")
            + "</div>")
    chart = view.artifact(CHART_ARTIFACT)
    ns, ratio = view.metric("ns_per_lookup"), view.metric("speed_ratio")
    if chart is not None or ns is not None or ratio is not None:
        # Where a wrong lookup sits on the chart says nothing about speed:
        # the card waits until the lookup works (the speed check's details
        # give its figures meanwhile).
        if lookup_works(view):
            body = ("" if chart is None else
                    _figure(chart, _("Speed against accuracy"), _("your lookup is the marked point"))
                    + f'<p class="reading">{e(chart_reading(view))}</p>')
            cards.append(f'<div class="card"><h2>{e(_("Speed"))}</h2>{body}'
                         f'{_figures_line([("ns_per_lookup", ns), ("speed_ratio", ratio)])}</div>')
    return f'<section class="pair">{"".join(cards)}</section>' if cards else ""


def lookup_works(view: ReportView) -> bool:
    """No mistake found but (possibly) speed: only then is the student's
    point on the speed-against-accuracy chart worth reading."""
    return all(g.info.kind == "speed" for g in view.diagnoses)


def chart_reading(view: ReportView) -> str:
    """The chart in one line."""
    ns, ratio = view.metric("ns_per_lookup"), view.metric("speed_ratio")
    speed = []
    if ns is not None:
        speed.append(_("%(ns)s ns per lookup") % {"ns": figure(ns)})
    if ratio is not None:
        speed.append(_("%(ratio)s times the reference's time") % {"ratio": figure(ratio)})
    yours = (_("Your lookup (%(speed)s) is the marked point") % {"speed": ", ".join(speed)} if speed
             else _("Your lookup is the marked point"))
    return _("%(yours)s; the lines are the study's lookup methods (the handout's and others, named in the "
             "legend) at several face sizes. Further left is faster, lower is more accurate.") % {"yours": yours}


def _is_placed(name: str) -> bool:
    return bool(RENDER_ARTIFACT.match(name)) or name in (ARROWS_ARTIFACT, CHART_ARTIFACT)


def _details(view: ReportView) -> str:
    items = []
    for c in view.checks:
        state = check_state(c)
        output = check_output(c)
        body = markdown_html(output) if output else ""
        body += _worst_cases(c)
        placed = lookup_works(view)
        shown = {k: v for k, v in sorted(c.metrics.items()) if not (placed and PLACED_METRIC.match(k))}
        if shown:
            rows = "".join(f"<tr><td>{e(_(METRIC_LABELS.get(k, (k.replace('_', ' '),))[0]))}</td>"
                           f"<td>{e(figure(v))}</td></tr>" for k, v in shown.items())
            body += f'<div class="wide"><table class="metrics"><tbody>{rows}</tbody></table></div>'
        extra = [(n, p) for n, p in sorted(c.artifacts.items()) if not _is_placed(n)]
        if extra:
            body += '<div class="gallery">' + "".join(
                _figure(Path(p), n.replace("_", " ")) for n, p in extra) + "</div>"
        if not body:
            continue
        items.append(
            f"<details><summary>{_pill(state)} <span class=\"num\">{e(c.number)}</span> "
            f"<span class=\"title\">{e(c.title)}</span> <span class=\"pts\">{e(check_points(c))}</span>"
            f'</summary><div class="output">{body}</div></details>')
    if not items:
        return ""
    glossary = "".join(f"<li>{e(line)}</li>" for line in GLOSSARY.values())
    return (f'<section><details class="all"><summary>{e(_("Details of each check"))}</summary>'
            f'<div class="output">{"".join(items)}<p><strong>{e(_("Words the details use:"))}</strong></p>'
            f'<ul class="glossary">{glossary}</ul></div></details></section>')


def _worst_cases(check: CheckResult) -> str:
    """CheckResult.mismatches as a table: the lookup, what it should do,
    what it did (a face, texel and (u, v) where the texture says so)."""
    out = []
    for group, rows, more in mismatch_groups(check):
        cells = "".join(f"<tr><td><code>{e(call)}</code></td><td>{e(should)}</td><td>{e(got)}</td></tr>"
                        for call, should, got in rows)
        if more:
            cells += f'<tr><td colspan="3">{e(_("... and %(more)d more") % {"more": more})}</td></tr>'
        title = e(_("Worst cases, %(group)s") % {"group": _(group)}) if group else e(_("Worst cases"))
        out.append(f'<p><strong>{title}</strong></p><div class="wide"><table class="cases">'
                   f"<thead><tr><th>{e(_('lookup'))}</th><th>{e(_('should'))}</th><th>{e(_('yours'))}</th></tr></thead>"
                   f"<tbody>{cells}</tbody></table></div>")
    return "".join(out)


def _build_log(view: ReportView) -> str:
    """The compiler's messages when the build failed (the student's to read)."""
    if not view.build_log.strip() or view.status != BUILD_ERROR:
        return ""
    return (f'<section><details open class="log"><summary>{e(_("Compiler messages"))}</summary>'
            f"<pre>{e(truncate_middle(view.build_log))}</pre></details></section>")


def _instructor(view: ReportView) -> str:
    """Harness facts, collapsed: isolation, warnings, timing, the source's
    hash, compiler warnings."""
    facts = [*view.instructor_facts, _("graded in %(time)s") % {"time": seconds(view.execution_time_s)}]
    if not view.complete and view.hidden:
        facts.append(_("hidden checks are not shown"))
    items = "".join(f"<li>{e(f)}</li>" for f in facts)
    if view.source_sha256:
        items += f"<li>source sha256 <code>{e(view.source_sha256[:16])}…</code></li>"
    log = (f'<p>{e(_("Compiler messages (warnings):"))}</p><pre>{e(truncate_middle(view.build_log))}</pre>'
           if view.build_log.strip() and view.status != BUILD_ERROR else "")
    return (f'<footer><details class="instructor"><summary>{e(_("For your instructor"))}</summary>'
            f'<ul>{items}</ul>{log}</details></footer>')


def render(view: ReportView) -> str:
    body = "\n".join(s for s in (
        _header(view), _notices(view),
        _build_log(view),
        _diagnoses(view), _score_table(view), _renders(view), _arrows_and_speed(view),
        _details(view), _instructor(view)) if s)
    return f"""<!DOCTYPE html>
<html lang="{language()}">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; img-src data:; style-src 'unsafe-inline'">
<meta name="color-scheme" content="light dark">
<title>{e(_("Feedback: %(submission)s") % {"submission": view.submission})}</title>
<style>{CSS.replace("@SANS@", SANS)}</style>
</head>
<body>
<main>
{body}
</main>
</body>
</html>
"""


CSS = """
:root {
  color-scheme: light dark;
  --bg: #f5f6f8; --card: #ffffff; --text: #1c2129; --muted: #5c6773; --border: #e1e5ea;
  --code-bg: #f0f2f5; --accent: #0b63ce;
  --passed: #1a7f37; --passed-bg: #dcf5e3; --partial: #9a6700; --partial-bg: #fff4c2;
  --failed: #c9252d; --failed-bg: #ffe9e8; --skipped: #6e7781; --skipped-bg: #eef0f2;
  --track: #e6e9ee;
}
@media (prefers-color-scheme: dark) {
  :root {
    --bg: #0e1116; --card: #161b22; --text: #e6edf3; --muted: #9da7b3; --border: #2d333b;
    --code-bg: #0b0e13; --accent: #58a6ff;
    --passed: #3fb950; --passed-bg: rgba(63,185,80,.14); --partial: #d29922; --partial-bg: rgba(210,153,34,.16);
    --failed: #f85149; --failed-bg: rgba(248,81,73,.14); --skipped: #8b949e; --skipped-bg: rgba(139,148,158,.14);
    --track: #2d333b;
  }
}
* { box-sizing: border-box; }
html { background: var(--bg); }
body { margin: 0; color: var(--text); background: var(--bg);
  font: 16px/1.55 @SANS@; }
main { max-width: 1120px; margin: 0 auto; padding: 32px 24px 48px; overflow-wrap: anywhere; }
h1, h2, h3 { line-height: 1.25; margin: 0 0 .6em; }
h1 { font-size: 1.9rem; letter-spacing: -.01em; overflow-wrap: anywhere; }
h2 { font-size: 1.3rem; }
h3 { font-size: 1.08rem; }
section { margin: 28px 0; }
code, pre { font-family: ui-monospace, "SFMono-Regular", Menlo, Consolas, "DejaVu Sans Mono", monospace; font-size: .88em; }
code { background: var(--code-bg); padding: .1em .35em; border-radius: 4px; }
pre { background: var(--code-bg); border: 1px solid var(--border); border-radius: 8px; padding: 14px 16px;
  overflow-x: auto; white-space: pre-wrap; overflow-wrap: anywhere; margin: .6em 0; }
pre code { background: none; padding: 0; }
a { color: var(--accent); }
.hero { display: flex; justify-content: space-between; align-items: center; gap: 24px;
  background: var(--card); border: 1px solid var(--border); border-radius: 14px; padding: 24px 28px; }
.eyebrow { margin: 0 0 .3em; color: var(--muted); font-size: .85rem; text-transform: uppercase; letter-spacing: .08em; }
.meta { margin: 0; color: var(--muted); }
.badge { display: inline-block; padding: .15em .7em; border-radius: 999px; font-weight: 600; font-size: .85rem;
  margin-right: .5em; }
.badge.passed { color: var(--passed); background: var(--passed-bg); }
.badge.failed { color: var(--failed); background: var(--failed-bg); }
.ring { --c: var(--skipped); flex: none; width: 132px; height: 132px; border-radius: 50%; display: grid; place-items: center;
  background: conic-gradient(var(--c) calc(var(--p) * 1%), var(--track) 0); }
.ring > div { width: 104px; height: 104px; border-radius: 50%; background: var(--card); display: grid;
  place-content: center; text-align: center; }
.ring strong { font-size: 1.75rem; line-height: 1.1; letter-spacing: -.02em; }
.ring span { color: var(--muted); font-size: .85rem; }
.ring.passed { --c: var(--passed); } .ring.partial { --c: var(--partial); } .ring.failed { --c: var(--failed); }
.callout { border-radius: 10px; padding: 12px 16px; margin: 12px 0; border: 1px solid var(--border);
  border-left-width: 5px; background: var(--card); }
.callout.failed { border-left-color: var(--failed); }
.callout.partial { border-left-color: var(--partial); }
.callout.passed { border-left-color: var(--passed); }
table { border-collapse: collapse; width: 100%; }
table.checks { background: var(--card); border: 1px solid var(--border); border-radius: 12px; overflow: hidden;
  border-collapse: separate; border-spacing: 0; }
.checks th, .checks td { padding: 10px 14px; border-bottom: 1px solid var(--border); text-align: left; vertical-align: middle; }
.checks th { font-size: .8rem; text-transform: uppercase; letter-spacing: .06em; color: var(--muted); font-weight: 600; }
.checks tr:last-child td { border-bottom: none; }
.checks .total td { font-weight: 700; }
.checks .hidden-row td { color: var(--muted); font-style: italic; }
.num { color: var(--muted); font-variant-numeric: tabular-nums; white-space: nowrap; }
.pts { text-align: right !important; white-space: nowrap; font-variant-numeric: tabular-nums; }
.bar { display: inline-block; width: 72px; height: 6px; border-radius: 3px; background: var(--track);
  margin-right: 10px; vertical-align: middle; overflow: hidden; }
.bar > span { display: block; height: 100%; background: var(--c, var(--skipped)); }
.bar.passed { --c: var(--passed); } .bar.partial { --c: var(--partial); } .bar.failed { --c: var(--failed); }
.pill { display: inline-block; padding: .1em .65em; border-radius: 999px; font-size: .82rem; font-weight: 600; white-space: nowrap; }
.pill.passed { color: var(--passed); background: var(--passed-bg); }
.pill.partial { color: var(--partial); background: var(--partial-bg); }
.pill.failed { color: var(--failed); background: var(--failed-bg); }
.pill.error, .pill.skipped { color: var(--skipped); background: var(--skipped-bg); }
.pill.info { color: var(--accent); background: var(--code-bg); }
.diagnosis { background: var(--card); border: 1px solid var(--border); border-left: 5px solid var(--failed);
  border-radius: 12px; padding: 16px 20px; margin: 14px 0; }
.diagnosis.partial { border-left-color: var(--partial); }
.diagnosis p { margin: .5em 0; }
.id { font-size: .75rem; color: var(--muted); font-weight: 500; margin-left: .3em; }
.chip { display: inline-block; font: 600 .8rem/1.4 ui-monospace, Menlo, Consolas, monospace; padding: .05em .5em;
  border-radius: 6px; border: 1px solid var(--border); background: var(--code-bg); margin-right: .25em; }
.findings { margin: .4em 0 .6em; padding-left: 1.2em; }
.findings li { margin: .25em 0; }
.hint { color: var(--muted); }
.todo { background: var(--passed-bg); border-radius: 8px; padding: 10px 14px; }
.card { background: var(--card); border: 1px solid var(--border); border-radius: 12px; padding: 18px 20px; }
.render-set { background: var(--card); border: 1px solid var(--border); border-radius: 12px; padding: 18px 20px; margin-bottom: 16px; }
.renders { display: grid; grid-template-columns: repeat(4, minmax(0, 1fr)); gap: 14px; }
.pair { display: grid; grid-template-columns: repeat(auto-fit, minmax(320px, 1fr)); gap: 16px; }
.gallery { display: grid; grid-template-columns: repeat(auto-fill, minmax(220px, 1fr)); gap: 14px; margin-top: 12px; }
figure { margin: 0; }
figure img { display: block; width: 100%; height: auto; border-radius: 8px; border: 1px solid var(--border);
  background: repeating-conic-gradient(var(--track) 0 25%, transparent 0 50%) 0 0 / 16px 16px; }
img.pixels { image-rendering: pixelated; }
figcaption { margin-top: .45em; font-weight: 600; font-size: .92rem; }
figcaption .note, .figures .note { display: block; font-weight: 400; color: var(--muted); font-size: .85rem; }
.figures { display: flex; flex-wrap: wrap; gap: 8px 28px; margin: 14px 0 0; }
.figures .note { display: inline; }
.missing { aspect-ratio: 1; display: grid; place-items: center; border: 1px dashed var(--border); border-radius: 8px;
  color: var(--muted); font-size: .9rem; }
details { background: var(--card); border: 1px solid var(--border); border-radius: 12px; margin: 10px 0; }
details > summary { cursor: pointer; padding: 12px 16px; display: flex; gap: 10px; align-items: center; list-style: none; }
details > summary::-webkit-details-marker { display: none; }
details > summary::before { content: "▸"; color: var(--muted); width: 1em; flex: none; transition: transform .15s; }
details[open] > summary::before { transform: rotate(90deg); }
details > summary .pts { margin-left: auto; color: var(--muted); }
details[open] > summary { border-bottom: 1px solid var(--border); }
.output { padding: 6px 18px 14px; overflow-wrap: anywhere; }
.output table { margin: .6em 0; }
.output th, .output td, .metrics td { border: 1px solid var(--border); padding: 4px 10px; text-align: left; }
.metrics { width: auto; margin-top: .8em; font-variant-numeric: tabular-nums; }
.log pre { margin: 0; border: none; border-radius: 0 0 12px 12px; max-height: 520px; overflow: auto; }
footer { color: var(--muted); font-size: .85rem; margin-top: 36px; }
footer details { background: none; }
.more { background: none; border: none; margin: .4em 0 0; }
.more > summary { padding: 4px 0; color: var(--muted); }
.more[open] > summary { border-bottom: none; }
details.all > .output > details { margin: 10px 0; }
.wide { overflow-x: auto; }
.output table, .cases { display: block; overflow-x: auto; max-width: 100%; }
/* Numbers in tables never break mid-figure: a table too wide scrolls instead. */
.output th, .output td, .metrics td { overflow-wrap: normal; }
.cases td, .cases th { border: 1px solid var(--border); padding: 4px 10px; text-align: left; vertical-align: top; }
.reading { color: var(--muted); font-size: .92rem; margin: .6em 0 0; }
details > summary .title { flex: 1 1 auto; min-width: 0; overflow-wrap: anywhere; }
.checks td:nth-child(3) { overflow-wrap: anywhere; }
@media (max-width: 760px) {
  .renders { grid-template-columns: repeat(2, minmax(0, 1fr)); }
  .hero { flex-direction: column-reverse; align-items: flex-start; }
}
/* A phone (360 px): every column of the checks table stays on screen; the
   bars and the state words go (the mark and colour say it), padding shrinks. */
@media (max-width: 600px) {
  main { padding: 12px 8px 32px; }
  .hero { padding: 16px; }
  .checks th, .checks td { padding: 8px 6px; }
  .bar, .pill .word { display: none; }
  .pair { grid-template-columns: minmax(0, 1fr); }
  .card, .render-set, .diagnosis { padding: 14px 12px; }
  details > summary { padding: 10px 10px; gap: 6px; }
  .output { padding: 6px 10px 12px; }
  /* Worst cases: one block per lookup instead of three narrow columns. */
  .cases thead { display: none; }
  .cases tr, .cases td { display: block; }
  .cases tr { border: 1px solid var(--border); border-radius: 6px; margin: 6px 0; padding: 4px 0; }
  .cases td { border: none; padding: 2px 8px; }
  .cases td:nth-child(2)::before { content: "should "; font-weight: 600; }
  .cases td:nth-child(3)::before { content: "yours "; font-weight: 600; }
}
"""
