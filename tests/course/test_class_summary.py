"""The class page an instructor reads (summary.html, summary.md) and the grade
files an LMS imports (grader/course/lms_csv.py), on hand-made gradebook rows:
what each student got is in the table, similar students come as clusters,
and each LMS file has the columns that LMS imports by."""
from __future__ import annotations

import csv
import io
import re
from html.parser import HTMLParser

from grader.course.grade_all import MISSING, Row
from grader.course.lms_csv import Target, write_lms_files
from grader.course.roster import Student, load_roster
from grader.reports.class_summary import similarity_clusters, write_summary
from grader.reports.templating import stylesheet

ROWS = [
    Row("alice", "graded", 100.0, 100.0, {"read_texture": 25.0}, [], first_diagnosis=""),
    Row("bob", "graded", 63.93, 100.0, {"read_texture": 6.12}, ["nearest-neighbor"], first_diagnosis="nearest-neighbor"),
    Row("carol", "graded", 58.32, 100.0, {"read_texture": 25.0}, ["crash", "length-overflow"], first_diagnosis="crash"),
    Row("dave", "build-error", 0.0, 100.0, {}, ["build-error"], first_diagnosis="build-error"),
    Row("erin", "ungradable", 0.0, 0.0, error="its grading process was killed by SIGKILL (graded alone, ...)"),
]


class Cells(HTMLParser):
    """The text of every table row, and the <details> summaries, of a page."""

    def __init__(self, page: str):
        super().__init__()
        self.rows, self.summaries, self._row, self._in = [], [], None, None
        self.feed(page)

    def handle_starttag(self, tag, attrs):
        if tag == "tr":
            self._row = []
        elif tag in ("td", "th") and self._row is not None:
            self._row.append("")
            self._in = "cell"
        elif tag == "summary":
            self.summaries.append("")
            self._in = "summary"

    def handle_endtag(self, tag):
        if tag == "tr" and self._row is not None:
            self.rows.append([c.strip() for c in self._row])
            self._row = None
        elif tag in ("td", "th", "summary"):
            self._in = None

    def handle_data(self, data):
        if self._in == "cell":
            self._row[-1] += data
        elif self._in == "summary":
            self.summaries[-1] += data


def test_the_class_page_lists_each_student_with_score_status_and_first_diagnosis(tmp_path):
    for r in ROWS:
        (tmp_path / r.student).mkdir()
        (tmp_path / r.student / "report.html").write_text("")
    write_summary(ROWS, tmp_path, data={"grade_again": {"statuses": ["timeout", "ungradable"], "students": ["erin"]}})
    page = (tmp_path / "summary.html").read_text()
    rows = {r[0]: r for r in Cells(page).rows if len(r) == 4}    # the students table: 4 columns without a roster
    assert rows["Student"] == ["Student", "Score", "Status", "First diagnosis"]
    assert rows["alice"][1:] == ["100 / 100", "✓ graded", ""]
    assert rows["bob"][1:] == ["63.93 / 100", "◐ graded", "readTexture still returns the nearest texel nearest-neighbor"]
    assert rows["carol"][3] == "Your code crashed crash (+1 more)"
    assert rows["dave"][1:3] == ["0 / 100", "✗ compile error"]
    assert rows["erin"][1:3] == ["–", "– ungradable"] and "SIGKILL" in rows["erin"][3]
    assert '<td class="who"><a href="bob/report.html">bob</a></td>' in page
    # report.html's stylesheet, not a copy of it
    assert page.count(stylesheet()) == 1
    assert "1 result says timed out or ungradable" in page and "grades it again: erin" in page
    md = (tmp_path / "summary.md").read_text()
    assert "| [bob](<bob/report.html>) | 63.93 / 100 | graded | readTexture still returns the nearest texel " \
           "(`nearest-neighbor`) |" in md


def pair(a, b, similarity):
    return {"a": a, "b": b, "similarity": similarity, "share_a": similarity, "share_b": similarity,
            "shared_tokens": 100, "passages": [{"a_lines": [1, 9], "b_lines": [2, 10], "a_text": f"code of {a}",
                                                "b_text": f"code of {b}"}]}


def test_similar_pairs_come_as_clusters_of_students():
    pairs = [pair("ann", "ben", 0.9), pair("dan", "eve", 0.97), pair("ben", "cat", 0.6)]
    clusters = similarity_clusters(pairs)
    assert [c["students"] for c in clusters] == [["dan", "eve"], ["ann", "ben", "cat"]]
    assert [c["similarity"] for c in clusters] == [0.97, 0.9]
    assert [(p["a"], p["b"]) for p in clusters[1]["pairs"]] == [("ann", "ben"), ("ben", "cat")]


