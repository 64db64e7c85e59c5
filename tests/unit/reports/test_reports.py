"""Reports: results.json against its schema, junit.xml, report.md,
report.html and the terminal summary, built from GradeResults made here.

The builders below (a perfect result, one with diagnoses and images, a build
error, an ungradable one, one with hidden checks holding secrets) are also
used by test_report_html_browser.py.
"""
from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET
from html.parser import HTMLParser
from pathlib import Path

import jsonschema
import numpy as np
import OpenImageIO as oiio
import pytest
from markdown_it import MarkdownIt
from rich.console import Console

from grader import PROJECT_ROOT
from grader.grading import catalogue
from grader.reports import REPORT_FILES, render_all, write_all
from grader.reports import gradescope_json, terminal
from grader.reports.text import md_escape
from grader.reports.view import check_label
from grader.grading.results import (BUILD_ERROR, ERROR, FAILED, GRADED, PASSED, SKIPPED, UNGRADABLE, CheckResult,
                                    Diagnosis, GradeResult)

SECRET_OUTPUT = "SECRET-hidden-scene-expected-0.8125"
SECRET_DETAIL = "SECRET-hidden-direction-(0.3,-0.9,0.1)"
HOSTILE = '<script>alert("pwned")</script><img src=x onerror=alert(1)>'

REQUIRED_IDS = [
    "wrong-face", "u-flipped", "v-flipped", "uv-swapped", "not-divided-by-m",
    "nearest-neighbor", "half-texel-offset", "weights-swapped",
    "out-of-bounds-read", "crash", "timeout", "nan-output", "build-error",
    "slow", "forbidden-syscall", "exception", "arrow-wrong", "arrow-missing",
    "discontinuous-seam", "render-mismatch",
]


# ---- builders -----------------------------------------------------------------

def _write_png(path: Path, rgb: np.ndarray) -> Path:
    buf = oiio.ImageBuf(np.ascontiguousarray(rgb, dtype=np.float32))
    assert buf.write(str(path), oiio.UINT8), buf.geterror()
    return path


def _sphere(size: int, flip: bool = False) -> np.ndarray:
    """A shaded disc on a gradient: enough structure to look like a render."""
    y, x = np.mgrid[0:size, 0:size] / (size - 1) * 2 - 1
    if flip:
        x = -x
    inside = x * x + y * y <= 0.8
    img = np.stack([0.2 + 0.3 * (y + 1) / 2, 0.3 + 0.2 * (x + 1) / 2,
                    np.full_like(x, 0.6)], axis=-1)
    shade = np.clip(0.5 + 0.5 * x, 0, 1)
    img[inside] = np.stack([shade, 0.4 * shade + 0.3, 1 - shade], axis=-1)[inside]
    return img


# Solid test images whose colours the browser test finds again on screen.
IMAGE_COLOURS = {
    "arrows": (0.9, 0.85, 0.2),
    "speed_accuracy_chart": (0.2, 0.7, 0.9),
}


def make_images(directory: Path) -> dict[str, Path]:
    ref, sub = _sphere(48), _sphere(48, flip=True)
    diff = np.abs(ref - sub)
    flip_map = np.stack([diff.mean(-1) * 2, diff.mean(-1), 0.2 + 0 * diff[..., 0]], -1)
    images = {
        "render_reference": _write_png(directory / "ref.png", ref),
        "render_submission": _write_png(directory / "sub.png", sub),
        "render_difference": _write_png(directory / "diff.png", np.clip(diff * 2, 0, 1)),
        "render_flip": _write_png(directory / "flip.png", np.clip(flip_map, 0, 1)),
    }
    for name, colour in IMAGE_COLOURS.items():
        block = np.empty((40, 64, 3), np.float32)
        block[:] = colour
        block[8:32, 8:56] = (0.1, 0.1, 0.1)       # some structure, not a flat block
        images[name] = _write_png(directory / f"{name}.png", block)
    return images


def _checks_passing() -> list[CheckResult]:
    specs = [
        ("build", "Your code compiles", 5),
        ("read_texture", "readTexture interpolates bilinearly as in the handout", 25),
        ("sweeps", "fetchColor picks the right face and (u, v) for every direction", 30),
        ("arrows", "The axis arrows point along +x, +y and +z", 10),
        ("stability", "Zero, NaN and huge directions never crash", 10),
        ("renders", "Renders match the reference", 15),
        ("speed", "Lookups are fast enough", 5),
    ]
    return [CheckResult(name=n, title=t, status=PASSED, fraction=1.0, output="All cases passed.",
                        score=float(p), max_score=float(p), number=str(i + 1),
                        duration_s=0.25 * (i + 1), tags=[n])
            for i, (n, t, p) in enumerate(specs)]


