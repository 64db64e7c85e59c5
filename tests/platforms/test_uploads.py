"""What each platform hands the grader, read as it arrives: Gradescope's
/autograder/submission and a Moodle download's folder hold the student's
upload as it is, so a zip sits inside a folder."""
from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

from grader import PROJECT_ROOT
from grader.intake import SubmissionError, select_source

TEMPLATE = PROJECT_ROOT / "student_template"
SOURCE = (PROJECT_ROOT / "tests" / "submissions" / "correct" / "if_chain.cpp").read_bytes()


def _zip(path: Path, members: dict[str, bytes]) -> Path:
    with zipfile.ZipFile(path, "w") as z:
        for name, data in members.items():
            z.writestr(name, data)
    return path


@pytest.mark.parametrize("folder, archive", [
    ("submission", "handin.zip"),                                   # Gradescope
    ("Jane Doe_101_assignsubmission_file", "EnvironmentMap.zip"),   # Moodle, downloaded in folders
])
def test_the_one_archive_in_a_folder_is_opened(tmp_path, folder, archive):
    (tmp_path / folder).mkdir()
    _zip(tmp_path / folder / archive, {"work/EnvironmentMap.cpp": SOURCE, "work/notes.txt": b"hi"})
    chosen = select_source(tmp_path / folder, TEMPLATE)
    assert chosen.text == SOURCE and chosen.name == "work/EnvironmentMap.cpp"
    assert chosen.notes[0] == f"graded {archive}, the archive in {folder}."


def test_a_source_beside_an_archive_wins(tmp_path):
    (tmp_path / "EnvironmentMap.cpp").write_bytes(SOURCE)
    _zip(tmp_path / "old.zip", {"EnvironmentMap.cpp": b"// an older attempt\n"})
    assert select_source(tmp_path, TEMPLATE).text == SOURCE


def test_two_archives_are_not_guessed_between(tmp_path):
    _zip(tmp_path / "a.zip", {"EnvironmentMap.cpp": SOURCE})
    _zip(tmp_path / "b.zip", {"EnvironmentMap.cpp": SOURCE})
    with pytest.raises(SubmissionError, match=r"No EnvironmentMap.cpp in the folder .* \(it holds: a.zip, b.zip\)") as e:
        select_source(tmp_path, TEMPLATE)
    assert e.value.diagnosis_id == "no-source"


def test_an_archive_in_an_archive_in_a_folder_is_not_opened(tmp_path):
    inner = _zip(tmp_path / "inner.zip", {"EnvironmentMap.cpp": SOURCE}).read_bytes()
    (tmp_path / "submission").mkdir()
    _zip(tmp_path / "submission" / "outer.zip", {"inner.zip": inner})
    with pytest.raises(SubmissionError) as e:
        select_source(tmp_path / "submission", TEMPLATE)
    assert e.value.diagnosis_id == "no-source" and "inner.zip" in str(e.value)
