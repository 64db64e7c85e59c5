"""Issue 18's build attacks where courses grade: Gradescope's /autograder and
PrairieLearn's /grade layouts, as root, in privilege-drop mode (a failing
fake bwrap first on PATH) and under bubblewrap.

The layouts are laid out under a folder of /tmp made 0755 (mkdtemp's 0700
would hide everything from the build uid and prove nothing): autograder/
holds the zip `make gradescope` builds, unpacked into source/ with the
reference built, a submission/ upload folder (the attack, a binary blob
lookup.bin, 0644) and submission_metadata.json; grade/ holds
serverFilesCourse/envmap (the same project), student/, tests/ and data/.
The attacks name the layout's real paths. Each test grades through the
platform's own entry point and asserts the build refused, less than full
marks, and no line of any grader or course file in what the student sees
(results.json, every file beside it).
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

from grader import PROJECT_ROOT
from grader.build.compiler import BUILD_GID, BUILD_UID
from grader.build.compiler import readable_tree
from grader.grading.catalogue import CATALOGUE
from grader.platforms.gradescope import build_bundle

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(os.geteuid() != 0, reason="privilege-drop mode needs root")]

ATTACKS = PROJECT_ROOT / "tests" / "submissions" / "attacks"
SECRET = "course-secret-5f1e9a-never-shown"
TESTS_SECRET = "question-tests-answer-77b2c0"
FAKE_BWRAP = "#!/bin/sh\necho 'bwrap: setting up uid map: Permission denied' >&2\nexit 1\n"
# (attack file, what its refusal must be): one per attack class of issue 18.
CLASSES = [("asm_incbin_reference.cpp", "refused-source"),
           ("asm_incbin_upload.cpp", "refused-source"),
           ("line_pragma_warning.cpp", "refused-source"),
           ("line_digraph_pragma_operator.cpp", "refused-source")]


@pytest.fixture(scope="module")
def layout():
    top = Path(tempfile.mkdtemp(prefix="production-layout-"))
    top.chmod(0o755)
    os.environ["GRADER_SECRET"], old = SECRET, os.environ.get("GRADER_SECRET")
    try:
        bundle = build_bundle(top / "autograder.zip")
    finally:
        os.environ.pop("GRADER_SECRET") if old is None else os.environ.__setitem__("GRADER_SECRET", old)
    autograder = top / "autograder"
    source = autograder / "source"
    source.mkdir(parents=True)
    subprocess.run(["unzip", "-q", str(bundle), "-d", str(source)], check=True)
    (top / "autograder.zip").unlink()
    (source / ".venv").symlink_to(PROJECT_ROOT / ".venv")
    subprocess.run(["make", "-s", "-C", str(source), "reference"], check=True, capture_output=True, timeout=600)
    (autograder / "submission_metadata.json").write_text(json.dumps({"users": [{"email": "a@b.c"}],
                                                                     "secret": SECRET}))
    grade = top / "grade"
    for name in ("student", "tests", "data", "serverFilesCourse"):
        (grade / name).mkdir(parents=True)
    (grade / "serverFilesCourse" / "envmap").symlink_to(source)
    (grade / "tests" / "answer.txt").write_text(f"{TESTS_SECRET}\n" * 40)
    (grade / "tests" / "reference.so").write_bytes((source / "build" / "libenvmap.so").read_bytes())
    (grade / "data" / "data.json").write_text(json.dumps({"answer": TESTS_SECRET}))
    bin_dir = top / "fake-bin"
    bin_dir.mkdir()
    (bin_dir / "bwrap").write_text(FAKE_BWRAP)
    (bin_dir / "bwrap").chmod(0o755)
    open_up(top)
    yield top
    shutil.rmtree(top, ignore_errors=True)


def open_up(top: Path) -> None:
    """Modes as an image's files have them: world-readable (as unpacked)."""
    for path in [top, *top.rglob("*")]:
        if not path.is_symlink():
            path.chmod(0o755 if path.is_dir() or os.access(path, os.X_OK) else 0o644)