def make_perfect() -> GradeResult:
    checks = _checks_passing()
    return GradeResult(submission="perfect", status=GRADED, checks=checks, score=100.0,
                       max_score=100.0, execution_time_s=2.345, source_sha256="ab" * 32)


def make_diagnosed(directory: Path) -> GradeResult:
    images = make_images(directory)
    checks = {c.name: c for c in _checks_passing()}

    sweeps = checks["sweeps"]
    for c in checks.values():
        c.output = ""
    checks["build"].output = "Compiled with 1 warning."
    sweeps.status, sweeps.fraction, sweeps.score = FAILED, 4 / 6, 20.0
    sweeps.output = ("4 of 6 faces correct.\n\n| face | result |\n|---|---|\n"
                     "| -Y | v runs the wrong way |\n| +Z | u runs the wrong way |")
    sweeps.diagnoses = [
        Diagnosis("v-flipped", "v = 1 - expected on the whole face", face="-Y"),
        Diagnosis("u-flipped", "u = 1 - expected on the whole face", face="+Z"),
    ]

    rt = checks["read_texture"]
    rt.status, rt.fraction, rt.score = FAILED, 0.0, 0.0
    rt.output = "Your readTexture returns the nearest texel.\n\nYour program printed:\n\n```\n" + HOSTILE + "\n```"
    rt.diagnoses = [Diagnosis("nearest-neighbor", "every sample equals one texel")]

    stab = checks["stability"]
    stab.status, stab.fraction, stab.score = FAILED, 0.5, 5.0
    stab.output = "Crashed on one input. " + HOSTILE
    stab.diagnoses = [Diagnosis("crash", "readTexture(face +X, u = 1.0, v = 0.5): SIGSEGV "
                                "(segmentation fault) " + HOSTILE, face="+X")]

    arrows = checks["arrows"]
    arrows.status, arrows.fraction, arrows.score = FAILED, 2 / 3, 6.67
    arrows.output = "The red (+x) and green (+y) arrows are right; the blue one is not."
    arrows.artifacts = {"arrows": images["arrows"]}
    arrows.diagnoses = [Diagnosis("arrow-wrong", "the blue (+z) arrow points along -z")]

    renders = checks["renders"]
    renders.status, renders.fraction, renders.score = FAILED, 0.0, 0.0
    renders.artifacts = {k: v for k, v in images.items() if k.startswith("render_")}
    renders.metrics = {"ssim": 0.7123456, "flip_mean": 0.1834}
    renders.output = "Mirror sphere in `uffizi_cross.hdr`: SSIM 0.712, FLIP 0.183."
    renders.diagnoses = [Diagnosis("render-mismatch", "mirror sphere: SSIM 0.712 (needs 0.98)")]

    speed = checks["speed"]
    speed.artifacts = {"speed_accuracy_chart": images["speed_accuracy_chart"]}
    speed.metrics = {"ns_per_lookup": 41.5, "speed_ratio": 1.31}
    speed.output = "41.5 ns per lookup, 1.31 times the reference's time."

    score = sum(c.score for c in checks.values())
    return GradeResult(
        submission="student_42", status=GRADED, checks=list(checks.values()), score=score,
        max_score=100.0, build_log="EnvironmentMap.cpp:12:5: warning: unused variable 'k' " + HOSTILE,
        warnings=["sandbox unavailable: user namespaces are disabled; graded with limits only"],
        execution_time_s=3.2, source_sha256="cd" * 32)


BUILD_LOG = ("\x1b[1mEnvironmentMap.cpp:40:12:\x1b[0m \x1b[31merror:\x1b[0m expected ';' before '}'\n"
             "   40 |     return c ``` \n" + HOSTILE + "\n\x00\x07 end of log")


def make_build_error() -> GradeResult:
    return GradeResult(submission="broken <b>build</b>", status=BUILD_ERROR, checks=[], score=0.0,
                       max_score=100.0, build_log=BUILD_LOG, execution_time_s=0.8)


