"""Feedback in the students' language (issue 22): the Japanese catalogue is
complete and current, and a Japanese report says what the English one says.

The catalogue checks read the code's marked words afresh (Babel's extraction
with babel.cfg), so a new or changed English sentence fails here until
grader/i18n/locale/ja/LC_MESSAGES/grader.po translates it (docs/glossary_ja.md:
`make translations`, then translate the entries that are new or fuzzy).
"""
import json
import re
from pathlib import Path

import pytest
from babel.messages.extract import extract_from_dir
from babel.messages.frontend import parse_mapping_cfg
from babel.messages.pofile import read_po

from grader import PROJECT_ROOT, i18n
from grader.grading.catalogue import CATALOGUE, KINDS

PO = i18n.po_path("ja")
PLACEHOLDER = re.compile(r"%\((\w+)\)[sd]")
ZOO = PROJECT_ROOT / "tests" / "submissions" / "wrong"


@pytest.fixture(scope="module")
def catalogue():
    with PO.open("rb") as f:
        return read_po(f, locale="ja")


@pytest.fixture(scope="module")
def marked():
    """Every message the code marks today, as Babel extracts it."""
    with (PROJECT_ROOT / "babel.cfg").open() as f:
        method_map, options_map = parse_mapping_cfg(f)
    keywords = {"_": None, "N_": None, "ngettext": (1, 2)}
    return {m[2] if isinstance(m[2], str) else m[2][0]
            for m in extract_from_dir(str(PROJECT_ROOT), method_map, options_map, keywords=keywords)}


@pytest.fixture
def japanese():
    before = i18n.language()
    i18n.set_language("ja")
    yield
    i18n.set_language(before)


def _id(message) -> str:
    return message.id[0] if isinstance(message.id, tuple) else message.id


def _strings(message) -> list[str]:
    return list(message.string) if isinstance(message.string, tuple) else [message.string]


def test_every_marked_message_has_a_japanese_entry(catalogue, marked):
    entries = {_id(m): m for m in catalogue if m.id}
    missing = sorted(marked - set(entries))
    assert not missing, f"not in grader.po (run `make translations` and translate them): {missing[:10]}"
    untranslated = sorted(i for i in marked if not all(s.strip() for s in _strings(entries[i])))
    assert not untranslated, f"empty msgstr: {untranslated[:10]}"
    fuzzy = sorted(i for i in marked if entries[i].fuzzy)
    assert not fuzzy, f"fuzzy (the English changed; check the translation, then drop the flag): {fuzzy[:10]}"
    stale = sorted(set(entries) - marked)
    assert not stale, f"in grader.po but no longer in the code (pybabel update drops them): {stale[:10]}"


def test_placeholders_are_the_same_in_both_languages(catalogue):
    for m in catalogue:
        if m.id:
            for text in _strings(m):
                assert sorted(set(PLACEHOLDER.findall(_id(m)))) == sorted(set(PLACEHOLDER.findall(text))), _id(m)


def test_every_diagnosis_check_title_and_kind_reads_in_japanese(japanese):
    from grader.checks import all_checks
    english = [t for e in CATALOGUE.values() for t in (e.title_id, e.explanation_id, e.what_to_do_id)]
    english += [KINDS.msgid(k) for k in KINDS] + [c.title for c in all_checks().values()]
    shown = [i18n._(t) for t in english]
    same = [t for t, s in zip(english, shown) if s == t]
    assert not same, f"shown in English with language ja: {same[:5]}"
    assert all(re.search(r"[\u3040-\u30ff\u4e00-\u9fff]", s) for s in shown)


def test_the_english_default_is_the_code_itself():
    assert i18n.language() == "en"
    e = CATALOGUE["u-flipped"]
    assert e.title == e.title_id == "On this face, u runs the wrong way"


def test_an_unknown_language_is_refused():
    from grader.grading.score import RubricError, load_rubric
    with pytest.raises(i18n.UnknownLanguage):
        i18n.set_language("fr")
    with pytest.raises(i18n.UnknownLanguage):
        i18n.choose("de", {})


