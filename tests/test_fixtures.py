"""fixtures/ is what the reference makes today, byte for byte, and staleness is caught."""
import shutil
import subprocess
import sys

import pytest

from grader import PROJECT_ROOT, fixtures


def test_committed_fixtures_are_current():
    fixtures.check_stale()


def test_regenerating_gives_identical_bytes(tmp_path):
    """Render every fixture again in a copy of the project: same bytes as committed."""
    project = tmp_path / "project"
    for name in ("reference", "scenes", "Cubemap", "grader", "fixtures"):
        shutil.copytree(PROJECT_ROOT / name, project / name, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(PROJECT_ROOT / "envmap_test.cfg", project)
    before = {p.relative_to(project): p.read_bytes() for p in (project / "fixtures").rglob("*") if p.is_file()}
    code = ("import grader, pathlib; grader.PROJECT_ROOT = pathlib.Path('.').resolve();"
            "import grader.fixtures as f; f.generate(progress=lambda s: None)")
    subprocess.run([sys.executable, "-c", code], cwd=project, check=True,
                   env={"ENVMAP_LIBRARY": str(PROJECT_ROOT / "build" / "libenvmap.so"), "PYTHONPATH": str(project)})
    after = {p.relative_to(project): p.read_bytes() for p in (project / "fixtures").rglob("*") if p.is_file()}
    assert after.keys() == before.keys()
    changed = [str(k) for k in before if before[k] != after[k]]
    assert changed == []


@pytest.fixture
def project_copy(tmp_path):
    project = tmp_path / "p"
    for rel in fixtures.inputs():
        target = project / rel.relative_to(PROJECT_ROOT)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(rel, target)
    shutil.copytree(PROJECT_ROOT / "fixtures", project / "fixtures")
    fixtures.check_stale(project)       # the copy starts fresh
    return project


@pytest.mark.parametrize("touched", ["reference/src/lookup.c", "envmap_test.cfg", "Cubemap/test_environment_map.hdr"])
def test_touching_an_input_makes_fixtures_stale(project_copy, touched):
    with open(project_copy / touched, "ab") as f:
        f.write(b"\n")
    with pytest.raises(fixtures.StaleFixtures, match=f"{touched} changed.*make fixtures"):
        fixtures.check_stale(project_copy)


def test_a_fixture_edited_by_hand_is_caught(project_copy):
    victim = next((project_copy / "fixtures" / "renders").glob("*.npy"))
    victim.write_bytes(victim.read_bytes()[:-1] + b"\0")
    with pytest.raises(fixtures.StaleFixtures, match="edited by hand"):
        fixtures.check_stale(project_copy)


def test_a_new_scene_makes_fixtures_stale(project_copy):
    shutil.copy(project_copy / "envmap_test.cfg", project_copy / "scenes" / "new.cfg")
    with pytest.raises(fixtures.StaleFixtures, match="scenes/new.cfg is new"):
        fixtures.check_stale(project_copy)


def test_fixtures_check_command_reports_up_to_date():
    done = subprocess.run([sys.executable, "-m", "grader", "fixtures", "--check"], cwd=PROJECT_ROOT,
                          capture_output=True, text=True)
    assert done.returncode == 0 and "up to date" in done.stdout


def test_grading_refuses_stale_fixtures_and_says_what_to_run(project_copy, tmp_path, monkeypatch):
    from grader.grade import GradeOptions, grade
    with open(project_copy / "reference" / "src" / "lookup.c", "ab") as f:
        f.write(b"\n")
    real_check = fixtures.check_stale
    # grade() checks the project it runs from; point it at the touched copy.
    monkeypatch.setattr(fixtures, "check_stale", lambda: real_check(project_copy))
    with pytest.raises(fixtures.StaleFixtures, match=r"reference/src/lookup.c changed.*make fixtures"):
        grade(PROJECT_ROOT / "examples" / "perfect", tmp_path / "out", GradeOptions())
    assert not (tmp_path / "out").exists()     # refused before anything was graded
