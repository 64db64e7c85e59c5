"""Japanese for what a student reads before anything runs (issue 22): the
build's refusals (the source policy's text half, the object check), the
compiler-output sentences, a wrong upload, and the speed chart's labels.

Each graded report is read with test_i18n's scanner (three English words in
a row outside code, ids and numbers): it catches a sentence still in English.
"""
import io
import re
import warnings
import zipfile
from pathlib import Path

import pytest

from grader import PROJECT_ROOT, i18n
from test_i18n import english_sentences

SUBMISSIONS = PROJECT_ROOT / "tests" / "submissions"
KANA = re.compile(r"[\u3040-\u30ff]")


@pytest.fixture
def japanese():
    before = i18n.language()
    i18n.set_language("ja")
    yield
    i18n.set_language(before)


def _grade(path: Path, out: Path, lang: str):
    from grader.grading.grade import GradeOptions, grade
    before = i18n.language()
    try:
        return grade(path, out, GradeOptions(quick=True, lang=lang))
    finally:
        i18n.set_language(before)


def _detail(result) -> str:
    return result.checks[0].diagnoses[0].detail


def _assert_japanese_and_same(path: Path, tmp_path: Path, name: str, quoted: str = "") -> str:
    """Graded in Japanese and in English: the same verdict, and the Japanese
    report (and its first diagnosis) holds no English sentence. `quoted`:
    code from the submission a message shows (it stays as written)."""
    ja = _grade(path, tmp_path / "ja", "ja")
    en = _grade(path, tmp_path / "en", "en")
    assert (ja.status, ja.score) == (en.status, en.score)
    assert [d.id for c in ja.checks for d in c.diagnoses] == [d.id for c in en.checks for d in c.diagnoses]
    report = (tmp_path / "ja" / "report.md").read_text()
    unquoted = lambda text: text.replace(quoted, " ") if quoted else text
    assert english_sentences(unquoted(report), name) == [], report
    assert KANA.search(_detail(ja)) and english_sentences(unquoted(_detail(ja)), name) == [], _detail(ja)
    assert english_sentences(_detail(en), name), "the English report says it in English"
    return _detail(ja)


# ---- the build: refusals and the compiler's mistakes, in Japanese ---------------------

# (submission, diagnosis id, a word of the Japanese sentence, code quoted
# from the submission): each reaches
# another message: the object check (build.inspect_object), the text half
# of the source policy (build.refused_directives), the friendly sentences
# over the compiler's output (grader.build.messages).
BUILD_CASES = [
    ("attacks/unknown_symbol.cpp", "forbidden-object", "標準ライブラリ"),
    ("attacks/calls_reference.cpp", "calls-reference", "参照実装"),
    ("attacks/replaces_loader_code.cpp", "forbidden-object", "static"),
    ("attacks/include_dotdot.cpp", "refused-include", "include"),
    ("attacks/pragma_dependency.cpp", "refused-include", "プラグマ", "pragma GCC dependency"),
    ("build/redefines_face_address.cpp", "build-error", "定義を消して"),
    ("build/missing_fetch_color.cpp", "build-error", "定義がありません"),
    ("build/member_helper.cpp", "build-error", "無名名前空間"),
]


@pytest.mark.slow
@pytest.mark.parametrize("case", BUILD_CASES, ids=[c[0] for c in BUILD_CASES])
def test_a_refused_or_failed_build_reads_in_japanese(case, tmp_path):
    source, diagnosis_id, word, *quoted = case
    path = SUBMISSIONS / source
    detail = _assert_japanese_and_same(path, tmp_path, path.stem, *quoted)
    ja = _grade(path, tmp_path / "again", "ja")
    assert ja.checks[0].diagnoses[0].id == diagnosis_id
    assert word in detail


@pytest.mark.slow
def test_a_cached_refusal_reads_in_the_language_of_each_run(tmp_path):
    """A refusal's message is stored with the build: graded first in English,
    the same source reads in Japanese the next time, and back."""
    from grader.build import build_submission
    source = SUBMISSIONS / "attacks" / "calls_reference.cpp"
    cache = tmp_path / "cache"
    before = i18n.language()
    try:
        i18n.set_language("en")
        first = build_submission(source, cache_dir=cache)
        i18n.set_language("ja")
        second = build_submission(source, cache_dir=cache)
        i18n.set_language("en")
        third = build_submission(source, cache_dir=cache)
    finally:
        i18n.set_language(before)
    assert first.diagnosis_id == second.diagnosis_id == "calls-reference"
    assert "reference solution" in first.log and not KANA.search(first.log)
    assert "参照実装" in second.log and english_sentences(second.log, source.name) == []
    assert third.cached and third.log == first.log


@pytest.mark.slow
def test_an_object_refusal_reads_in_japanese_in_privilege_drop_mode(privilege_drop, japanese, tmp_path):
    """The refusal is worded on the grader's side, whichever way the
    compiler was confined (a fresh cache: the build really runs)."""
    from grader.build import build_submission
    source = SUBMISSIONS / "attacks" / "unknown_symbol.cpp"
    result = build_submission(source, cache_dir=tmp_path / "cache")
    assert result.isolation == "privilege-drop" and result.diagnosis_id == "forbidden-object"
    assert "標準ライブラリ" in result.log and english_sentences(result.log, source.name) == []