def test_the_rubric_chooses_and_lang_overrides(tmp_path, monkeypatch):
    from grader.grading.score import RUBRIC, RubricError, load_rubric
    monkeypatch.delenv(i18n.ENV, raising=False)
    shipped = load_rubric(RUBRIC)
    assert shipped["grading"]["language"] == "en" and i18n.choose(None, shipped) == "en"
    assert i18n.choose(None, {"grading": {"language": "ja"}}) == "ja"
    assert i18n.choose("en", {"grading": {"language": "ja"}}) == "en"
    monkeypatch.setenv(i18n.ENV, "ja")
    assert i18n.choose(None, shipped) == "ja"
    bad = tmp_path / "rubric.toml"
    bad.write_text(RUBRIC.read_text().replace('language = "en"', 'language = "fr"'))
    with pytest.raises(RubricError, match="grading.language"):
        load_rubric(bad)


# ---- graded reports, Japanese against English ---------------------------------

# Three or more English words in a row, outside code, identifiers and numbers.
ENGLISH = re.compile(r"(?<![\w-])(?:[A-Za-z]{2,}[ ,'’]+){2,}[A-Za-z]{2,}(?![\w-])")
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e[+-]?\d+)?%?")
NOT_WORDS = re.compile(r"\b(?:nan|inf)\b")
SUBMISSIONS = ("u-flipped-pos-x", "nearest-neighbor", "crash-null", "syntax-error")
# Beyond tests/submissions/wrong/: a refused source (asm goto), a forbidden
# system call (system()), a timeout: their messages come from the build and
# the worker, and must read in Japanese too.
OTHER = {"timeout-loop": ZOO / "timeout-loop.cpp",
         "asm_goto": ZOO.parent / "attacks" / "asm_goto.cpp",
         "system_call": ZOO.parent / "hostile" / "system_call.cpp"}


def prose(markdown: str, submission: str) -> list[str]:
    """The report's sentences without code, markup, the submission's name and
    the grader's own warnings (instructor notes, English: docs/glossary_ja.md)."""
    # The instructor's section (collapsed, last) holds the grader's warnings.
    for lang in i18n.LANGUAGES:
        marker = f"<summary>{i18n.translations(lang).gettext('For your instructor')}</summary>"
        markdown = markdown.split(marker, 1)[0]
    text = re.sub(r"```.*?```", " ", markdown, flags=re.S)
    text = re.sub(r"`[^`]*`|<[^>]+>", " ", text)
    text = NOT_WORDS.sub(" ", text.replace(submission, " "))
    return [line for line in text.splitlines() if not line.startswith("> **")]


def english_sentences(markdown: str, submission: str) -> list[str]:
    return [m.group(0) for line in prose(markdown, submission) for m in ENGLISH.finditer(line)]


def test_the_scan_finds_english_left_in_a_japanese_report():
    # The scanner itself: it must catch a sentence a translator missed.
    report = "## 直すところ\n\n- +X の面で u が逆向きです。\n\nCheck the sign in front of `u = (1 + z/m)/2`.\n"
    assert english_sentences(report, "x") == ["Check the sign in front of"]
    assert english_sentences("`fetchColor(Vector3(1, 2, 3))` と crash-null-face, 色 (nan, nan, nan)", "x") == []


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    """Each submission graded in Japanese and English (and Japanese twice)."""
    from grader.grading.grade import GradeOptions, grade
    from grading_cache import grade_once
    out, before = {}, i18n.language()
    try:
        for name in (*SUBMISSIONS, *OTHER):
            for lang, run in (("ja", 1), ("en", 1), ("ja", 2)):
                if run == 2 and name != SUBMISSIONS[0]:
                    continue
                folder = tmp_path_factory.mktemp(f"{name}-{lang}-{run}")
                # The second Japanese grading is a real second one (determinism); the
                # others may be this session's grading of that file and options.
                result = (grade if run == 2 else grade_once)(OTHER.get(name, ZOO / f"{name}.cpp"), folder,
                                                             GradeOptions(quick=True, lang=lang))
                out[name, lang, run] = (result, folder)
    finally:
        i18n.set_language(before)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", (*SUBMISSIONS, *OTHER))