def make_ungradable() -> GradeResult:
    checks = _checks_passing()[:2]
    checks[1].status, checks[1].score, checks[1].output = ERROR, 0.0, ""
    checks.append(CheckResult(name="sweeps", title="fetchColor sweeps", status=SKIPPED,
                              fraction=0.0, max_score=30.0, number="3"))
    return GradeResult(submission="ungradable", status=UNGRADABLE, checks=checks, score=5.0,
                       max_score=60.0, warnings=["worker failed to start: fixtures missing"],
                       execution_time_s=1.0)


def make_hidden(directory: Path) -> GradeResult:
    result = make_perfect()
    secret_png = directory / "secret.png"
    _write_png(secret_png, np.full((8, 8, 3), 0.123, np.float32))
    result.checks.append(CheckResult(
        name="hidden_renders", title="Renders of the hidden scenes match", status=FAILED,
        fraction=0.5, score=5.0, max_score=10.0, number="8", visibility="after_due_date",
        output=f"Expected {SECRET_OUTPUT}",
        diagnoses=[Diagnosis("wrong-face", SECRET_DETAIL, face="-Z")],
        artifacts={"render_submission_hidden": secret_png},
        metrics={"ssim_hidden": 0.4242}))
    result.checks.append(CheckResult(
        name="hidden_sweeps", title="Hidden sweeps", status=PASSED, score=10.0, max_score=10.0,
        number="9", visibility="hidden", output=f"{SECRET_OUTPUT} passed"))
    result.score, result.max_score = 115.0, 120.0
    return result


def make_speed_only(directory: Path) -> GradeResult:
    """Correct but slow: the one case where the speed chart is worth reading."""
    result = make_perfect()
    images = make_images(directory)
    speed = result.checks[-1]
    speed.status, speed.fraction, speed.score = FAILED, 0.0, 0.0
    speed.artifacts = {"speed_accuracy_chart": images["speed_accuracy_chart"]}
    speed.metrics = {"ns_per_lookup": 141.5, "speed_ratio": 4.31}
    speed.diagnoses = [Diagnosis("slow", "fetchColor takes 4.3x the reference's time per lookup (limit 3x).")]
    result.score = 95.0
    result.isolation = "privilege-drop"
    return result


@pytest.fixture
def results(tmp_path) -> dict[str, GradeResult]:
    return {
        "perfect": make_perfect(),
        "diagnosed": make_diagnosed(tmp_path),
        "build_error": make_build_error(),
        "ungradable": make_ungradable(),
        "hidden": make_hidden(tmp_path),
    }


def _visible_texts(texts: dict[str, str], result: GradeResult) -> dict[str, str]:
    """Everything a student reads: our reports, the terminal, and what
    Gradescope shows of results.json (top-level output, visible tests)."""
    data = json.loads(texts["results.json"])
    out = {k: v for k, v in texts.items() if k != "results.json"}
    out["results.json output"] = data["output"]
    out["results.json visible tests"] = json.dumps(
        [t for t in data["tests"] if t["visibility"] == "visible"])
    out["terminal"] = terminal.summary_text(result)
    return out


# ---- results.json -------------------------------------------------------------

def test_schema_is_a_valid_json_schema():
    jsonschema.Draft202012Validator.check_schema(gradescope_json.load_schema())


@pytest.mark.parametrize("kind", ["perfect", "diagnosed", "build_error", "ungradable", "hidden"])
def test_results_json_is_valid_against_the_schema(results, kind):
    data = json.loads(render_all(results[kind])["results.json"])
    jsonschema.Draft202012Validator(gradescope_json.load_schema()).validate(data)


def test_schema_rejects_what_gradescope_would_reject(results):
    validator = jsonschema.Draft202012Validator(gradescope_json.load_schema())
    data = json.loads(render_all(results["diagnosed"])["results.json"])
    data["tests"][0]["status"] = "partial"
    assert not validator.is_valid(data)
    data = json.loads(render_all(results["diagnosed"])["results.json"])
    data["tests"][0]["visibility"] = "secret"
    assert not validator.is_valid(data)


