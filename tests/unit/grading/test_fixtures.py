"""fixtures/ is what the reference makes today, byte for byte, and staleness is caught."""
import shutil
import subprocess
import sys

import pytest

from grader import PROJECT_ROOT
from grader.grading import fixtures


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
            "import grader.grading.fixtures as f; f.generate(progress=lambda s: None)")
    subprocess.run([sys.executable, "-c", code], cwd=project, check=True,
                   env={"ENVMAP_LIBRARY": str(PROJECT_ROOT / "build" / "libenvmap.so"), "PYTHONPATH": str(project)})
    after = {p.relative_to(project): p.read_bytes() for p in (project / "fixtures").rglob("*") if p.is_file()}
    assert after.keys() == before.keys()
    changed = [str(k) for k in before if before[k] != after[k]]
    assert changed == []


def test_fixtures_holds_only_what_is_generated_and_read():
    """Every file in fixtures/ is a render the checks load (named in the
    manifest), the manifest, or the study's table: nothing written for no
    reader (fixtures/sweeps/ was, 948 KB, until it went)."""
    import json
    from grader.study import STUDY_CSV
    manifest = json.loads(fixtures.MANIFEST.read_text())
    present = {p.relative_to(PROJECT_ROOT).as_posix() for p in fixtures.FIXTURES.rglob("*") if p.is_file()}
    read = set(manifest["files"]) | {p.relative_to(PROJECT_ROOT).as_posix() for p in (fixtures.MANIFEST, STUDY_CSV)}
    assert present == read
    assert set(manifest["files"]) == {f.path.relative_to(PROJECT_ROOT).as_posix() for f in fixtures.render_fixtures()}


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


def test_changed_render_settings_make_fixtures_stale(project_copy, monkeypatch):
    monkeypatch.setattr(fixtures, "RENDER_SPP", fixtures.RENDER_SPP + 1)
    with pytest.raises(fixtures.StaleFixtures, match="samples per pixel changed"):
        fixtures.check_stale(project_copy)


def test_the_generators_own_text_is_not_an_input():
    """Moving or re-wording grader's Python must not stale the fixtures: what
    determines them is the reference, the scenes, the maps and the recorded
    settings and GENERATOR_VERSION."""
    assert [p for p in fixtures.inputs() if not p.is_relative_to(PROJECT_ROOT / "reference")
            and p.suffix not in (".cfg", ".hdr")] == []


def test_fixtures_check_command_reports_up_to_date():
    done = subprocess.run([sys.executable, "-m", "grader", "fixtures", "--check"], cwd=PROJECT_ROOT,
                          capture_output=True, text=True)
    assert done.returncode == 0 and "up to date" in done.stdout


def test_grading_refuses_stale_fixtures_and_says_what_to_run(project_copy, tmp_path, monkeypatch):
    from grader.grading.grade import GradeOptions, grade
    with open(project_copy / "reference" / "src" / "lookup.c", "ab") as f:
        f.write(b"\n")
    real_check = fixtures.check_stale
    # grade() checks the project it runs from; point it at the touched copy.
    monkeypatch.setattr(fixtures, "check_stale", lambda: real_check(project_copy))
    with pytest.raises(fixtures.StaleFixtures, match=r"reference/src/lookup.c changed.*make fixtures"):
        grade(PROJECT_ROOT / "examples" / "perfect", tmp_path / "out", GradeOptions())
    assert not (tmp_path / "out").exists()     # refused before anything was graded


# ---- the environment that made the fixtures ------------------------------------------


def test_manifest_records_library_and_compiler_versions():
    import json
    from importlib import metadata
    recorded = json.loads(fixtures.MANIFEST.read_text())["environment"]
    assert set(recorded["libraries"]) == {"numpy", "flip-evaluator", "OpenImageIO"}
    assert recorded["libraries"]["numpy"] == metadata.version("numpy")
    assert set(recorded["compilers"]) == {"cc", "g++"}
    assert all(v != "not found" and v[0].isalpha() for v in recorded["compilers"].values()), recorded


def test_same_environment_gives_no_warning():
    assert fixtures.environment_warnings() == []
    fixtures.check_environment()


def test_another_numpy_warns_and_strict_refuses(monkeypatch):
    real = fixtures._library_version
    monkeypatch.setattr(fixtures, "_library_version", lambda n: "1.26.4" if n == "numpy" else real(n))
    warnings = fixtures.environment_warnings()
    assert len(warnings) == 1 and warnings[0].startswith("numpy is '1.26.4' here but the fixtures were made with")
    assert "make venv" in warnings[0]
    with pytest.raises(fixtures.EnvironmentMismatch, match="numpy is '1.26.4'"):
        fixtures.check_environment()


def test_a_manifest_without_versions_says_to_record_them(project_copy):
    import json
    manifest = project_copy / "fixtures" / "manifest.json"
    data = json.loads(manifest.read_text())
    del data["environment"]
    manifest.write_text(json.dumps(data))
    assert fixtures.environment_warnings(project_copy) == [
        "fixtures/manifest.json does not record the library and compiler versions the fixtures were made with: "
        "run `make fixtures` to record them."]


def test_grade_warns_in_the_report_and_strict_exits_3(monkeypatch, tmp_path, capsys):
    """In-process through the command line: the report carries the warning;
    --strict refuses before grading, with exit status 3 and the reason."""
    import json
    from grader import cli
    broken = PROJECT_ROOT / "tests" / "submissions" / "build" / "syntax_error.cpp"
    monkeypatch.setattr(fixtures, "_compiler_version", lambda c: "g++ (Imaginary) 99.0")
    assert cli.main(["grade", str(broken), "--quick", "--out", str(tmp_path / "warned")]) == 0
    warnings = json.loads((tmp_path / "warned" / "results.json").read_text())["extra_data"]["warnings"]
    assert any(w.startswith("g++ is 'g++ (Imaginary) 99.0' here") for w in warnings), warnings
    capsys.readouterr()
    assert cli.main(["grade", str(broken), "--quick", "--strict", "--out", str(tmp_path / "strict")]) == 3
    assert "cc is 'g++ (Imaginary) 99.0' here" in capsys.readouterr().err
    assert not (tmp_path / "strict").exists()


def test_fixtures_check_notes_other_versions_but_passes(monkeypatch, capsys):
    from grader import cli
    real = fixtures._library_version
    monkeypatch.setattr(fixtures, "_library_version", lambda n: "0.1" if n == "flip-evaluator" else real(n))
    assert cli.main(["fixtures", "--check"]) == 0       # not stale: the same inputs made them
    printed = capsys.readouterr().out
    assert "up to date" in printed and "note: flip-evaluator is '0.1' here" in printed
