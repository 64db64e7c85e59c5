"""The kit's claim attacked as a student would (issue 20's red team): for any
submission `make selfcheck` gives the grader's per-check points and
diagnosis ids (`grade --visible-only --kit-inputs`), and it never reports a
score the grader would not give. Submissions in submissions/kit_redteam/
(the first line of each says what it does and the right verdict), each
covering what the other zoos do not: a BOM and CRLF line ends, state kept
between calls, NaN/inf/-0/denormal answers in a pattern, a crash in some
batches only, code that looks for the kit around it. And the kit's own
files edited (its rubric, its grader): the self-check must refuse, not
report a full score; an edited API header is named. One kit build for the module (test_kit_agreement's
fixture)."""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from test_kit_agreement import agree, assert_agree, clean_environment, environment, kit_alone, per_check  # noqa: F401
from project_paths import SUBMISSIONS

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]   # grades each attack in the kit and in the grader

ZOO = SUBMISSIONS / "kit_redteam"
AGREES = ["bom_crlf.cpp", "stateful_call_count.cpp", "nan_inf_denormal.cpp", "crash_some_batches.cpp",
          "sees_the_kit.cpp"]


def test_every_zoo_file_is_tested():
    assert sorted(p.name for p in ZOO.glob("*.cpp")) == sorted(AGREES)


@pytest.mark.parametrize("name", AGREES)
def test_the_kit_agrees_under_bubblewrap(kit_alone, tmp_path, name):
    assert_agree(*agree(kit_alone, ZOO / name, tmp_path, environment("bubblewrap", tmp_path)))


# A student's machine without bubblewrap (and not root): the kit runs the
# worker unconfined, as the student, where it can see the kit's folder
# through /proc/<ppid>/cwd. Simulated as root by making privilege-drop
# unavailable in the kit's process alone; the grader's side is privilege-drop.
UNCONFINED = ("import sys, grader.worker.sandbox as s\n"
              "s.privilege_drop_problem = lambda: 'not root (a student machine, simulated)'\n"
              "from grader.kit.selfcheck import main\n"
              "sys.exit(main(['--out', 'build/selfcheck']))\n")


@pytest.mark.xfail(strict=True, reason="unconfined, a submission can tell the kit from the grader "
                   "(sees_the_kit.cpp: 95 in the kit, 25 in the grader): no fix but a sandbox")
def test_the_kit_agrees_unconfined(kit_alone, tmp_path):
    source = ZOO / "sees_the_kit.cpp"
    env = environment("no-bwrap", tmp_path)
    folder = tmp_path / "kit"
    shutil.copytree(kit_alone, folder, symlinks=True)
    shutil.copyfile(source, folder / "EnvironmentMap.cpp")
    done = subprocess.run([sys.executable, "-c", UNCONFINED], cwd=folder, env={**env, "PYTHONPATH": "selfcheck"},
                          capture_output=True, text=True, timeout=900)
    assert "no sandbox" in done.stdout, done.stdout + done.stderr       # it did run unconfined
    subprocess.run([sys.executable, "-m", "grader", "grade", "--visible-only", "--kit-inputs", str(source),
                    "--out", str(tmp_path / "grader")], env=env, capture_output=True, text=True, timeout=900)
    assert_agree(per_check(folder / "build" / "selfcheck" / "selfcheck.json"),
                 per_check(tmp_path / "grader" / "results.json"))


def selfcheck(folder: Path) -> subprocess.CompletedProcess:
    return subprocess.run(["make", "-s", "selfcheck", f"SELFCHECK_PYTHON={sys.executable}"], cwd=folder,
                          env=clean_environment(), capture_output=True, text=True, timeout=900)


def test_an_edited_kit_gives_no_score(kit_alone, tmp_path):
    """A wrong fetchColor (the +X face's u flipped) and the kit's rubric edited
    to hide every fetchColor check: the self-check reported 25 / 25 (a false
    full score, FAIL_UNDER=100 passing) before it compared its own files.
    It must refuse, name the file, and leave no score behind, not even an
    earlier run's. A file only converted to CRLF (git's autocrlf) is not an edit."""
    folder = tmp_path / "kit"
    shutil.copytree(kit_alone, folder, symlinks=True)
    shutil.copyfile(ZOO.parent / "wrong" / "u-flipped-pos-x.cpp", folder / "EnvironmentMap.cpp")
    out = folder / "build" / "selfcheck"
    out.mkdir(parents=True)
    (out / "selfcheck.json").write_text(json.dumps({"score": 95}))      # an earlier run's
    rubric = folder / "selfcheck" / "grader" / "grading" / "rubric.toml"
    hidden = 0
    lines = rubric.read_text().splitlines()
    for i, line in enumerate(lines):
        if line.startswith("[checks.") and line not in ("[checks.read_texture]",):
            for j in range(i + 1, min(i + 6, len(lines))):
                if lines[j] == 'visibility = "visible"':
                    lines[j], hidden = 'visibility = "hidden"', hidden + 1
    assert hidden >= 4
    rubric.write_text("\n".join(lines) + "\n")
    score = folder / "selfcheck" / "grader" / "grading" / "score.py"
    score.write_bytes(score.read_bytes().replace(b"\n", b"\r\n"))
    done = selfcheck(folder)
    assert done.returncode != 0, done.stdout
    assert "grader/grading/rubric.toml" in done.stderr and "no score" in done.stderr, done.stderr
    assert "score.py" not in done.stderr, done.stderr
    assert not (out / "selfcheck.json").exists()
    assert "25 / 25" not in done.stdout


def test_a_file_added_to_the_kits_grader_gives_no_score(kit_alone, tmp_path):
    """A module dropped into the kit's grader (here one shadowing nothing yet)
    is an edit too."""
    folder = tmp_path / "kit"
    shutil.copytree(kit_alone, folder, symlinks=True)
    (folder / "selfcheck" / "grader" / "sitecustomize.py").write_text("")
    done = selfcheck(folder)
    assert done.returncode != 0 and "grader/sitecustomize.py" in done.stderr, done.stdout + done.stderr


def test_an_edited_api_header_is_named(kit_alone, tmp_path):
    """A member added to the kit's EnvironmentMap.h and used in
    EnvironmentMap.cpp: `make` builds it, the grader (the course's header)
    does not, nor does the self-check, which said only "did not compile"
    and left the student to wonder why; it now says which provided file is not
    the course's. A fresh kit's files are the course's."""
    folder = tmp_path / "kit"
    shutil.copytree(kit_alone, folder, symlinks=True)
    fresh = selfcheck(folder)
    assert "not the course's" not in fresh.stderr, fresh.stderr
    header = folder / "EnvironmentMap.h"
    member = "    int m_FaceHeight = 0;              // texel rows per face\n"
    assert member in header.read_text()
    header.write_text(header.read_text().replace(member, member + "    double m_Scale = 1.0;\n"))
    source = (ZOO.parent / "correct" / "idiomatic.cpp").read_text()
    used = "    const double px = u * m_FaceWidth;\n"
    assert used in source
    (folder / "EnvironmentMap.cpp").write_text(source.replace(used, "    const double px = u * m_FaceWidth * m_Scale;\n"))
    assert subprocess.run(["make", "-s", "envmap"], cwd=folder, capture_output=True).returncode == 0
    done = selfcheck(folder)
    assert done.returncode != 0 and "EnvironmentMap.h here is not the course's" in done.stderr, done.stdout + done.stderr