def test_results_json_fields(results):
    result = results["diagnosed"]
    data = json.loads(render_all(result)["results.json"])
    assert data["score"] == pytest.approx(result.score)
    assert data["execution_time"] == pytest.approx(3.2)
    assert data["output_format"] == "md"
    # Short names in Gradescope's list; each test's output opens with the check's sentence.
    assert [t["name"] for t in data["tests"]] == [check_label(c) for c in result.checks]
    assert all(t["output"].startswith(f"_{md_escape(c.title)}_") for t, c in zip(data["tests"], result.checks))
    by_name = {t["extra_data"]["check"]: t for t in data["tests"]}
    assert by_name["sweeps"]["status"] == "failed" and by_name["sweeps"]["score"] == 20.0
    assert by_name["build"]["status"] == "passed" and by_name["build"]["number"] == "1"
    assert by_name["sweeps"]["tags"] == ["sweeps"]
    # Each visible check's own ids (the kit's agreement test compares them per check).
    assert {name: t["extra_data"]["diagnoses"] for name, t in by_name.items()} == {
        c.name: sorted({d.id for d in c.diagnoses}) for c in result.checks}
    assert any(t["extra_data"]["diagnoses"] for t in data["tests"])
    assert data["extra_data"]["status"] == GRADED
    assert data["extra_data"]["warnings"] == result.warnings
    diag = data["extra_data"]["diagnoses"]
    assert {"id": "v-flipped", "face": "-Y", "detail": "v = 1 - expected on the whole face"} in diag
    assert {"id": "nearest-neighbor", "detail": "every sample equals one texel"} in diag
    # The top-level output says what to fix, in the catalogue's words.
    assert catalogue.CATALOGUE["u-flipped"].what_to_do in data["output"]


def test_hidden_checks_are_in_tests_for_gradescope_to_hide(results):
    data = json.loads(render_all(results["hidden"])["results.json"])
    hidden = [t for t in data["tests"] if t["visibility"] != "visible"]
    assert sorted(t["visibility"] for t in hidden) == ["after_due_date", "hidden"]
    assert data["score"] == 115.0
    # A hidden check's own entry explains its diagnoses, for when it is shown.
    shown_later = [t for t in hidden if t["visibility"] == "after_due_date"][0]
    assert SECRET_DETAIL in shown_later["output"]
    assert catalogue.CATALOGUE["wrong-face"].what_to_do in shown_later["output"]
    # extra_data is stored for instructors only: every diagnosis is there.
    assert any(d["detail"] == SECRET_DETAIL for d in data["extra_data"]["diagnoses"])


def test_a_build_error_and_an_ungradable_result_say_so(results):
    data = json.loads(render_all(results["build_error"])["results.json"])
    assert data["extra_data"]["status"] == BUILD_ERROR and data["tests"] == []
    assert "did not compile" in data["output"] and "expected ';'" in data["output"]
    data = json.loads(render_all(results["ungradable"])["results.json"])
    assert data["extra_data"]["status"] == UNGRADABLE
    assert "problem in the grader" in data["output"]
    errored = [t for t in data["tests"] if t["extra_data"]["status"] == ERROR][0]
    assert errored["status"] == "failed" and "problem in the grader" in errored["output"]


# ---- hidden checks do not leak ------------------------------------------------

def test_hidden_checks_do_not_leak_into_visible_output(results):
    result = results["hidden"]
    texts = render_all(result)
    for where, text in _visible_texts(texts, result).items():
        for secret in (SECRET_OUTPUT, SECRET_DETAIL, "Renders of the hidden scenes",
                       "Hidden sweeps", "0.4242"):
            assert secret not in text, f"{secret!r} leaked into {where}"
    import base64
    secret_png = base64.b64encode(Path(result.checks[-2].artifacts["render_submission_hidden"])
                                  .read_bytes()).decode()
    assert secret_png not in texts["report.html"]
    # The visible reports count only visible checks: the total would tell.
    assert "**Score: 100 / 100**" in texts["report.md"]
    assert "2 more checks" not in texts["report.md"]
    assert "more check (10 points) is shown after the due date" in texts["report.md"]
    assert "more check (10 points) is not shown to students" in texts["report.md"]


def test_instructors_can_ask_for_everything(results):
    texts = render_all(results["hidden"], include_hidden=True)
    assert SECRET_OUTPUT in texts["report.md"] and SECRET_OUTPUT in texts["report.html"]
    assert "**Score: 115 / 120**" in texts["report.md"]


# ---- HTML: self-contained and escaped --------------------------------------

class _Tags(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags: list[tuple[str, dict]] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))


def _tags(html_text: str) -> list[tuple[str, dict]]:
    parser = _Tags()
    parser.feed(html_text)
    return parser.tags


