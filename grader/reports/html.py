"""report.html: one self-contained page a student opens in any browser.

The markup is templates/report.html, the style templates/report.css; this
module gives the template what each section shows. Images are embedded as
data URIs and the CSS is inline; there is no JavaScript and nothing is
fetched (a Content-Security-Policy says so, which also neutralises anything
that slipped through escaping). Everything the student controls (compiler
messages, printed output, exception messages, the submission's name) is
escaped by the template engine (templating.py); check outputs are Markdown
made inert (text.inert_markdown) and rendered with raw HTML, links and
images off.
"""
from __future__ import annotations

import base64
import re
import struct
from dataclasses import dataclass
from pathlib import Path

from markdown_it import MarkdownIt
from markupsafe import Markup

from ..i18n import N_, Translated, _
from ..grading.results import BUILD_ERROR, UNGRADABLE, CheckResult
from .markdown import FINDINGS_SHOWN, all_correct, check_points, mistake_counts, mistake_heading
from .pictures import RENDER_PICTURES
from .templating import render_page
from .text import figure, inert_markdown, points, seconds, truncate_middle
from .view import (GLOSSARY, STATE_ERROR, STATE_FAILED, STATE_INFO, STATE_PARTIAL,
                   STATE_PASSED, STATE_SKIPPED, DiagnosisGroup, ReportView,
                   check_label, check_output, check_state, mismatch_groups)

# Inline styles and data: images, nothing else: no script, no request.
CSP = Markup("default-src 'none'; img-src data:; style-src 'unsafe-inline'")

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
STATE_MARK = {
    STATE_PASSED: "✓", STATE_PARTIAL: "◐", STATE_FAILED: "✗",
    STATE_ERROR: "!", STATE_SKIPPED: "–", STATE_INFO: "i",
}

# Raw HTML, links and images off: inert_markdown already shows any output
# that would form them as literal text; this is the second lock.
_markdown = (MarkdownIt("commonmark", {"html": False}).enable(["table", "strikethrough"])
             .disable(["image", "link", "autolink", "reference"]))


def markdown_html(text: str) -> Markup:
    return Markup(_markdown.render(inert_markdown(truncate_middle(text))))


def catalogue_html(text: str) -> Markup:
    """The catalogue's sentences are Markdown (formulas in `code`)."""
    return Markup(_markdown.renderInline(text))


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


@dataclass(frozen=True)
class EmbeddedImage:
    uri: str                          # data:<mime>;base64,...
    size: tuple[int, int] | None      # a PNG's (width, height)


def embedded_image(path: Path | None) -> EmbeddedImage | None:
    """The file as a data URI, or None when it is missing or no image (the
    page then says so in its place)."""
    try:
        data = Path(path).read_bytes() if path is not None else b""
    except OSError:
        data = b""
    mime = _image_mime(data)
    if mime is None:
        return None
    return EmbeddedImage(f"data:{mime};base64,{base64.b64encode(data).decode('ascii')}", _png_size(data))


# ---- what the sections show ---------------------------------------------------

def score_class(score: float, max_score: float, status: str) -> str:
    """A score's colour (a ring's, a bar's; report.html's and the class
    page's): full marks, half or more, less."""
    if max_score <= 0 or status == UNGRADABLE:   # no verdict to colour
        return "skipped"
    fraction = score / max_score
    return "passed" if fraction >= 0.999 else "partial" if fraction >= 0.5 else "failed"


def percent(score: float, max_score: float) -> str:
    """A bar's or the ring's fill, 0 to 100."""
    return f"{0.0 if max_score <= 0 else max(0.0, min(100.0, 100 * score / max_score)):.1f}"


def render_groups(view: ReportView) -> list[tuple[str, list[tuple[Path, object]]]]:
    """The render pictures by render (the artifact name's suffix), each
    group's title and its pictures in RENDER_PICTURES' order."""
    groups: dict[str, dict[str, Path]] = {}
    for _check, name, path in view.artifacts():
        m = RENDER_ARTIFACT.match(name)
        if m:
            groups.setdefault(m.group(2) or "", {})[m.group(1)] = path
    return [(suffix.replace("_", " "), [(paths[name], picture) for name, picture in RENDER_PICTURES.items()
                                        if name in paths])
            for suffix, paths in sorted(groups.items())]


def metric_parts(items: list[tuple[str, float | None]]) -> list[tuple[str, str, str]]:
    """(label, figure, meaning) of each metric that has a value."""
    parts = []
    for name, value in items:
        if value is None:
            continue
        label, meaning = METRIC_LABELS.get(name, (name, ""))
        parts.append((_(label), figure(value), _(meaning) if meaning else ""))
    return parts


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


@dataclass(frozen=True)
class CheckDetails:
    """What a check's collapsed details show, in this order."""
    check: CheckResult
    state: str
    output: Markup                                  # its Markdown output, rendered
    cases: list[tuple[str, list, int]]              # (title, (call, should, got) rows, how many more)
    metrics: list[tuple[str, str]]                  # (label, figure)
    extras: list[tuple[str, Path]]                  # artifacts no section places: (caption, path)

    def __bool__(self) -> bool:
        return bool(self.output or self.cases or self.metrics or self.extras)


def check_details(view: ReportView) -> list[CheckDetails]:
    """The checks with something to show in their details."""
    placed = lookup_works(view)   # the speed card shows these metrics then
    out = []
    for c in view.checks:
        output = check_output(c)
        cases = [(_("Worst cases, %(group)s") % {"group": _(group)} if group else _("Worst cases"), rows, more)
                 for group, rows, more in mismatch_groups(c)]
        metrics = [(_(METRIC_LABELS.get(k, (k.replace("_", " "),))[0]), figure(v))
                   for k, v in sorted(c.metrics.items()) if not (placed and PLACED_METRIC.match(k))]
        extras = [(n.replace("_", " "), Path(p)) for n, p in sorted(c.artifacts.items()) if not _is_placed(n)]
        details = CheckDetails(c, check_state(c), markdown_html(output) if output else Markup(""),
                               cases, metrics, extras)
        if details:
            out.append(details)
    return out


def instructor_facts(view: ReportView) -> list[str]:
    """Harness facts: isolation, warnings, timing (the source's hash and the
    compiler's warnings follow them in the footer)."""
    facts = [*view.instructor_facts, _("graded in %(time)s") % {"time": seconds(view.execution_time_s)}]
    if not view.complete and view.hidden:
        facts.append(_("hidden checks are not shown"))
    return facts


def render(view: ReportView) -> str:
    return render_page(
        "report.html", view=view, CSP=CSP,
        build_failed=bool(view.build_log.strip()) and view.status == BUILD_ERROR,
        instructor_facts=instructor_facts(view),
        STATE_CLASS=STATE_CLASS, STATE_MARK=STATE_MARK, STATE_WORD=STATE_WORD, STATE_INFO=STATE_INFO,
        FINDINGS_SHOWN=FINDINGS_SHOWN, GLOSSARY=GLOSSARY,
        ARROWS_ARTIFACT=ARROWS_ARTIFACT, CHART_ARTIFACT=CHART_ARTIFACT,
        embedded_image=embedded_image, score_class=score_class, percent=percent, points=points,
        truncate_middle=truncate_middle, mistake_counts=mistake_counts, mistake_heading=mistake_heading,
        catalogue_html=catalogue_html, all_correct=all_correct, check_state=check_state,
        check_label=check_label, check_points=check_points, render_groups=render_groups,
        lookup_works=lookup_works, chart_reading=chart_reading, metric_parts=metric_parts,
        check_details=check_details)