def secret_lines(top: Path) -> set[str]:
    """Lines of grader and course files a leak would show: the secret, and
    every longer line of the rubric, the reference's lookup and the question's files."""
    source = top / "autograder" / "source"
    lines = {SECRET, TESTS_SECRET}
    for path in (source / "grader" / "grading" / "rubric.toml", source / "reference" / "src" / "lookup.c"):
        lines |= {t.strip() for t in path.read_text().splitlines() if len(t.strip()) >= 30}
    return lines


def attack_text(name: str, top: Path) -> str:
    text = (ATTACKS / name).read_text()
    return text.replace("/autograder/", f"{top}/autograder/").replace("/grade/", f"{top}/grade/")


def environment(top: Path, mode: str) -> dict:
    env = {**os.environ, "AUTOGRADER_ROOT": str(top / "autograder"), "PL_GRADE_ROOT": str(top / "grade")}
    if mode == "privilege-drop":
        env["PATH"] = f"{top / 'fake-bin'}:{env['PATH']}"
    return env


def grade_on_gradescope_file(top: Path, source: Path) -> tuple[dict, str]:
    return grade_on_gradescope(top, None, "privilege-drop", text=source.read_text())


def grade_on_prairielearn_file(top: Path, source: Path) -> tuple[dict, str]:
    return grade_on_prairielearn(top, None, "privilege-drop", text=source.read_text())


def grade_on_gradescope(top: Path, name: str | None, mode: str, suffix: str = "",
                        text: str | None = None) -> tuple[dict, str]:
    root = top / "autograder"
    for folder in ("submission", "results"):
        shutil.rmtree(root / folder, ignore_errors=True)
        (root / folder).mkdir()
        (root / folder).chmod(0o755)
    (root / "submission" / "EnvironmentMap.cpp").write_text(text if text is not None
                                                           else attack_text(name, top) + suffix)
    shutil.copy(root / "source" / "build" / "libenvmap.so", root / "submission" / "lookup.bin")
    for path in (root / "submission").iterdir():
        path.chmod(0o644)
    run = subprocess.run([str(root / "source" / "run_autograder")], cwd=root, capture_output=True, text=True,
                         timeout=600, env=environment(top, mode))
    assert run.returncode == 0, run.stdout + run.stderr
    seen = "\n".join(p.read_text(errors="replace") for p in (root / "results").rglob("*") if p.is_file())
    return json.loads((root / "results" / "results.json").read_text()), seen


def grade_on_prairielearn(top: Path, name: str | None, mode: str, text: str | None = None) -> tuple[dict, str]:
    root = top / "grade"
    shutil.rmtree(root / "results", ignore_errors=True)
    for path in (root / "student").iterdir():
        path.unlink()
    (root / "student" / "EnvironmentMap.cpp").write_text(text if text is not None else attack_text(name, top))
    (root / "student" / "EnvironmentMap.cpp").chmod(0o644)
    entry = root / "serverFilesCourse" / "envmap" / "grader" / "platforms" / "prairielearn" / "entrypoint.sh"
    run = subprocess.run([str(entry)], capture_output=True, text=True, timeout=600, env=environment(top, mode))
    assert run.returncode == 0, run.stdout + run.stderr
    seen = "\n".join(p.read_text(errors="replace") for p in (root / "results").rglob("*") if p.is_file())
    return json.loads((root / "results" / "results.json").read_text()), seen


def assert_nothing_leaked(top: Path, seen: str) -> None:
    leaked = sorted(line for line in secret_lines(top) if line in seen)
    assert not leaked, leaked[:5]


@pytest.mark.parametrize("mode", ["privilege-drop", "bubblewrap"])
@pytest.mark.parametrize("name, diagnosis", CLASSES, ids=[c[0].removesuffix(".cpp") for c in CLASSES])
def test_gradescope_refuses_the_attack_and_shows_nothing_of_ours(layout, name, diagnosis, mode):
    data, seen = grade_on_gradescope(layout, name, mode)
    assert data["score"] == 0, data["output"][:2000]
    assert CATALOGUE[diagnosis].title in seen and "refused before it could be built" in data["output"], \
        data["output"][:2000]
    assert_nothing_leaked(layout, seen)


