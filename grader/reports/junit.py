"""junit.xml for CI test reporters: one testcase per check.

The common JUnit dialect (as pytest and most CI reporters read it): a
<testsuites> root with one <testsuite>; a failed check carries <failure>,
a check the harness could not run <error>, a skipped or hidden check
<skipped>. Built from the students' ReportView, so a hidden check appears
only as skipped, without its output. A build error or an ungradable
submission with no checks still gets one testcase saying so. A check worth
no points passes (it informs; CI must not turn red on it).

Text is plain here (ElementTree escapes it); clean() has removed what XML
1.0 cannot hold (control characters, lone surrogates, U+FFFE/U+FFFF).
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

from ..i18n import _
from ..grading.results import BUILD_ERROR
from ..grading.catalogue import describe
from .text import clean, points, truncate_middle
from .view import (STATE_ERROR, STATE_INFO, STATE_PASSED, STATE_SKIPPED, TEXT_LIMIT,
                   ReportView, check_output, check_state, mismatch_groups)

SUITE_NAME = "envmap"


def _check_text(check) -> str:
    parts = [check_output(check)]
    for group, rows, more in mismatch_groups(check):
        lines = [_("Worst cases, %(group)s:") % {"group": _(group)} if group else _("Worst cases:")]
        lines += ["  " + _("%(call)s: should %(should)s; yours %(got)s") % {"call": call, "should": should, "got": got}
                  for call, should, got in rows]
        parts.append("\n".join(lines + (["  " + _("... and %(more)d more") % {"more": more}] if more else [])))
    for d in check.diagnoses:
        info = describe(d.id)
        face = f" [{d.face}]" if d.face else ""
        parts.append(f"{d.id}{face}: {truncate_middle(d.detail, TEXT_LIMIT)}\n  {_('What to do:')} {info.what_to_do}")
    return truncate_middle(clean("\n\n".join(p for p in parts if p)))


def render(view: ReportView) -> str:
    suite = ET.Element("testsuite", name=SUITE_NAME)
    props = ET.SubElement(suite, "properties")
    for key, value in (("submission", view.submission), ("status", view.status),
                       ("score", points(view.score)), ("max_score", points(view.max_score)),
                       ("isolation", view.isolation)):
        ET.SubElement(props, "property", name=key, value=value)

    counts = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    total_time = 0.0

    def case(name: str, classname: str, time_s: float) -> ET.Element:
        nonlocal total_time
        counts["tests"] += 1
        total_time += time_s
        return ET.SubElement(suite, "testcase", classname=classname, name=name,
                             time=f"{time_s:.3f}")

    for check in view.checks:
        name = clean(f"{check.number} {check.title}".strip())
        tc = case(name, f"{SUITE_NAME}.{check.name}", check.duration_s)
        state = check_state(check)
        message = _("%(score)s / %(max_score)s points") % {"score": points(check.score), "max_score": points(check.max_score)}
        text = _check_text(check)
        if state in (STATE_PASSED, STATE_INFO):
            if text:
                ET.SubElement(tc, "system-out").text = text
        elif state == STATE_ERROR:
            counts["errors"] += 1
            ET.SubElement(tc, "error", message=_("could not run (grader problem); %(points)s") % {"points": message},
                          type="error").text = text
        elif state == STATE_SKIPPED:
            counts["skipped"] += 1
            ET.SubElement(tc, "skipped", message=text or _("skipped"))
        else:
            counts["failures"] += 1
            ET.SubElement(tc, "failure", message=message, type=state).text = text

    for h in view.hidden:
        for i in range(h.count):
            tc = case(_("hidden check %(number)d") % {"number": i + 1}, f"{SUITE_NAME}.hidden", 0.0)
            counts["skipped"] += 1
            ET.SubElement(tc, "skipped", message=_("hidden: %(when)s") % {"when": h.when})

    if not view.checks and not view.hidden:
        if view.status == BUILD_ERROR:
            tc = case("build", f"{SUITE_NAME}.build", 0.0)
            counts["failures"] += 1
            ET.SubElement(tc, "failure", message=view.status_text,
                          type="build-error").text = truncate_middle(view.build_log)
        else:
            tc = case("grading", f"{SUITE_NAME}.grading", 0.0)
            counts["errors"] += 1
            ET.SubElement(tc, "error", message=view.status_text,
                          type=view.status).text = view.status_explanation

    for key, value in counts.items():
        suite.set(key, str(value))
    suite.set("time", f"{total_time:.3f}")
    root = ET.Element("testsuites", name=f"{SUITE_NAME}: {view.submission}",
                      **{k: str(v) for k, v in counts.items()}, time=f"{total_time:.3f}")
    root.append(suite)
    ET.indent(root)
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"