@pytest.mark.parametrize("kind", ["diagnosed", "build_error"])
def test_html_escapes_what_the_student_controls(results, kind):
    page = render_all(results[kind])["report.html"]
    tags = _tags(page)
    names = {t for t, _ in tags}
    assert not names & {"script", "iframe", "object", "embed", "link", "base", "form"}
    assert not [a for _, attrs in tags for a in attrs if a.startswith("on")]
    assert "&lt;script&gt;alert(&quot;pwned&quot;)&lt;/script&gt;" in page
    assert "<b>build</b>" not in page


def test_html_is_self_contained(results):
    page = render_all(results["diagnosed"])["report.html"]
    tags = _tags(page)
    srcs = [attrs["src"] for t, attrs in tags if "src" in attrs]
    # Four renders and the arrows; not the speed chart: this lookup has mistakes.
    assert len(srcs) == 5
    assert all(s.startswith("data:image/png;base64,") for s in srcs)
    assert "url(" not in page and "@import" not in page
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:|//)""", page)
    assert "default-src 'none'" in page


def test_html_shows_every_part(results):
    page = render_all(results["diagnosed"])["report.html"]
    for text in ("Checks", "What to fix", "Renders", "Axis arrows", "Speed",
                 "Reference render", "Your render", "Difference", "Where it looks different",
                 "0.7123", "41.5", "1.31", "sandbox unavailable",
                 catalogue.CATALOGUE["v-flipped"].title, catalogue.CATALOGUE["v-flipped"].what_to_do,
                 "Compiler messages (warnings):", "student_42"):
        assert escape_html(text) in page, text
    # Markdown is rendered: a check's table becomes a table, the catalogue's
    # formulas become code (and u*W, v*H does not turn into emphasis).
    assert "<td>v runs the wrong way</td>" in page
    assert "<code>p = (u*W, v*H)</code>" in page


def test_html_of_a_missing_image_says_so(results, tmp_path):
    result = results["diagnosed"]
    result.checks[3].artifacts["arrows"] = tmp_path / "does-not-exist.png"
    page = render_all(result)["report.html"]
    assert "image not available" in page


def escape_html(text: str) -> str:
    import html
    return html.escape(text, quote=True)


# ---- junit.xml ----------------------------------------------------------------

def test_junit_has_one_testcase_per_check(results):
    result = results["diagnosed"]
    root = ET.fromstring(render_all(result)["junit.xml"].encode())
    assert root.tag == "testsuites"
    (suite,) = root.findall("testsuite")
    cases = suite.findall("testcase")
    assert len(cases) == len(result.checks) == int(suite.get("tests"))
    failed = [c for c in result.checks if c.status != PASSED]
    failures = suite.findall("testcase/failure")
    assert len(failures) == len(failed) == int(suite.get("failures")) == int(root.get("failures"))
    by_class = {c.get("classname"): c for c in cases}
    sweeps_failure = by_class["envmap.sweeps"].find("failure")
    assert "4 of 6 faces correct" in sweeps_failure.text
    assert "v-flipped [-Y]" in sweeps_failure.text
    assert sweeps_failure.get("message") == "20 / 30 points"
    assert by_class["envmap.build"].find("failure") is None
    assert float(by_class["envmap.speed"].get("time")) == pytest.approx(1.75)


@pytest.mark.parametrize("kind", ["perfect", "diagnosed", "build_error", "ungradable", "hidden"])
def test_junit_follows_the_common_structure(results, kind):
    """What CI reporters rely on (the JUnit dialect pytest writes): counts
    that add up, numeric times, a name on every testcase, at most one
    outcome element per testcase."""
    root = ET.fromstring(render_all(results[kind])["junit.xml"].encode())
    assert root.tag == "testsuites" and [s.tag for s in root] == ["testsuite"]
    suite = root[0]
    cases = suite.findall("testcase")
    assert {c.tag for c in suite} <= {"properties", "testcase"}
    for key, tag in (("failures", "failure"), ("errors", "error"), ("skipped", "skipped")):
        assert int(suite.get(key)) == int(root.get(key)) == sum(c.find(tag) is not None for c in cases)
    assert int(suite.get("tests")) == len(cases) >= 1
    assert float(suite.get("time")) == pytest.approx(sum(float(c.get("time")) for c in cases), abs=0.01)
    for c in cases:
        assert c.get("name") and c.get("classname", "").startswith("envmap.")
        outcome = [e.tag for e in c if e.tag in ("failure", "error", "skipped")]
        assert len(outcome) <= 1
        assert {e.tag for e in c} <= {"failure", "error", "skipped", "system-out", "system-err"}