def test_the_page_collapses_each_cluster_and_each_shared_passage(tmp_path):
    similarity = {"tool": "copydetect 0.5.0", "compared": 5, "min_listed": 0.5,
                  "pairs": [pair("ann", "ben", 0.9), pair("dan", "eve", 0.97), pair("ben", "cat", 0.6)]}
    write_summary(ROWS[:1], tmp_path, data={"similarity": similarity})
    page = (tmp_path / "summary.html").read_text()
    summaries = [s for s in Cells(page).summaries if not s.startswith("Points per check")]
    assert summaries == [
        "Cluster 1: dan, eve (2 students, up to 97%)",
        "shared passage: dan lines 1-9, eve lines 2-10",
        "Cluster 2: ann, ben, cat (3 students, up to 90%)",
        "shared passage: ann lines 1-9, ben lines 2-10",
        "shared passage: ben lines 1-9, cat lines 2-10"]
    # every cluster and passage starts closed
    assert not re.search(r"<details[^>]* open", page)
    md = (tmp_path / "summary.md").read_text()
    assert "### Cluster 2: ann, ben, cat (3 students, up to 90%)" in md


def entries():
    students = [Student("S001", "Anderson, Alice", "alice@uni.example", "501", "Lab A", "alice"),
                Student("S002", "Brown, Bob", "", "502", "Lab B", "bob"),
                Student("S003", "Clark, Carol", "carol@uni.example", "503", "Lab A", "carol"),
                Student("S004", "=cmd|' /C calc'!A0", "dan@uni.example", "504", "Lab A", "dan")]
    rows = [Row("alice", "graded", 100.0, 100.0), Row("bob", "graded", 63.93, 100.0),
            Row("carol", "ungradable", 0.0, 0.0), Row("Clark", MISSING, 0.0, 0.0)]
    return list(zip(rows, students))


def read(path):
    return list(csv.reader(io.StringIO(path.read_text(), newline="")))


def test_each_lms_gets_the_columns_it_imports_by(tmp_path):
    files, left_out = write_lms_files(entries(), tmp_path, Target("Environment map (1234)", "Environment map", 10.0))
    assert [f.name for f in files] == ["grades_canvas.csv", "grades_moodle.csv", "grades_gradescope.csv"]
    # Canvas: its export's identity columns, the Points Possible row, the assignment as Canvas names it,
    # scores scaled to its points.
    assert read(tmp_path / "grades_canvas.csv") == [
        ["Student", "ID", "SIS User ID", "SIS Login ID", "Section", "Environment map (1234)"],
        ["    Points Possible", "", "", "", "", "10"],
        ["Anderson, Alice", "501", "S001", "alice", "Lab A", "10"],
        ["Brown, Bob", "502", "S002", "bob", "Lab B", "6.39"],
        ["Clark, Carol", "503", "S003", "carol", "Lab A", ""],           # ungradable: left alone
        ["'=cmd|' /C calc'!A0", "504", "S004", "dan", "Lab A", ""]]     # no formula; nothing handed in
    # Moodle: a row only with a score and every identifier (Bob has no email address).
    assert read(tmp_path / "grades_moodle.csv") == [
        ["Full name", "ID number", "Email address", "Environment map"],
        ["Anderson, Alice", "S001", "alice@uni.example", "100"]]
    assert left_out == [{"file": "grades_moodle.csv", "student": "Brown, Bob", "why": "no Email address to be found by"}]
    assert read(tmp_path / "grades_gradescope.csv") == [
        ["First Name", "Last Name", "SID", "Email", "Total Score", "Max Points", "Status"],
        ["Alice", "Anderson", "S001", "alice@uni.example", "100", "100", "Graded"],
        ["Bob", "Brown", "S002", "", "63.93", "100", "Graded"],
        ["Carol", "Clark", "S003", "carol@uni.example", "", "100", "Ungraded"],
        ["'=cmd|' /C", "calc'!A0", "S004", "dan@uni.example", "", "100", "Missing"]]
    assert (tmp_path / "grades_canvas.csv").read_bytes().count(b"\r\n") == 6    # RFC 4180 line ends


def test_zero_for_nothing_handed_in_only_when_asked(tmp_path):
    write_lms_files(entries(), tmp_path, Target("Environment map (1234)", "Environment map", 10.0, zero_missing=True))
    canvas = read(tmp_path / "grades_canvas.csv")
    assert [r[-1] for r in canvas[2:]] == ["10", "6.39", "", "0"]     # ungradable stays blank
    assert read(tmp_path / "grades_gradescope.csv")[-1][4:] == ["0", "100", "Missing"]


def test_a_canvas_export_names_its_assignment_column(tmp_path):
    path = tmp_path / "canvas.csv"
    path.write_text("Student,ID,SIS User ID,SIS Login ID,Section,Environment map (1234),Quiz 1 (77),Current Score\n"
                    '"Doe, Jane",555,1001,jdoe,S1,,,\n')
    assert load_roster(path).assignments == ["Environment map (1234)", "Quiz 1 (77)"]
    path.write_text("First Name,Last Name,SID,Email\nJane,Doe,1001,jdoe@uni.edu\n")
    assert load_roster(path).assignments == []


def test_a_submission_named_like_an_lms_file_does_not_take_its_place(tmp_path):
    from grader.course.grade_all import find_submissions
    for name in ("grades_canvas.csv.zip", "grades_moodle.csv.cpp", "grades_gradescope.csv"):
        (tmp_path / name).mkdir() if "." not in name.rsplit(".csv", 1)[1] else (tmp_path / name).write_text("")
    assert sorted(find_submissions(tmp_path)) == ["grades_canvas.csv_", "grades_gradescope.csv_", "grades_moodle.csv_"]


