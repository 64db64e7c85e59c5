"""Where fetchColor samples, recovered face by face, and the mistake that
explains it.

The faces handed over encode their positions; fetchColor's readTexture calls
are recorded and answered by the handout's readTexture
(instruments.fetch_record.AsIfHandoutRead), so a wrong readTexture is never
blamed on fetchColor; face_recovery names what the requests show.
"""
from __future__ import annotations

from ..i18n import N_, _
from ..grading.results import FAILED, CheckResult
from . import check
from .context import CheckContext
from .instruments import fetch_record, record_picture
from .instruments.face_recovery import CANDIDATES, analyse
from .instruments.face_recovery import DIAGNOSIS_IDS as _READ_BACK_IDS
from .read_texture import ReadTextureFinding, read_texture

# Every id the per-face analysis can give from a candidate (tests/unit/grading/test_diagnosis_catalogue.py).
DIAGNOSIS_IDS = tuple(sorted({i for c in CANDIDATES for i in c.ids} | set(_READ_BACK_IDS)))


@check(requires=(read_texture,))
def diagnosis(ctx: CheckContext, result: CheckResult, texture: ReadTextureFinding) -> None:
    """fetchColor samples the face the direction exits through, with u and v running the right way."""
    # fetchColor's recorded requests, answered by the handout's readTexture
    # (instruments.fetch_record.AsIfHandoutRead): the student's readTexture
    # plays no part, so the handout's model is the one that fits.
    from .instruments.texture_model import HANDOUT, Fit
    analysis = analyse(fetch_record.AsIfHandoutRead(ctx.lookups), Fit(HANDOUT, HANDOUT, 1.0, 0), quick=ctx.quick)
    result.diagnoses = analysis.diagnoses()
    result.artifacts["record"] = record_picture.draw(ctx, ctx.lookups)
    if not result.diagnoses and len(analysis.faces) == 6 and all(v.correct for v in analysis.faces):
        result.fraction = 1.0
        result.output = _("On every face, fetchColor samples the right face with u and v running the right way.")
        return
    if not result.diagnoses:
        # Said only when every face was analysed and found right (issue 29, pattern 13).
        result.fraction = 1.0
        result.output = "\n".join([_("The per-face analysis names no mistake, but not every face could be shown "
                                      "right:"), ""] + (analysis.table() if analysis.faces else []))
        return
    result.status, result.fraction = FAILED, 0.0
    how = {"fitted": N_("What fetchColor does, recovered from a texture whose texels encode their own position, read back "
                        "through a model of your readTexture that reproduces all its answers:"),
           "closest": N_("What fetchColor does, recovered from a texture whose texels encode their own position, read back "
                         "through the closest model of your readTexture (it does not reproduce all its answers, so this is "
                         "less certain):"),
           "read back": N_("What fetchColor does, recovered from a texture whose texels encode their own position, read "
                           "back by calling your readTexture itself at known (u, v) (no model of it reproduces all its answers):")}
    if analysis.instrument == "none":
        result.output = analysis.reason
        return
    lines = [_(how[analysis.instrument]), ""]
    if analysis.faces:
        lines += analysis.table()
    result.output = "\n".join(lines)