def test_junit_for_build_error_ungradable_and_hidden(results):
    root = ET.fromstring(render_all(results["build_error"])["junit.xml"].encode())
    (case,) = root.iter("testcase")
    assert case.get("name") == "build" and "expected ';'" in case.find("failure").text
    assert "\x1b" not in case.find("failure").text       # colour codes removed

    root = ET.fromstring(render_all(results["ungradable"])["junit.xml"].encode())
    assert int(root.get("errors")) == 1 and int(root.get("skipped")) == 1

    root = ET.fromstring(render_all(results["hidden"])["junit.xml"].encode())
    skipped = [c for c in root.iter("testcase") if c.find("skipped") is not None]
    assert len(skipped) == 2
    assert {c.find("skipped").get("message") for c in skipped} == {
        "hidden: shown after the due date", "hidden: not shown to students"}


# ---- report.md ----------------------------------------------------------------

def test_markdown_has_score_table_diagnoses_and_hints(results):
    md = render_all(results["diagnosed"])["report.md"]
    assert md.startswith("# Environment mapping: student\\_42\n")
    assert "**Score: 41.67 / 100**" in md
    assert "| ❌ | 2 | readTexture: bilinear interpolation | 0 / 25 |" in md
    assert "| 🟡 | 3 | fetchColor picks the right face and (u, v) for every direction | 20 / 30 |" in md
    assert "| ✅ | 1 | Your code compiles | 5 / 5 |" in md
    for diagnosis_id in ("v-flipped", "u-flipped", "nearest-neighbor", "crash", "arrow-wrong",
                         "render-mismatch"):
        info = catalogue.CATALOGUE[diagnosis_id]
        assert f"Its id: `{diagnosis_id}`" in md and info.what_to_do in md and info.explanation in md
    assert "- **\\-Y:** v = 1 \\- expected" not in md    # faces are not over-escaped
    assert "- **-Y:** v = 1 - expected on the whole face" in md
    assert "readTexture(face +X, u = 1.0, v = 0.5): SIGSEGV" in md     # crash attribution
    # The grader's warnings are the instructor's: in that collapsed section.
    assert "- sandbox unavailable" in md.split("<summary>For your instructor</summary>")[1]
    # Order: what stops grading first (a crash) before mapping and filtering mistakes.
    assert md.index("`crash`") < md.index("`v-flipped`") < md.index("`nearest-neighbor`")


def test_markdown_cannot_be_broken_by_the_build_log(results):
    md = render_all(results["build_error"])["report.md"]
    assert "Your code did not compile" in md
    tokens = MarkdownIt("commonmark").parse(md)
    fences = [t for t in tokens if t.type == "fence"]
    assert len(fences) == 1
    assert HOSTILE in fences[0].content and "end of log" in fences[0].content
    # The only raw HTML is our own collapsed instructor's section.
    assert [t.content.strip() for t in tokens if t.type == "html_block"] == [
        "<details><summary>For your instructor</summary>", "</details>"]
    inline_html = [c.content for t in tokens if t.type == "inline"
                   for c in t.children or [] if c.type == "html_inline"]
    assert inline_html == []            # the name "broken <b>build</b>" is escaped


def test_markdown_of_a_perfect_result(results):
    md = render_all(results["perfect"])["report.md"]
    assert "**Score: 100 / 100**" in md and "7 of 7 checks passed" in md
    assert "What to fix" not in md and "Well done" in md


# ---- determinism and writing ----------------------------------------------------

@pytest.mark.parametrize("kind", ["perfect", "diagnosed", "build_error", "ungradable", "hidden"])
def test_same_input_gives_identical_bytes(results, kind, tmp_path):
    a = write_all(results[kind], tmp_path / "a")
    b = write_all(results[kind], tmp_path / "b")
    for name in REPORT_FILES:
        assert a[name].read_bytes() == b[name].read_bytes(), name


