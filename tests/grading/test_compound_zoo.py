"""The compound zoo: submissions with two to five mistakes at once across
fetchColor and readTexture (tests/submissions/compound/). Each one's truth
was written in its sidecar X.json from the code, before grading: the causes
(id, face) the report must name, with nothing else beyond the listed
symptoms, and the checks that must lose or keep their points. In
particular a readTexture mistake never costs fetchColor's sweep points and
is never reported as a fetchColor mistake."""
import json
from pathlib import Path

import pytest

from grader.grading.grade import GradeOptions
from grading_cache import grade_once
from grader.grading.results import GRADED
from project_paths import SUBMISSIONS

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]   # grades whole submissions

ZOO = SUBMISSIONS / "compound"
NAMES = sorted(p.stem for p in ZOO.glob("*.cpp"))


def test_every_compound_submission_has_its_truth():
    assert NAMES and {p.stem for p in ZOO.glob("*.json")} == set(NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_compound_submission_is_diagnosed_exactly(name, tmp_path):
    truth = json.loads((ZOO / f"{name}.json").read_text())
    causes = {(i, f) for i, f in truth["causes"]}
    result = grade_once(ZOO / f"{name}.cpp", tmp_path, GradeOptions(quick=True))
    assert result.status == GRADED
    found = {(d.id, d.face) for d in result.diagnoses}
    assert causes <= found, f"missing {causes - found}"
    assert {d for d in found - causes if d[0] not in truth["symptoms"]} == set()
    by_name = {c.name: c for c in result.checks}
    assert all(by_name[c].score < by_name[c].max_score for c in truth["loses"]), {c: by_name[c].score for c in truth["loses"]}
    assert all(by_name[c].score == by_name[c].max_score for c in truth["keeps"]), {c: by_name[c].score for c in truth["keeps"]}


def exact_share(out: Path) -> tuple[int, int, list[str]]:
    """(exact, total, lines) for a folder of reports written by
    `python -m grader grade --quick tests/submissions/compound/*.cpp --out OUT`:
    the measure quoted in the zoo's README, for any version of the grader."""
    exact, lines = 0, []
    for name in NAMES:
        truth = json.loads((ZOO / f"{name}.json").read_text())
        causes = {(i, f) for i, f in truth["causes"]}
        data = json.loads((out / name / "results.json").read_text())
        found = {(d["id"], d.get("face")) for d in data["extra_data"]["diagnoses"]}
        missing = causes - found
        extra = {d for d in found - causes if d[0] not in truth["symptoms"]}
        exact += not missing and not extra
        lines.append(f"{'exact' if not missing and not extra else 'WRONG'}  {name}"
                     + (f"  missing {sorted(missing, key=str)}" if missing else "")
                     + (f"  extra {sorted(extra, key=str)}" if extra else ""))
    return exact, len(NAMES), lines


if __name__ == "__main__":
    import sys
    exact, total, lines = exact_share(Path(sys.argv[1]))
    print("\n".join(lines) + f"\nexactly diagnosed: {exact} of {total}")