class Text(HTMLParser):
    """A page's visible text, one string per text node (style and script left out)."""

    def __init__(self, page: str):
        super().__init__()
        self.texts, self._skip = [], 0
        self.feed(page)

    def handle_starttag(self, tag, attrs):
        self._skip += tag in ("style", "script")
        self.texts += [v for k, v in attrs if k in ("aria-label", "alt", "title") and v]

    def handle_endtag(self, tag):
        self._skip -= tag in ("style", "script")

    def handle_data(self, data):
        if not self._skip and data.strip():
            self.texts.append(data.strip())


def test_the_class_page_in_japanese_leaves_no_english_sentence(tmp_path):
    """grade-all --lang ja: every word the page itself says is Japanese; what
    stays is data (names, ids, file names, the tool's name, numbers) and
    the words the glossary keeps (diagnosis ids, LMS names). The reasons
    grade-all gives (entries it skipped, roster rows it left out, a
    submission not compared) come from where grade-all makes them."""
    from grader import i18n
    from grader.course.grade_all import OWN_TIMEOUT_WHY, skipped_entries
    from grader.course.similarity import NOTHING_OF_ITS_OWN
    folder = tmp_path / "class"
    folder.mkdir()
    for name in (".DS_Store", "notes.txt", "README"):
        (folder / name).write_text("")
    (folder / "link.zip").symlink_to(folder / "notes.txt")
    roster = tmp_path / "roster.csv"
    roster.write_text("First Name,Last Name,SID,Email,Role\nGus,Gray,S9,,Student\n"
                      "Grace,Hopper,,ghopper@uni.example,Instructor\nTest,Student,,,Student\n")
    rows = ROWS[:4] + [Row("fay", "timeout", 40.0, 100.0, {}, ["timeout"], first_diagnosis="timeout"),
                       Row("gus", MISSING, 0.0, 100.0)]
    similarity = {"tool": "copydetect 0.5.0", "compared": 5, "min_listed": 0.5, "boilerplate": "template.cpp",
                  "pairs": [pair("ann", "ben", 0.9)],
                  "not_compared": [{"student": "zed", "reason": NOTHING_OF_ITS_OWN}]}
    data = {"similarity": similarity, "grade_again": {"statuses": ["timeout"], "students": ["fay"]},
            "own_timeouts": {"students": ["fay"], "why": OWN_TIMEOUT_WHY}, "skipped": skipped_entries(folder),
            "roster": {"file": "roster.csv", "students": 6, "matched": 5, "lms_files": ["grades_canvas.csv"],
                       "missing": [{"id": "S9", "name": "gus", "email": ""}], "unmatched": ["hal"],
                       "left_out": load_roster(roster).left_out}}
    assert len(data["skipped"]) == 4 and len(data["roster"]["left_out"]) == 2
    before = i18n.language()
    i18n.set_language("ja")
    try:
        write_summary(rows, tmp_path, data=data)
    finally:
        i18n.set_language(before)
    page = (tmp_path / "summary.html").read_text()
    assert '<html lang="ja">' in page
    data_words = {"alice", "bob", "carol", "dave", "fay", "gus", "hal", "ann", "ben", "Student", "Test",
                  "copydetect", "template", "cpp", "roster", "csv", "grades_canvas", "gradebook", "summary", "json",
                  "md", "code", "of", "Canvas", "Moodle", "Gradescope", "grade", "all", "docs", "study",
                  "zed", "Grace", "Hopper", "Instructor", "Store", "notes", "txt", "README", "link", "zip"}
    from grader.grading.catalogue import _ENTRIES
    data_words |= {"readTexture", "fetchColor", "CPU"}     # code and CPU, as the glossary keeps them
    ids = sorted((e.id for e in _ENTRIES), key=len, reverse=True)
    catalogue_ids = re.compile("|".join(re.escape(i) for i in ids))    # diagnosis ids, shown as they are
    english = []
    for text in Text(page).texts + (tmp_path / "summary.md").read_text().splitlines():
        text = re.sub(r"\S+\.(?:csv|json|md|png)\b|\b[a-z]+(?:_[a-z]+)+\b", "", catalogue_ids.sub("", text))
        words = re.findall(r"[A-Za-z]{3,}", text)      # file names and gradebook.csv's column names are data
        if [w for w in words if w not in data_words]:
            english.append(text)
    assert english == [], english


def test_grade_all_writes_the_class_page_in_the_reports_language(tmp_path):
    """--lang ja reached each student's grading but not the page grade-all
    writes itself (issue 33): the summary is chosen the way grade() chooses."""
    from grader import i18n
    from grader.course.grade_all import _summary
    from grader.grading.grade import GradeOptions
    before = i18n.language()
    _summary(ROWS[:2], tmp_path, {}, GradeOptions(lang="ja"))
    assert i18n.language() == before
    assert '<html lang="ja">' in (tmp_path / "summary.html").read_text()
    assert (tmp_path / "summary.md").read_text().startswith("# クラスの採点結果")