def test_results_json_keys_are_sorted(results):
    text = render_all(results["diagnosed"])["results.json"]
    assert text == json.dumps(json.loads(text), indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def test_write_all_writes_every_file_and_no_temporaries(results, tmp_path):
    out = tmp_path / "out" / "student"
    paths = write_all(results["diagnosed"], out)
    paths = write_all(results["diagnosed"], out)      # overwrite in place
    assert sorted(p.name for p in out.iterdir()) == sorted(REPORT_FILES)
    assert set(paths) == set(REPORT_FILES) and all(p.parent == out for p in paths.values())


# ---- terminal -----------------------------------------------------------------

def test_terminal_summary_plain_and_coloured(results):
    text = terminal.summary_text(results["diagnosed"])
    assert "student_42" in text and "41.67 / 100" in text
    assert catalogue.CATALOGUE["nearest-neighbor"].title in text
    assert "sandbox unavailable" in text and "\x1b[" not in text

    console = Console(force_terminal=True, color_system="standard", width=100, record=True)
    terminal.print_summary(results["diagnosed"], console)
    assert "\x1b[" in console.export_text(styles=True)


def test_terminal_shows_compiler_messages_on_build_error(results):
    text = terminal.summary_text(results["build_error"])
    assert "did not compile" in text and "expected ';'" in text


# ---- the diagnosis catalogue ----------------------------------------------------

def test_catalogue_has_every_required_id_in_plain_words():
    for diagnosis_id in REQUIRED_IDS:
        info = catalogue.CATALOGUE[diagnosis_id]
        assert info.kind in catalogue.KINDS
        assert info.title and len(info.explanation) > 60 and len(info.what_to_do) > 40
    entries = {k: i for k, i in catalogue.CATALOGUE.items() if k not in catalogue.ALIASES}
    assert len({i.title for i in entries.values()}) == len(entries)
    # An old id reads as its new entry.
    assert all(catalogue.describe(old).id == new for old, new in catalogue.ALIASES.items())


def test_docs_agree_with_the_catalogue():
    docs = (PROJECT_ROOT / "docs" / "diagnoses.md").read_text()
    assert docs == catalogue.catalogue_markdown(), (
        "docs/diagnoses.md is stale: run `python -m grader.grading.catalogue > docs/diagnoses.md`")
    for diagnosis_id in set(catalogue.CATALOGUE) - set(catalogue.ALIASES):
        assert f"### `{diagnosis_id}`" in docs


def test_an_unknown_id_is_refused_not_given_made_up_words():
    # tests/unit/grading/test_diagnosis_catalogue.py: every id the grader emits is catalogued.
    with pytest.raises(catalogue.UnknownDiagnosis, match="made-up-thing"):
        catalogue.describe("made-up-thing")


def test_every_worker_failure_kind_has_words():
    """The worker names its failures by these ids; reports look them up here."""
    from grader.worker import failures    # our own module: an import error must fail, not skip
    missing = [kind for kind in failures.KINDS if kind not in catalogue.CATALOGUE]
    assert missing == []


# ---- a report a student reads once and understands (issue 13) --------------------

def _with_info_check(result: GradeResult) -> GradeResult:
    result.checks.append(CheckResult(
        name="diagnosis", title="What fetchColor does", status=FAILED, fraction=0.0, score=0.0,
        max_score=0.0, number="8", output="| toward | face sampled |\n|---|---|\n| +Y | -Y |"))
    return result


def test_a_check_worth_no_points_is_information_not_a_failure():
    result = _with_info_check(make_perfect())
    texts = render_all(result)
    md = texts["report.md"]
    assert "7 of 7 checks passed" in md                 # the 0-point check is not counted
    assert "| ℹ️ | 8 | fetchColor: what it does on each face | no points |" in md
    assert "0 / 0" not in md
    page = texts["report.html"]
    assert "7 of 7 checks passed" in page and '<span class="pill info">' in page and "0 / 0" not in page
    root = ET.fromstring(texts["junit.xml"].encode())
    assert root.get("failures") == "0"
    test = [t for t in json.loads(texts["results.json"])["tests"] if t["extra_data"]["check"] == "diagnosis"][0]
    assert test["status"] == "passed" and test["max_score"] == 0
    assert "✗" not in terminal.summary_text(result).split("What fetchColor does")[0].splitlines()[-1]


def test_numbers_are_written_as_people_write_them():
    result = make_perfect()
    result.checks[4].status, result.checks[4].score = FAILED, 5.0
    result.checks[4].output = ("- fetchColor(Vector3(0, 1e+308, 0)): expected [16. 16.  1.], got [16.  1.  1.]\n"
                               "- expected [11.66666667 14.33333333  5.        ]")
    texts = render_all(result)
    for name in ("report.md", "report.html", "junit.xml", "results.json"):
        assert "(16, 16, 1)" in texts[name] and "(16, 1, 1)" in texts[name], name
        assert "(11.67, 14.33, 5)" in texts[name], name
        assert "[16." not in texts[name] and "14.33333333" not in texts[name], name


def test_worst_cases_on_a_position_texture_are_told_as_face_texel_and_uv():
    from grader.grading.results import Mismatch, TexelHit
    result = make_perfect()
    sweeps = result.checks[2]
    sweeps.status, sweeps.score = FAILED, 15.0
    sweeps.mismatches = [Mismatch(
        "fetchColor(Vector3(0.65, 0.65, -0.38))", (7.57, 32.0, 3.0), (7.57, 1.0, 4.0),
        expected_at=TexelHit("+Y", (6.57, 31.0), (0.2053, 0.96875)),
        got_at=TexelHit("-Y", (6.57, 0.0), (0.2053, 0.0)), group="Fibonacci sphere")]
    sweeps.mismatch_counts = {"Fibonacci sphere": 50000}
    texts = render_all(result)
    should = "sample face +Y at texel (6.57, 31), (u, v) = (0.2053, 0.9688)"
    got = "sampled face -Y at texel (6.57, 0), (u, v) = (0.2053, 0)"
    md = texts["report.md"]
    assert f"fetchColor(Vector3(0.65, 0.65, -0.38)): should {should}; yours {got}" in md
    assert "... and 49999 more" in md and "Worst cases, Fibonacci sphere" in md
    assert "(7.57, 32, 3)" not in md                     # not the raw colours
    page = texts["report.html"]
    assert f"<td>{should}</td><td>{got}</td>" in page
    assert should in texts["junit.xml"] and should in texts["results.json"]


def test_render_metrics_are_shown_once():
    result = make_diagnosed_plain()
    renders = [c for c in result.checks if c.name == "renders"][0]
    renders.metrics.update({"ssim_envmap_test--sky_cross": 0.91, "flip_mean_envmap_test--sky_cross": 0.05,
                            "cases": 7})
    page = render_all(result)["report.html"]
    assert "ssim_envmap" not in page and "flip_mean_envmap" not in page
    assert "<td>cases</td><td>7</td>" in page


def make_diagnosed_plain() -> GradeResult:
    import tempfile
    return make_diagnosed(Path(tempfile.mkdtemp()))


def test_report_md_reads_cleanly_as_a_github_job_summary():
    cmarkgfm = pytest.importorskip("cmarkgfm", reason="pip install cmarkgfm (GitHub's renderer)")
    from cmarkgfm.cmark import Options
    result = make_perfect()
    result.checks[3].title = "On test_environment_map.hdr the *arrows* point along +x"
    html_text = cmarkgfm.github_flavored_markdown_to_html(render_all(result)["report.md"],
                                                          options=Options.CMARK_OPT_UNSAFE)
    summaries = re.findall(r"<summary>(.*?)</summary>", html_text, re.S)
    # One per check, inside "Details of each check", and the instructor's section.
    assert len(summaries) == len(result.checks) + 2
    for summary in summaries:
        assert "\\" not in summary, summary               # no Markdown escapes shown literally
    assert any("test_environment_map.hdr the *arrows*" in s for s in summaries)
    # The details' bodies are Markdown again (a blank line after <summary>).
    assert "<p>All cases passed.</p>" in html_text


def test_every_report_says_how_the_code_was_isolated(tmp_path):
    result = make_speed_only(tmp_path)
    texts = render_all(result)
    words = "separate unprivileged user with a system-call filter"
    assert f"- Your code ran under: {words}." in texts["report.md"]
    assert words in texts["report.html"] and words in terminal.summary_text(result)
    data = json.loads(texts["results.json"])
    # results.json: for instructors only (extra_data), never in what Gradescope shows students (issue 21).
    assert data["extra_data"]["isolation"] == "privilege-drop" and words not in data["output"]
    assert 'name="isolation" value="privilege-drop"' in texts["junit.xml"]
    # No code ran (a build error), and a mode this version does not know.
    assert "Your code ran under: none needed" in render_all(make_build_error())["report.md"]
    result.isolation = "new-mode"
    assert "- Your code ran under: new-mode." in render_all(result)["report.md"]


def test_the_speed_chart_only_when_the_lookup_works(tmp_path):
    page = render_all(make_speed_only(tmp_path))["report.html"]
    assert sum(1 for t, a in _tags(page) if t == "img") == 1
    assert "Further left is faster, lower is more accurate." in page and "141.5 ns per lookup" in page
    page = render_all(make_diagnosed(tmp_path))["report.html"]
    assert "Further left is faster" not in page
    assert "Speed against accuracy" not in page      # no speed card until the lookup works