@pytest.mark.parametrize("mode", ["privilege-drop", "bubblewrap"])
@pytest.mark.parametrize("name, diagnosis", CLASSES, ids=[c[0].removesuffix(".cpp") for c in CLASSES])
def test_prairielearn_refuses_the_attack_and_shows_nothing_of_ours(layout, name, diagnosis, mode):
    data, seen = grade_on_prairielearn(layout, name, mode)
    assert data["gradable"] is True and data["score"] == 0, data["message"]
    assert CATALOGUE[diagnosis].title in seen, data["output"][:2000]
    assert_nothing_leaked(layout, seen)


@pytest.mark.representative
def test_in_privilege_drop_mode_the_build_uid_reads_nothing_of_ours(layout):
    # Listed as the build uid sees it: before grading, the layout is open
    # (so the listing can find files); after one privilege-drop grading,
    # nothing under /autograder or /grade is readable to it.
    open_up(layout)
    before = readable_tree(BUILD_UID, BUILD_GID, [layout])
    assert {layout / "autograder" / "source" / "grader" / "grading" / "rubric.toml", layout / "grade" / "tests" / "answer.txt",
            layout / "autograder" / "submission_metadata.json"} <= set(before)
    # A source not built before (a cached verdict compiles nothing, so it needs no probe).
    grade_on_gradescope(layout, "asm_incbin_reference.cpp", "privilege-drop", suffix="// fresh\n")
    after = readable_tree(BUILD_UID, BUILD_GID, [layout])
    assert [p for p in after if p not in (layout, layout / "fake-bin", layout / "fake-bin" / "bwrap")] == []


@pytest.mark.representative
def test_a_pasted_has_include_finds_no_course_file(layout):
    # Built by the bundle's own grader, as root with the failing bwrap, in
    # the Gradescope layout: the log (the student's, when the build fails)
    # says what the probe found.
    root = layout / "autograder"
    upload = root / "submission"
    shutil.rmtree(upload, ignore_errors=True)
    upload.mkdir()
    (upload / "EnvironmentMap.cpp").write_text(attack_text("has_include_probe.cpp", layout))
    script = ("import json; from grader.build import build_submission; "
              "r = build_submission('%s'); print(json.dumps([r.isolation, r.log]))" % (upload / "EnvironmentMap.cpp"))
    done = subprocess.run([str(root / "source" / ".venv" / "bin" / "python"), "-c", script], cwd=root / "source",
                          capture_output=True, text=True, timeout=600, env=environment(layout, "privilege-drop"))
    isolation, log = json.loads(done.stdout.splitlines()[-1])
    assert isolation == "privilege-drop"
    # GCC opens the file to answer: refused by the kernel, it stops with
    # "Permission denied" (so existence can still be told, not content).
    assert "FOUND the course file" not in log, log
    assert "NOTFOUND" in log or "Permission denied" in log, log
    assert_nothing_leaked(layout, log)


@pytest.mark.parametrize("platform", ["gradescope", "prairielearn"])
def test_a_correct_submission_still_gets_full_marks_once_our_files_are_closed(layout, platform):
    # The confinement must not cost an honest student anything: the worker
    # enters its chroot as root, and root still reads the closed tree.
    correct = PROJECT_ROOT / "tests" / "submissions" / "correct" / "idiomatic.cpp"
    shutil.copy(correct, layout / "correct.cpp")
    if platform == "gradescope":
        data, _ = grade_on_gradescope_file(layout, layout / "correct.cpp")
        assert data["score"] == sum(t["max_score"] for t in data["tests"]) > 0, data["output"][:2000]
    else:
        data, _ = grade_on_prairielearn_file(layout, layout / "correct.cpp")
        assert data["gradable"] is True and data["score"] == 1.0, data["message"]
    assert readable_tree(BUILD_UID, BUILD_GID, [layout / "autograder"]) == []
