"""grader/reports/pictures.py: the render check's pictures are named and
worded once; the check leaves exactly those names and every report shows
them under the table's captions."""
import re

from fake_lookups import FakeLookups
from grader.checks import all_checks, run_checks
from grader.checks.context import CheckContext
from grader.i18n import N_
from grader.platforms import prairielearn
from grader.reports import gradescope_json, html
from grader.reports.pictures import RENDER_PICTURES


def test_the_render_check_leaves_exactly_the_tables_pictures(tmp_path):
    """Observed: the check run on a lookup with a flipped face (so the pictures are drawn)."""
    checks = all_checks()
    ctx = CheckContext(lookups=FakeLookups(fetch={"+X": "u-flipped"}), seed=1234, artifacts=tmp_path, quick=True)
    order = [c for c in checks.values() if c.name in {"renders", *checks["renders"].prerequisites}]
    renders = {r.name: r for r in run_checks(order, ctx, [c.name for c in order]).results}["renders"]
    assert set(renders.artifacts) == set(RENDER_PICTURES)
    assert all(path.is_file() for path in renders.artifacts.values())


def test_every_report_words_them_from_the_table():
    captions = {name: p.caption for name, p in RENDER_PICTURES.items()}
    assert dict(gradescope_json.RENDER_PAIR) == {n: captions[n] for n in ("render_submission", "render_reference")}
    assert {n: prairielearn.IMAGE_LABELS.msgid(n) for n in captions} == captions
    assert all(html.RENDER_ARTIFACT.match(n) for n in captions)
    assert html.RENDER_ARTIFACT.match("render_flip_mirror_ball").groups() == ("render_flip", "mirror_ball")


def test_no_report_keeps_a_wording_of_its_own():
    """The old second and third wordings are gone from every module (they were
    'Your code', 'The reference render' and '... (brighter is further off)')."""
    from project_paths import PROJECT_ROOT
    old = re.compile(r"N_\(\"(Your code|Reference|The reference render|[^\"]*\(brighter is further off\))\"\)")
    found = [str(p.relative_to(PROJECT_ROOT)) for p in (PROJECT_ROOT / "grader").rglob("*.py") if old.search(p.read_text())]
    assert found == [] and N_("x") == "x"