def test_the_compilers_own_messages_follow_the_japanese_sentence(japanese):
    """describe(): the friendly sentence in Japanese, the compiler's own
    lines as it printed them, the grader's cut-off note in Japanese."""
    from grader.build import BuildResult
    from grader.build.messages import OUTPUT_STOPPED, describe
    output = ("EnvironmentMap.cpp:4:14: error: redefinition of 'const float* EnvironmentMap::faceAddress(int) "
              "const'\n" + OUTPUT_STOPPED + "\n")
    result = BuildResult(ok=False, library=None, source=Path("EnvironmentMap.cpp"))
    describe(result, output, 60)
    first, *rest = result.log.splitlines()
    assert "faceAddress を定義してはいけません" in first
    assert "error: redefinition of 'const float* EnvironmentMap::faceAddress(int) const'" in result.log
    assert OUTPUT_STOPPED not in result.log and "コンパイラを止めました" in result.log
    assert all(not english_sentences(e["message"], "x") for e in result.errors if e["line"] is None)


# ---- a wrong upload ---------------------------------------------------------------------

def _two_sources(folder: Path) -> Path:
    folder.mkdir()
    for name in ("a.cpp", "b.cpp"):
        (folder / name).write_text('#include "EnvironmentMap.h"\nColor EnvironmentMap::fetchColor'
                                   '(const Vector3&) const { return Color(); }\n')
    return folder


def _no_source(folder: Path) -> Path:
    folder.mkdir()
    (folder / "main.cpp").write_text("int main() { return 0; }\n")
    (folder / "notes.txt").write_text("the report is in report.pdf\n")
    return folder


def _zip_without_source(path: Path) -> Path:
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("hw/readme.txt", "nothing to see here\n")
    return path


def _pdf_named_zip(path: Path) -> Path:
    path.write_bytes(b"%PDF-1.4\n% not a zip at all\n")
    return path


def _empty(path: Path) -> Path:
    path.write_bytes(b"")
    return path


def _utf16(path: Path) -> Path:
    path.write_bytes("// fetchColor\nint x;\n".encode("utf-16"))
    return path


UPLOADS = {"two-sources": (_two_sources, "two", "no-source"),
           "no-source": (_no_source, "none", "no-source"),
           "zip-without-source": (_zip_without_source, "hw.zip", "no-source"),
           "pdf-named-zip": (_pdf_named_zip, "report.zip", "unknown-format"),
           "empty-file": (_empty, "EnvironmentMap.cpp", "empty-submission"),
           "utf-16": (_utf16, "EnvironmentMap.cpp", "unknown-format")}


@pytest.mark.parametrize("name", UPLOADS)
def test_a_wrong_upload_reads_in_japanese(name, tmp_path):
    make, filename, diagnosis_id = UPLOADS[name]
    (tmp_path / "up").mkdir()
    path = make(tmp_path / "up" / filename)
    detail = _assert_japanese_and_same(path, tmp_path, Path(filename).stem)
    ja = _grade(path, tmp_path / "again", "ja")
    assert ja.checks[0].diagnoses[0].id == diagnosis_id
    # Names from the upload stay as they are.
    assert filename.split(".")[0] in detail


# ---- the speed chart ----------------------------------------------------------------------

def _chart_texts(svg: str) -> list[str]:
    """The words drawn in an SVG matplotlib wrote with svg.fonttype none."""
    import html
    return [html.unescape(t) for t in re.findall(r"<text[^>]*>([^<]*)</text>", svg)]


def _draw_speed_chart(path: Path) -> list[str]:
    """The speed check's chart (its title, panel and point label) drawn to
    SVG with text kept as text; returns the missing-glyph warnings."""
    import matplotlib

    from grader.checks import speed
    from grader.study import STUDY_CSV, chart
    from grader.study.run import read_csv
    point = {"label": i18n._("your fetchColor (face %(size)d)") % {"size": speed.STUDY_FACE_SIZE},
             "ns_random": 60.0, "uniform_smooth_rms": 1e-3}
    with warnings.catch_warnings(record=True) as caught, matplotlib.rc_context({"svg.fonttype": "none"}):
        warnings.simplefilter("always")
        chart.draw(read_csv(STUDY_CSV), [point], path, panels=chart.PANELS[:1],
                   title=i18n._("Speed against accuracy"), dpi=90)
    return [str(w.message) for w in caught if "missing from" in str(w.message)]


def test_the_speed_chart_has_japanese_labels_and_their_glyphs(japanese, tmp_path):
    from grader.i18n.languages import glyph_font
    if glyph_font("ja") is None:
        pytest.skip("no CJK font installed (packages.txt: fonts-ipafont-gothic|fonts-noto-cjk)")
    missing = _draw_speed_chart(tmp_path / "chart.svg")
    assert missing == []
    texts = _chart_texts((tmp_path / "chart.svg").read_text())
    shown = "\n".join(texts)
    for word in ("速度と精度", "双一次補間", "最近傍サンプリング", "あなたの fetchColor", "対数目盛"):
        assert word in shown, word
    assert [s for t in texts for s in english_sentences(t, "x")] == []


def test_without_the_cjk_font_the_chart_would_miss_glyphs(japanese, tmp_path, monkeypatch):
    # What the check above guards against: DejaVu alone has no Japanese glyphs.
    from grader.i18n import languages
    monkeypatch.setattr(languages, "glyph_font", lambda code: None)
    assert _draw_speed_chart(tmp_path / "chart.svg")


def test_the_cached_chart_is_drawn_again_in_another_language(tmp_path):
    from grader.study import STUDY_CSV, chart
    from grader.study.run import read_csv
    rows, point = read_csv(STUDY_CSV), {"label": "x", "ns_random": 60.0, "uniform_smooth_rms": 1e-3}
    before = i18n.language()
    try:
        for lang in ("en", "ja"):
            i18n.set_language(lang)
            chart.draw_with_point(rows, point, tmp_path / f"{lang}.png", tmp_path / "cache", dpi=90)
    finally:
        i18n.set_language(before)
    assert len(list((tmp_path / "cache").glob("chart-*.png"))) == 2
