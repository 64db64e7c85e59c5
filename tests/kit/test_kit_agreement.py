"""One judge (issues 20 and 30): the kit's `make selfcheck`, unpacked alone
and run on nothing but its own copy of the grader, gives what the grader
gives students (`grade --visible-only`, its random inputs drawn from the
course secret, not the kit's public seed): the same points per check the kit
runs (to 0.01) and the same diagnosis ids, on submissions of every zoo.

`make test-all` runs SUBSET (one or two per zoo folder, about a minute on two
cores), two of them also with a failing bwrap first on PATH (privilege-drop
as root; on a laptop without bubblewrap, the worker alone); `make
kit-agreement` (pytest -m agreement) runs every .cpp of every zoo, many
minutes. The grader's live reference on one side, the kit's
recorded answers and renderer-only library on the other: a question the
recording missed is a harness error in the kit, which shows here."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from fake_bwrap import write_failing_bwrap
from grader import PROJECT_ROOT
from project_paths import SUBMISSIONS

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]   # builds the kit, grades each submission twice

ZOOS = sorted(p for p in SUBMISSIONS.iterdir() if p.is_dir())
EVERY = sorted(SUBMISSIONS.rglob("*.cpp"))
# Deterministic and fast: per zoo, one file that grades in seconds (a hang
# or a crash search takes the grader 20-30 s; a hostile one printing
# megabytes, minutes), and two of the compound zoo (two mistakes each: both
# functions judged; one crashes, one needs the read-back).
SUBSET = [SUBMISSIONS / name for name in (
    "attacks/calls_reference.cpp",
    "blind/hostile_recorded-by-own-blend_v-flipped-pos-z.cpp",
    "blind2/uv-clamp-texel-centres_half-over-w.cpp",
    "build/syntax_error.cpp",
    "compound/float-args_wh-swapped.cpp",
    "correct/idiomatic.cpp",
    "correct_lead/if_chains.cpp",
    "footprint/box-quarter-weights-top-down_table.cpp",
    "hostile/read_secrets.cpp",
    "offmodel/attack18/half-texel-fetch_handout-read.cpp",
    "patterns/rotated-90-every-face_table.cpp",
    "record/static-face-size_switch.cpp",
    "recording/tag_detector.cpp",
    "redteam/terminal_escapes.cpp",
    "redteam2/believed_on_two_faces.cpp",
    "redteam3/readtexture_vouches_for_cheap_lookups.cpp",
    "redteam4/correct_control.cpp",
    "redteam5/knows_the_tags.cpp",
    "redteam6/reach_the_spare.cpp",
    "resources/pipe_filler.cpp",
    "runtime_attacks/forged_reply.cpp",
    "wrong/u-flipped-pos-x.cpp",
)]
# Also without bubblewrap: a refused build and a graded one.
WITHOUT_BWRAP = [SUBMISSIONS / "attacks" / "calls_reference.cpp", SUBMISSIONS / "compound" / "float-args_wh-swapped.cpp"]


def _name(path: Path) -> str:
    return path.relative_to(SUBMISSIONS).as_posix()


def test_the_subset_covers_every_zoo():
    assert all(p.is_file() for p in SUBSET), [str(p) for p in SUBSET if not p.is_file()]
    # kit_redteam: every one of its files is compared in tests/kit/test_kit_redteam.py.
    # resources (issue 32): pipe_filler here; the spinners agree too but take the
    # pair 72 s and 180 s on a busy machine; memory_hog touches 1 GiB in every new
    # worker, so under load its grading can spend the 150 s all lookups share
    # (grader.worker.lookups.GRADING_BUDGET_S, a wall-clock limit) before the renders:
    # measured 2026-12-07, kit and grader run at once, renders 5.71 in the kit
    # ("used up the 150 s") and 20 in the grader: the machine decides, not the code.
    assert {p.relative_to(SUBMISSIONS).parts[0] for p in SUBSET} == {z.name for z in ZOOS} - {"kit_redteam"}
    assert set(WITHOUT_BWRAP) <= set(SUBSET)


def clean_environment(**extra: str) -> dict:
    """No PYTHONPATH, no secret from the caller: the kit sees only itself."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "GRADER_SECRET", "ENVMAP_LIBRARY")}
    return {**env, **extra}


