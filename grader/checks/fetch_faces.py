"""What fetchColor asks readTexture for, face by face, and the mistake that
explains it.

The record of fetchColor's readTexture calls (instruments.fetch_record) gives
the face and (u, v) it asked for; instruments.face_map sets them against the
table and names what the record proves. The student's readTexture plays no
part, so a wrong readTexture is never blamed on fetchColor.
"""
from __future__ import annotations

from ..i18n import _
from ..grading.results import FAILED, CheckResult
from . import check
from .context import CheckContext
from .instruments import record_picture
from .instruments.face_map import CANDIDATES, FACE_SIZE, analyse
from .instruments.face_map import DIAGNOSIS_IDS as _MAP_IDS
from .read_texture import ReadTextureFinding, read_texture

# Every id the per-face analysis can give from a candidate (tests/unit/grading/test_diagnosis_catalogue.py).
DIAGNOSIS_IDS = tuple(sorted({i for c in CANDIDATES for i in c.ids} | set(_MAP_IDS)))


@check(requires=(read_texture,))
def diagnosis(ctx: CheckContext, result: CheckResult, texture: ReadTextureFinding) -> None:
    """fetchColor samples the face the direction exits through, with u and v running the right way."""
    analysis = analyse(ctx.lookups, quick=ctx.quick)
    result.diagnoses = analysis.diagnoses()
    result.artifacts["record"] = record_picture.draw(ctx, ctx.lookups)
    if not result.diagnoses and len(analysis.faces) == 6 and all(v.correct for v in analysis.faces):
        result.fraction = 1.0
        # Scoped to what was observed: the sweep judges other face sizes and
        # fetchColor answered by its own readTexture (pattern 13: no sentence
        # another check's table contradicts).
        result.output = _("On every face, fetchColor samples the right face with u and v running the right way "
                          "(%(count)d directions of a Fibonacci sphere, on %(size)d x %(size)d faces, its readTexture "
                          "calls answered by the grader).") % {"count": analysis.directions, "size": FACE_SIZE}
        return
    if not result.diagnoses:
        # Said only when every face was analysed and found right (issue 29, pattern 13).
        result.fraction = 1.0
        result.output = "\n".join([_("The per-face analysis names no mistake, but not every face could be shown "
                                      "right:"), ""] + (analysis.table() if analysis.faces else []))
        return
    result.status, result.fraction = FAILED, 0.0
    lines = [_("What fetchColor asks readTexture for, recorded (the face and (u, v) of each call), against the "
               "(u, v) table in README.md:"), ""]
    if analysis.faces:
        lines += analysis.table()
    result.output = "\n".join(lines)
