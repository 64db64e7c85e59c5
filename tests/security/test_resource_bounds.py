"""Issue 32: every resource a submission can hold is bounded or charged to it,
in both isolation modes (bubblewrap, and privilege-drop as on Gradescope: a
failing bwrap first on PATH, root). tests/submissions/resources/*.cpp holds
the attacks; each file's header says the attack and the verdict.

Memory cgroups are made under this process's own (cgroup v1's memory
controller, or a delegated v2 subtree); where there is none the tests that
need one are skipped with the reason.
"""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from grader import PROJECT_ROOT
from grader.build import build_submission
from grader.worker import SubmissionFailure, Worker, WorkerHarnessError, memory, sandbox
from fake_bwrap import write_failing_bwrap

pytestmark = [pytest.mark.sandbox]

RESOURCES = PROJECT_ROOT / "tests" / "submissions" / "resources"
CORRECT = PROJECT_ROOT / "tests" / "submissions" / "correct"
BWRAP = sandbox.sandbox_problem()
DROP = sandbox.privilege_drop_problem()
CGROUP = memory.cgroup_problem()
MODES = [pytest.param("sandbox", marks=pytest.mark.skipif(BWRAP is not None, reason=f"no bubblewrap: {BWRAP}")),
         pytest.param("privilege-drop", marks=pytest.mark.skipif(DROP is not None, reason=f"no privilege drop: {DROP}"))]
MODES_AVAILABLE = [m for m, problem in (("sandbox", BWRAP), ("privilege-drop", DROP)) if problem is None] or ["plain"]
needs_cgroup = pytest.mark.skipif(CGROUP is not None, reason=f"no memory cgroup here: {CGROUP}")


def library(name: str) -> Path:
    build = build_submission(RESOURCES / f"{name}.cpp")
    assert build.ok, build.log
    return build.library


def faces() -> np.ndarray:
    return np.random.default_rng(3).random((6, 8, 8, 3), dtype=np.float32)


def proc_field(pid: int, name: str) -> str:
    return Path(f"/proc/{pid}/{name}").read_text()


# ---- one worker ---------------------------------------------------------------------------

@pytest.mark.parametrize("mode", MODES)
def test_the_pipe_filler_holds_a_few_pipes_and_is_the_oom_killers_first_choice(mode):
    with Worker(library("pipe_filler"), sandbox=mode) as worker:
        worker.set_faces(faces())
        assert worker.fetch(np.eye(3)).shape == (3, 3)     # it loaded, and it answers
        pid = worker._worker_pid
        assert proc_field(pid, "oom_score_adj").strip() == "1000"
        assert re.search(r"Max open files\s+64\s+64", proc_field(pid, "limits"))
        held = int(re.search(r"pipes held: (\d+)", worker.output()).group(1))
    # 64 descriptors, a few already open: at most 32 pipes of 64 KiB (2 MiB).
    assert 0 < held <= 32, held


@pytest.mark.parametrize("mode", MODES)
def test_a_worker_that_died_between_calls_is_the_submissions_verdict(mode):
    """The alive/call race: the worker ends after one call's reply and before
    the next call; that call's failure is the submission's, never "the
    grader failed" (WorkerHarnessError)."""
    with Worker(library("pipe_filler"), sandbox=mode) as worker:
        worker.set_faces(faces())
        worker.fetch(np.eye(3))
        os.kill(worker._worker_pid, signal.SIGTERM)
        os.kill(worker._worker_pid, signal.SIGCONT)      # it is stopped between calls
        deadline = time.monotonic() + 10
        while worker.alive and time.monotonic() < deadline:
            time.sleep(0.01)
        assert not worker.alive
        with pytest.raises(SubmissionFailure) as caught:
            worker.fetch(np.eye(3))
    assert caught.value.kind == "exited" and caught.value.signal_name == "SIGTERM", caught.value.message
    assert not isinstance(caught.value, WorkerHarnessError)


def test_a_worker_the_grader_ended_refuses_calls_as_the_graders_own_mistake():
    with Worker(library("pipe_filler"), sandbox=MODES_AVAILABLE[0]) as worker:
        worker.set_faces(faces())
        worker._kill()
        with pytest.raises(WorkerHarnessError):
            worker.fetch(np.eye(3))



