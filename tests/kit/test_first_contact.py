"""The kit's first contact on a machine that lacks something: what `make`
says when g++, cc or python3 is missing, and the one quiet line about the
sandbox on a machine without bubblewrap.

"A root without g++" is a bubblewrap view of this machine whose /usr/bin
holds only make, sh, mkdir and python3 (no compiler driver anywhere on
PATH); where bubblewrap cannot run, a PATH without them stands in."""
from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from grader.kit.selfcheck import OWN_MACHINE, quiet_about_own_machine
from grader.reports.terminal import summary
from grader.reports.view import build_view
from grader.grading.results import CheckResult, GradeResult
from grader.worker.sandbox import fallback_warning, sandbox_problem

pytestmark = pytest.mark.slow   # builds the student kit (once per session)

INSTALL = {"Debian, Ubuntu and WSL:  sudo apt install build-essential", "macOS:                   xcode-select --install"}


@pytest.fixture
def kit_copy(student_kit, tmp_path) -> Path:
    folder = tmp_path / "kit"
    shutil.copytree(student_kit.folder, folder, symlinks=True)
    shutil.rmtree(folder / "build", ignore_errors=True)
    return folder


def run_without(folder: Path, target: str, keep: tuple[str, ...]) -> subprocess.CompletedProcess:
    """`make target` where /usr/bin holds only `keep` (bubblewrap), else with
    PATH holding only links to them."""
    if sandbox_problem() is None:
        binds = [a for name in keep for a in ("--ro-bind", shutil.which(name, path="/usr/bin"), f"/usr/bin/{name}")]
        cmd = ["bwrap", "--ro-bind", "/", "/", "--tmpfs", "/usr/bin", *binds, "--dev", "/dev", "--proc", "/proc",
               "--bind", str(folder), str(folder), "--chdir", str(folder), "--setenv", "PATH", "/usr/bin:/bin",
               "make", target]
        return subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    bin_dir = folder.parent / "bin"
    bin_dir.mkdir()
    for name in keep:
        (bin_dir / name).symlink_to(shutil.which(name))
    return subprocess.run(["make", target], cwd=folder, capture_output=True, text=True, timeout=120,
                          env={"PATH": str(bin_dir), "HOME": str(folder)})


@pytest.mark.parametrize("target", ["run", "selfcheck"])
def test_without_a_compiler_make_says_what_to_install(kit_copy, target):
    run = run_without(kit_copy, target, ("make", "sh", "mkdir", "python3"))
    assert run.returncode == 2, run.stdout + run.stderr
    assert run.stderr.startswith("g++ (the C++ compiler) is not installed (or not on PATH)"), run.stderr
    assert all(line in run.stderr for line in INSTALL), run.stderr
    assert "No such file or directory" not in run.stderr + run.stdout
    assert not (kit_copy / "build").exists()     # nothing half-built


def test_without_python_make_selfcheck_says_what_to_install(kit_copy):
    compilers = tuple(n for n in ("g++", "cc", "as", "ld") if shutil.which(n, path="/usr/bin"))
    run = run_without(kit_copy, "selfcheck", ("make", "sh", "mkdir", *compilers))
    assert run.returncode == 2, run.stdout + run.stderr
    assert run.stderr.startswith("python3 (Python 3.11 or later) is not installed (or not on PATH): make selfcheck "
                                 "needs it"), run.stderr
    assert "sudo apt install python3 python3-venv" in run.stderr and "brew install python" in run.stderr


def test_no_sandbox_on_the_students_machine_is_one_quiet_line():
    """Where bubblewrap is missing the kit runs the student's own code
    without one: said once, in the isolation line, not as a warning."""
    result = GradeResult(submission="EnvironmentMap", score=25, max_score=25, isolation="unsafe-none",
                         checks=[CheckResult("read_texture", "t", score=25, max_score=25, fraction=1.0)],
                         warnings=[fallback_warning("bwrap (Debian package bubblewrap) is not installed"),
                                   "submitted Vector3.h differs from ours: ignored"])
    quiet_about_own_machine(result)
    assert result.isolation == OWN_MACHINE
    assert result.warnings == ["submitted Vector3.h differs from ours: ignored"]    # other warnings stay
    from rich.console import Console
    console = Console(width=80, record=True, color_system=None)
    console.print(summary(build_view(result)))
    text = console.export_text()
    sandbox_lines = [line for line in text.splitlines() if "sandbox" in line]
    assert sandbox_lines == ["your code ran under: no sandbox (your own code on your own machine)"]