def test_a_japanese_report_holds_no_english_sentence(graded, name):
    result, folder = graded[name, "ja", 1]
    report = (folder / "report.md").read_text()
    assert english_sentences(report, name) == []
    assert re.search(r"[\u3040-\u30ff]", report)
    data = json.loads((folder / "results.json").read_text())
    texts = [data.get("output", "")] + [t.get("output", "") + "\n" + t.get("name", "") for t in data["tests"]]
    texts += [d["detail"] for d in data.get("extra_data", {}).get("diagnoses", [])]
    assert [s for t in texts for s in english_sentences(t, name)] == []
    assert f'<html lang="ja">' in (folder / "report.html").read_text()


@pytest.mark.slow
@pytest.mark.parametrize("name", (*SUBMISSIONS, *OTHER))
def test_japanese_and_english_reports_say_the_same(graded, name):
    ja, en = graded[name, "ja", 1][0], graded[name, "en", 1][0]
    assert (ja.status, ja.score, ja.max_score) == (en.status, en.score, en.max_score)
    assert [(c.name, c.status, c.score) for c in ja.checks] == [(c.name, c.status, c.score) for c in en.checks]
    for cj, ce in zip(ja.checks, en.checks):
        assert [(d.id, d.face) for d in cj.diagnoses] == [(d.id, d.face) for d in ce.diagnoses]
        for dj, de in zip(cj.diagnoses, ce.diagnoses):
            # Every number the English detail gives is in the Japanese one
            # (Japanese writes some of the English words as numerals: "one texel", "1 画素").
            missing = _numbers(de.detail) - _numbers(dj.detail)
            assert not missing, (de.id, de.detail, dj.detail)
        if ce.name != "speed":   # timings differ from run to run
            missing = _numbers(ce.output) - _numbers(cj.output)
            assert not missing, (ce.name, missing)
        assert cj.title != ce.title


def _numbers(text: str):
    from collections import Counter
    return Counter(NUMBER.findall(text))


@pytest.mark.slow
def test_the_same_submission_graded_twice_in_japanese_reads_the_same(graded):
    first, second = graded[SUBMISSIONS[0], "ja", 1][1], graded[SUBMISSIONS[0], "ja", 2][1]
    # Times (the grading's, the speed check's ns and ratio) vary from run to run; nothing else may.
    strip = lambda t: re.sub(r"[\d.]+ (s|ms|ns)\b|比は [\d.]+ 倍", "", t)
    assert strip((first / "report.md").read_text()) == strip((second / "report.md").read_text())
    assert (first / "report.md").read_text().count("直し方") >= 1


@pytest.mark.representative
@pytest.mark.slow
def test_a_crash_reads_in_japanese_in_privilege_drop_mode(privilege_drop, tmp_path):
    """The worker's failure words come from the grader's side of the pipe,
    whichever isolation runs the submission."""
    from grader.grading.grade import GradeOptions, grade
    before = i18n.language()
    try:
        result = grade(ZOO / "crash-null.cpp", tmp_path / "out", GradeOptions(quick=True, lang="ja"))
    finally:
        i18n.set_language(before)
    assert result.isolation == "privilege-drop"
    report = (tmp_path / "out" / "report.md").read_text()
    assert "セグメンテーション違反" in report and "ヌルポインタ" in report
    assert english_sentences(report, "crash-null") == []


def test_the_bundles_ship_the_catalogue_and_need_no_build_step():
    from grader.platforms import gradescope
    shipped = {p.relative_to(PROJECT_ROOT).as_posix() for p in gradescope._files()}
    assert "grader/i18n/locale/ja/LC_MESSAGES/grader.po" in shipped
    assert not any(p.endswith(".mo") for p in shipped)   # compiled in memory (grader/i18n/__init__.py)
    # PrairieLearn's image runs the course's copy of grader/, the same tree.
    lock = (PROJECT_ROOT / "requirements.lock").read_text()
    assert re.search(r"^babel==", lock, re.M)


def test_a_kit_without_babel_reads_the_compiled_catalogue(tmp_path):
    # The student kit's Python has its standard library only: it ships the
    # .mo that compiled() writes, and gettext reads it the same way.
    import gettext
    (tmp_path / "grader.mo").write_bytes(i18n.compiled("ja"))
    stdlib = gettext.GNUTranslations((tmp_path / "grader.mo").open("rb"))
    title = CATALOGUE["u-flipped"].title_id
    assert stdlib.gettext(title) == i18n.translations("ja").gettext(title) == "この面で u が逆向きです"
