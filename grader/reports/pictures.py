"""The render check's pictures and the words they are shown under, once.

grader/checks/renders.py leaves these four PNGs in CheckResult.artifacts
under these names (the render that differs most); report.html, Gradescope's
results.json and PrairieLearn's results.json show them with these captions
(tests/unit/reports/test_pictures.py holds each to this table).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..i18n import N_


@dataclass(frozen=True)
class Picture:
    caption: str    # marked (N_), read out through _() where shown
    note: str       # what to look for, where a report has room for it


RENDER_PICTURES = {   # in the order report.html shows them
    "render_reference": Picture(N_("Reference render"), N_("the scene with the reference lookup")),
    "render_submission": Picture(N_("Your render"), N_("the same scene with your lookup")),
    "render_difference": Picture(N_("Difference"), N_("brighter where your render differs more")),
    "render_flip": Picture(N_("Where it looks different"), N_("brighter where a viewer sees a difference")),
}
