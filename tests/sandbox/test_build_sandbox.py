"""The student's file is compiled inside the sandbox: the compiler sees the
system, our headers and its build folder, nothing else of ours."""
import subprocess

import pytest

from grader import PROJECT_ROOT
from grader.build.common import REFERENCE, TEMPLATE
from grader.worker.sandbox import compiler_command, sandbox_problem

pytestmark = pytest.mark.skipif(sandbox_problem() is not None, reason=f"no sandbox here: {sandbox_problem()}")


def inside(tmp_path, shell: str) -> subprocess.CompletedProcess:
    cmd = compiler_command(["/bin/sh", "-c", shell], [TEMPLATE, REFERENCE / "include"], tmp_path)
    return subprocess.run(cmd, capture_output=True, text=True, timeout=30)


def test_headers_and_build_folder_are_visible_and_the_folder_writable(tmp_path):
    done = inside(tmp_path, f"test -r {TEMPLATE}/EnvironmentMap.h && test -r {REFERENCE}/include/envmap.h "
                            f"&& echo ok > {tmp_path}/out.txt")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out.txt").read_text() == "ok\n"


@pytest.mark.parametrize("secret", ["fixtures/manifest.json", "grader/grading/rubric.toml", "reference/src/lookup.c"])
def test_the_rest_of_the_project_is_not_there(tmp_path, secret):
    assert (PROJECT_ROOT / secret).exists()
    assert inside(tmp_path, f"test -e {PROJECT_ROOT / secret}").returncode != 0


def test_no_environment_leaks_into_the_compiler(tmp_path, monkeypatch):
    monkeypatch.setenv("GRADER_SECRET", "do-not-leak")
    done = inside(tmp_path, "cat /proc/self/environ")
    assert "do-not-leak" not in done.stdout


def test_a_student_build_step_sees_no_project_folder(tmp_path):
    # The student's compile and link get a scratch folder with copies of the
    # API headers and our objects: not even the template or the reference's
    # headers are mounted.
    from grader.build.compiler import Deadline, run_compiler
    probe = " || ".join(f"test -e {p}" for p in (REFERENCE / "include" / "envmap.h",
                                                   TEMPLATE / "EnvironmentMap.h", PROJECT_ROOT / "grader"))
    step = run_compiler(["/bin/sh", "-c", f"{probe} || echo hidden; id -u"], tmp_path, Deadline.of(30),
                "bubblewrap")
    assert step.output.startswith("hidden"), step.output