@needs_cgroup
@pytest.mark.parametrize("mode", MODES)
def test_an_oom_kill_in_the_grading_cgroup_is_the_submissions_memory_verdict(mode):
    with memory.grading_cgroup(limit_mb=256) as group:
        assert group is not None
        with Worker(library("memory_hog"), sandbox=mode) as worker:
            worker.set_faces(faces())
            assert str(group.path.name) in proc_field(worker._worker_pid, "cgroup")
            with pytest.raises(SubmissionFailure) as caught:
                worker.fetch(np.eye(3), timeout_s=30)
        assert group.oom_kills() >= 1
    failure = caught.value
    assert (failure.kind, failure.detail, failure.signal_name) == ("exited", "memory", "SIGKILL"), failure.message
    assert not failure.grader_limit          # a verdict, not tried again as the machine's doing
    assert not group.path.exists()           # removed with the grading


@needs_cgroup
def test_the_grading_cgroup_holds_the_worker_and_goes_with_the_grading():
    with memory.grading_cgroup() as group:
        with Worker(library("pipe_filler"), sandbox=MODES_AVAILABLE[0]) as worker:
            worker.set_faces(faces())
            procs = group.procs.read_text().split()
            assert str(worker._worker_pid) in procs
    assert not group.path.exists()


def test_the_grader_lowers_its_own_oom_score_where_allowed():
    before = proc_field(os.getpid(), "oom_score_adj").strip()
    try:
        why = memory.protect_grader()
        now = int(proc_field(os.getpid(), "oom_score_adj"))
        if why is None:
            assert now == memory.GRADER_OOM_SCORE_ADJ
        else:
            # Lowering needs CAP_SYS_RESOURCE; the reason says so.
            assert "oom_score_adj" in why and now == int(before)
    finally:
        try:
            Path("/proc/self/oom_score_adj").write_text(before)
        except OSError:
            pass


# ---- whole gradings -------------------------------------------------------------------

def grade_cmd(path: Path, out: Path) -> list[str]:
    return [sys.executable, "-m", "grader", "grade", str(path), "--quick", "--allow-stale", "--out", str(out)]


def mode_env(mode: str, tmp_path: Path) -> dict:
    if mode == "privilege-drop":
        fake = write_failing_bwrap(tmp_path / "fakebin")
        return {**os.environ, "PATH": f"{fake}:{os.environ['PATH']}"}
    return dict(os.environ)


@needs_cgroup
@pytest.mark.slow
@pytest.mark.parametrize("mode", MODES)
def test_the_pipe_filler_beside_a_classmate_in_a_small_container(mode, tmp_path):
    """The issue's container: 285 MiB of memory for the grader and all it
    starts. Two gradings run in it at once; each grader finishes and writes
    its reports, the classmate keeps full marks and the filler gets what its
    own (correct) lookup earns."""
    container = memory._make(285)
    assert container is not None
    try:
        env = mode_env(mode, tmp_path)
        # The grader itself joins, its oom_score_adj untouched, with the
        # issue's 20,000 descriptors (about 1.3 GiB of full pipes without a bound).
        join = 'echo $$ >"$0" && ulimit -n 20000 && exec "$@"'
        runs = {name: subprocess.Popen(["/bin/sh", "-c", join, str(container.procs), *grade_cmd(path, tmp_path / name)],
                                       env=env, cwd=PROJECT_ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                       text=True)
                for name, path in (("filler", RESOURCES / "pipe_filler.cpp"), ("classmate", CORRECT / "idiomatic.cpp"))}
        printed = {name: run.communicate(timeout=600)[0] for name, run in runs.items()}
        codes = {name: run.returncode for name, run in runs.items()}
        oom_kills = container.oom_kills()
    finally:
        container.remove()
    assert codes == {"filler": 0, "classmate": 0}, printed
    results = {name: json.loads((tmp_path / name / "results.json").read_text()) for name in runs}
    for name, result in results.items():
        assert result["extra_data"]["status"] == "graded", (name, printed[name])
        assert result["score"] == sum(t["max_score"] for t in result["tests"]), (name, printed[name])
    assert oom_kills == 0      # bounded before memory ran out: nobody was killed
    if mode == "privilege-drop":
        assert all("separate unprivileged user" in text for text in printed.values()), printed
