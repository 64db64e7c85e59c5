"""grade.drop_consequences: what a report leaves out once a cause is named.
(The zoos hold it on real code: tests/grading/test_offmodel_zoo.py,
tests/grading/test_record_zoo.py; here each rule alone.)"""
from __future__ import annotations

from grader.grading.grade import drop_consequences
from grader.grading.results import CheckResult, Diagnosis, GradeResult


def result(**found: list[str]) -> GradeResult:
    return GradeResult("s", checks=[CheckResult(name, name, diagnoses=[Diagnosis(i, i) for i in ids])
                                    for name, ids in found.items()])


def ids(r: GradeResult) -> dict[str, list[str]]:
    return {c.name: [d.id for d in c.diagnoses] for c in r.checks}


def test_a_symptom_alone_is_kept_and_goes_once_a_cause_is_named():
    alone = result(arrows=["arrow-wrong"], renders=["render-mismatch"])
    drop_consequences(alone)
    assert ids(alone) == {"arrows": ["arrow-wrong"], "renders": ["render-mismatch"]}
    named = result(fetch_sweep=["u-flipped"], arrows=["arrow-wrong"], renders=["render-mismatch"])
    drop_consequences(named)
    assert ids(named) == {"fetch_sweep": ["u-flipped"], "arrows": [], "renders": []}


def test_the_speed_check_names_no_cause_of_a_picture():
    r = result(renders=["render-mismatch"], speed=["slow"])
    drop_consequences(r)
    assert ids(r) == {"renders": ["render-mismatch"], "speed": ["slow"]}


def test_reads_outside_the_face_after_state_kept_between_calls_are_left_to_the_cause():
    """Pattern 12 of issue 29: a face size kept in a static reads past the
    smaller faces set later; its clamps are right for the old size."""
    for cause, where in (("kept-between-calls", "read_texture"), ("address-not-face-start", "fetch_sweep")):
        r = result(**{where: [cause, "out-of-bounds-read"]}, arrows=["out-of-bounds-read"],
                   renders=["out-of-bounds-read", "render-mismatch"])
        drop_consequences(r)
        assert ids(r) == {where: [cause, "out-of-bounds-read"], "arrows": [], "renders": []}


def test_a_read_outside_the_face_with_no_state_kept_is_a_cause_of_its_own():
    r = result(read_texture=["unclamped-edge"], arrows=["out-of-bounds-read"], renders=["render-mismatch"])
    drop_consequences(r)
    assert ids(r) == {"read_texture": ["unclamped-edge"], "arrows": ["out-of-bounds-read"], "renders": []}