def environment(mode: str, tmp_path: Path) -> dict:
    """The environment of both runs: bubblewrap as installed, or a failing
    bwrap first on PATH (privilege-drop as root, a laptop without it otherwise)."""
    if mode == "bubblewrap":
        return clean_environment()
    fake = write_failing_bwrap(tmp_path / "fakebin")
    return clean_environment(PATH=f"{fake}:{os.environ.get('PATH', '/usr/bin:/bin')}")


@pytest.fixture(scope="module")
def kit_alone(student_kit, tmp_path_factory) -> Path:
    """The kit's zip (the session's, tests/conftest.py) unpacked alone in an empty folder."""
    kit = student_kit
    where = tmp_path_factory.mktemp("alone")
    with zipfile.ZipFile(kit.zip_path) as z:
        z.extractall(where)
    folder = where / "student-kit"
    found = subprocess.run([sys.executable, "-c", "import grader; print(grader.__file__)"], cwd=folder,
                           env=clean_environment(PYTHONPATH="selfcheck"), capture_output=True, text=True, check=True)
    assert Path(found.stdout.strip()).is_relative_to(folder / "selfcheck"), found.stdout
    return folder


def per_check(results: Path) -> dict[str, tuple[float, list[str]]]:
    """results.json (Gradescope's format) as {check: (points, sorted diagnosis ids)}."""
    data = json.loads(results.read_text())
    # Every check here is visible (--visible-only), so each carries its ids.
    return {t["extra_data"]["check"]: (t["score"], t["extra_data"]["diagnoses"]) for t in data["tests"]}


def agree(kit: Path, source: Path, scratch: Path, env: dict) -> tuple[dict, dict]:
    """(the kit's per_check, the grader's) for `source`, both run at once."""
    folder = scratch / "kit"
    shutil.copytree(kit, folder, symlinks=True)
    shutil.copyfile(source, folder / "EnvironmentMap.cpp")
    kit_run = subprocess.Popen(["make", "-s", "selfcheck", f"SELFCHECK_PYTHON={sys.executable}"], cwd=folder,
                               env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    grader_out = scratch / "grader"
    grader_run = subprocess.run([sys.executable, "-m", "grader", "grade", "--visible-only",
                                 str(source), "--out", str(grader_out)], cwd=PROJECT_ROOT, env=env,
                                capture_output=True, text=True, timeout=900)
    kit_log = kit_run.communicate(timeout=900)[0]
    summary = folder / "build" / "selfcheck" / "selfcheck.json"
    assert summary.is_file(), kit_log
    assert (grader_out / "results.json").is_file(), grader_run.stdout + grader_run.stderr
    assert json.loads(summary.read_text()) == json.loads((folder / "build" / "selfcheck" / "results.json").read_text())
    return per_check(summary), per_check(grader_out / "results.json")


def assert_agree(got: dict, expected: dict) -> None:
    from grader.kit import NOT_IN_KIT
    assert list(got) == [name for name in expected if name not in NOT_IN_KIT]
    expected = {name: expected[name] for name in got}
    for name, (points, ids) in expected.items():
        assert abs(got[name][0] - points) <= 0.01 + 1e-9 and got[name][1] == ids, (name, got[name], (points, ids))


@pytest.mark.parametrize("mode, source", [("bubblewrap", p) for p in SUBSET] + [("no-bwrap", p) for p in WITHOUT_BWRAP],
                         ids=lambda v: _name(v) if isinstance(v, Path) else v)
def test_the_kit_agrees_with_the_grader(kit_alone, tmp_path, mode, source):
    assert_agree(*agree(kit_alone, source, tmp_path, environment(mode, tmp_path)))


@pytest.mark.agreement
@pytest.mark.parametrize("source", EVERY, ids=_name)
def test_the_kit_agrees_with_the_grader_on_every_zoo(kit_alone, tmp_path, source):
    assert_agree(*agree(kit_alone, source, tmp_path, clean_environment()))
