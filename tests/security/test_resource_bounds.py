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
import uuid
from pathlib import Path

import numpy as np
import pytest

from grader import PROJECT_ROOT
from grader.build import build_submission
from grader.worker import SubmissionFailure, Worker, WorkerHarnessError, memory, process, sandbox
from fake_bwrap import write_failing_bwrap
from loaded import stretch

pytestmark = [pytest.mark.sandbox]

RESOURCES = PROJECT_ROOT / "tests" / "submissions" / "resources"
CORRECT = PROJECT_ROOT / "tests" / "submissions" / "correct"
BWRAP = sandbox.sandbox_problem()
DROP = sandbox.privilege_drop_problem()
CGROUP = memory.cgroup_problem()
CPU_CGROUP = memory.cgroup_problem("cpu")
MODES = [pytest.param("sandbox", marks=pytest.mark.skipif(BWRAP is not None, reason=f"no bubblewrap: {BWRAP}")),
         pytest.param("privilege-drop", marks=pytest.mark.skipif(DROP is not None, reason=f"no privilege drop: {DROP}"))]
MODES_AVAILABLE = [m for m, problem in (("sandbox", BWRAP), ("privilege-drop", DROP)) if problem is None] or ["plain"]
needs_cgroup = pytest.mark.skipif(CGROUP is not None, reason=f"no memory cgroup here: {CGROUP}")
needs_cpu_cgroup = pytest.mark.skipif(CPU_CGROUP is not None, reason=f"no cpu cgroup here: {CPU_CGROUP}")


def library(name: str) -> Path:
    build = build_submission(RESOURCES / f"{name}.cpp")
    assert build.ok, build.log
    return build.library


def faces() -> np.ndarray:
    return np.random.default_rng(3).random((6, 8, 8, 3), dtype=np.float32)


def proc_field(pid: int, name: str) -> str:
    return Path(f"/proc/{pid}/{name}").read_text()


def calls_until_every_thread_has_run(worker: Worker, calls: int = 20) -> None:
    """`calls` calls, and more until every thread of the worker has run (a
    thread is put at SCHED_IDLE only once it has: Worker._demote_threads),
    then one more, after which the worker has put them there."""
    pid = worker._worker_pid
    for n in range(1000):
        worker.fetch(np.eye(3), timeout_s=30)
        if n >= calls and all(process.thread_run_ns(pid, int(t)) != 0 for t in os.listdir(f"/proc/{pid}/task")):
            break
    worker.fetch(np.eye(3), timeout_s=30)


# ---- one worker ---------------------------------------------------------------------------

@pytest.mark.parametrize("mode", MODES)
def test_the_pipe_filler_holds_a_few_pipes_and_is_the_oom_killers_first_choice(mode):
    with Worker(library("pipe_filler"), sandbox=mode) as worker:
        worker.set_faces(faces())
        assert worker.fetch(np.eye(3)).shape == (3, 3)     # it loaded, and it answers
        pid = worker._worker_pid
        assert proc_field(pid, "oom_score_adj").strip() == "1000"
        assert re.search(r"Max open files\s+64\s+64", proc_field(pid, "limits"))
        assert re.search(r"Max pending signals\s+64\s+64", proc_field(pid, "limits"))   # and POSIX timers
    # What it printed is complete once its worker has ended (Worker.output): read
    # while it ran, the line could still be in the pipe on a loaded machine.
    printed = re.search(r"pipes held: (\d+)", worker.output())
    assert printed, worker.output()
    held = int(printed.group(1))
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


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("name", ["idle_spinner", "self_waking_spinner"])
def test_threads_left_spinning_use_no_cpu_between_calls(mode, name):
    """63 threads spin whenever no call is in flight; the self-waking one
    also sends itself SIGCONT by a timer every millisecond."""
    with Worker(library(name), sandbox=mode) as worker:
        worker.set_faces(faces(), timeout_s=30)       # its threads spin in set_faces: its own call
        worker.fetch(np.eye(3), timeout_s=30)
        time.sleep(0.05)                               # the stop lands asynchronously
        before = worker.cpu_ns()
        time.sleep(0.5)
        used = (worker.cpu_ns() - before) / 1e9
        assert worker.fetch(np.eye(3), timeout_s=30).shape == (3, 3)    # resumed for the next call
    printed = worker.output()       # complete once the worker has ended (Worker.output)
    assert used < 0.05, f"{used:.3f} s of CPU time between calls"
    if name == "self_waking_spinner":
        assert "waker: 0" in printed, printed


@pytest.mark.parametrize("mode", MODES)
def test_threads_it_started_run_in_calls_only_at_the_lowest_priority(mode):
    """Inside its own calls the idle spinner's 63 threads are SCHED_IDLE (the
    main thread, which serves the calls, is not): they run only on CPU
    nothing else wants. They try to leave SCHED_IDLE and cannot."""
    with Worker(library("idle_spinner"), sandbox=mode) as worker:
        worker.set_faces(faces(), timeout_s=30)
        calls_until_every_thread_has_run(worker)    # its threads spin (and try to leave) whenever no lookup runs
        pid = worker._worker_pid
        policies = {int(t): os.sched_getscheduler(int(t)) for t in os.listdir(f"/proc/{pid}/task")}
    printed = worker.output()       # complete once the worker has ended (Worker.output)
    assert policies.pop(pid) == os.SCHED_OTHER
    assert len(policies) == 63 and set(policies.values()) == {os.SCHED_IDLE}, policies
    assert "left SCHED_IDLE" not in printed, printed


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
@needs_cpu_cgroup
def test_the_grading_cgroups_hold_the_worker_and_go_with_the_grading():
    with memory.grading_cgroup() as group:
        cpu = memory.current_cpu()
        with Worker(library("pipe_filler"), sandbox=MODES_AVAILABLE[0]) as worker:
            worker.set_faces(faces())
            assert str(worker._worker_pid) in group.procs.read_text().split()
            assert str(worker._worker_pid) in cpu.procs.read_text().split()
    assert not group.path.exists() and not cpu.path.exists()


IDLE_CGROUP = CPU_CGROUP or (None if memory._own_cgroup("cpu")[1] == 1 else "cgroup v2 keeps a process's threads "
                                                                          "in one domain")


@pytest.mark.skipif(IDLE_CGROUP is not None, reason=f"no idle cpu cgroup for threads here: {IDLE_CGROUP}")
@pytest.mark.parametrize("mode", MODES)
def test_the_threads_it_started_run_in_an_idle_cgroup_beside_the_gradings(mode, monkeypatch):
    """The idle spinner's 63 threads, once at SCHED_IDLE and once they have
    run, move to a cpu cgroup beside the grading's that runs only on a core
    nothing else wants (cpu.idle 1): SCHED_IDLE alone weighs a thread only
    against its own cgroup, where they had the grading's whole share against
    a classmate whenever the main thread was not running. The main thread
    stays. A thread that has not run yet stays too (here the kernel is made
    to say so at first): in the idle cgroup on a loaded machine it might
    never run, and what it starts with never happen."""
    def tasks(group):
        return {int(t) for t in (group.path / "tasks").read_text().split()}

    with memory.grading_cgroup():
        cpu, idle = memory.current_cpu(), memory.idle_cgroup()
        monkeypatch.setattr(process, "thread_run_ns", lambda pid, tid: 0)
        with Worker(library("idle_spinner"), sandbox=mode) as worker:
            worker.set_faces(faces(), timeout_s=30)
            worker.fetch(np.eye(3), timeout_s=30)
            not_yet_run = tasks(idle)
            monkeypatch.undo()
            calls_until_every_thread_has_run(worker)
            pid = worker._worker_pid
            threads = {int(t) for t in os.listdir(f"/proc/{pid}/task")}
            in_idle, in_cpu = tasks(idle), tasks(cpu)
            weight = ((idle.path / "cpu.idle").read_text().strip() if (idle.path / "cpu.idle").exists()
                      else (idle.path / "cpu.shares").read_text().strip())
    assert idle.path.parent == cpu.path.parent and weight in ("1", "2")
    assert not_yet_run == set()
    assert in_cpu & threads == {pid}
    assert in_idle == threads - {pid} and len(in_idle) == 63
    assert not idle.path.exists()           # removed with the grading


@needs_cgroup
@pytest.mark.parametrize("isolation", [
    pytest.param("bubblewrap", marks=pytest.mark.skipif(BWRAP is not None, reason=f"no bubblewrap: {BWRAP}")),
    pytest.param("privilege-drop", marks=pytest.mark.skipif(DROP is not None, reason=f"no privilege drop: {DROP}")),
    "none"])
def test_every_compiler_step_is_charged_to_the_grading(isolation, tmp_path):
    import threading
    from grader.build import Deadline, run_compiler
    tmp_path.chmod(0o777)          # the scratch folder of the build uid too (privilege-drop)
    with memory.grading_cgroup() as group:
        cpu, seen, done = memory.current_cpu(), set(), threading.Event()

        def watch():        # from outside: under bubblewrap the step's own /proc/self/cgroup says "/"
            while not done.is_set():
                seen.update(cpu.procs.read_text().split() if cpu else [])
                time.sleep(0.01)
        watcher = threading.Thread(target=watch)
        watcher.start()
        try:
            step = run_compiler(["/bin/sh", "-c", "cat /proc/self/oom_score_adj; ulimit -n; sleep 0.3"], tmp_path,
                        Deadline.of(20), isolation)
        finally:
            done.set()
            watcher.join()
        charged = group.peak_bytes()
    assert step.output.split() == ["1000", "256"], step.output
    assert charged and charged > 0, "nothing ran in the grading's memory cgroup"
    if CPU_CGROUP is None:
        assert seen, "nothing ran in the grading's cpu cgroup"


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


# ---- a class ----------------------------------------------------------------------------

def grade_all_cmd(folder: Path, out: Path) -> list[str]:
    return [sys.executable, "-m", "grader", "grade-all", str(folder), "--out", str(out), "--jobs", "2", "--quick",
            "--no-progress"]


@pytest.mark.slow
@pytest.mark.wallclock      # make test-load, not CI's test-all: a wall-clock ratio
@pytest.mark.parametrize("mode", MODES)
def test_the_idle_spinner_costs_its_classmates_neither_marks_nor_time(mode, tmp_path):
    """63 threads that spin whenever no call is in flight, beside four correct
    classmates in grade-all --jobs 2: their scores stay full and the class
    takes at most 1.5x the control's time (a class of five correct ones).
    Builds are cached first, so both classes time gradings only."""
    classmates = sorted(CORRECT.glob("*.cpp"))[:4]
    control_fifth = sorted(CORRECT.glob("*.cpp"))[4]
    for source in [*classmates, control_fifth, RESOURCES / "idle_spinner.cpp"]:
        assert build_submission(source).ok
    env = mode_env(mode, tmp_path)
    # Timed twice at most: a wall-clock ratio on a shared machine can be
    # thrown by another user's burst; the spinner's own cost shows in both.
    for attempt in (1, 2):
        seconds, rows = {}, {}
        for name, fifth in (("control", control_fifth), ("spinner", RESOURCES / "idle_spinner.cpp")):
            folder = tmp_path / f"{name}-{attempt}"
            folder.mkdir()
            for i, source in enumerate(classmates):
                (folder / f"classmate{i}.cpp").write_bytes(source.read_bytes())
            (folder / "fifth.cpp").write_bytes(fifth.read_bytes())
            out = tmp_path / f"{name}-{attempt}-out"
            began = time.monotonic()
            # Under make test-load every process here gets about 1/31 of a
            # core: the harness's own timeout stretches with it (loaded.stretch).
            run = subprocess.run(grade_all_cmd(folder, out), env=env, cwd=PROJECT_ROOT,
                                 capture_output=True, text=True, timeout=900 * stretch())
            seconds[name] = time.monotonic() - began
            assert run.returncode == 0, run.stdout + run.stderr
            with open(out / "gradebook.csv") as f:
                import csv
                rows[name] = {r["student"]: r for r in csv.DictReader(f)}
        for i in range(4):
            row = rows["spinner"][f"classmate{i}"]
            assert row["status"] == "graded" and float(row["score"]) == float(row["max_score"]) > 0, row
        assert rows["spinner"]["fifth"]["status"] != "ungradable", rows["spinner"]["fifth"]
        print(f"class seconds ({mode}, attempt {attempt}): {seconds}")
        if seconds["spinner"] <= 1.5 * seconds["control"]:
            break
    assert seconds["spinner"] <= 1.5 * seconds["control"], seconds


def grading_whose_first_build_times_out(student, submission, out, key, options):
    """grade-all's grading of one student (in its grading processes): tim's
    first build gets 1 ms of CPU time, so it really times out; any later
    grading builds normally. Every attempt is logged beside the results."""
    import functools

    import grader.build
    from grader.course.grade_all import _grade_one
    log = Path(out).parent / f"attempts-{student}.log"
    first = not log.exists()
    with open(log, "a") as f:
        f.write(f"{os.getpid()}\n")
    if student == "tim" and first:
        grader.build.build_submission = functools.partial(grader.build.build_submission, timeout_s=0.001)
    return _grade_one(student, submission, out, key, options)


@pytest.mark.slow
def test_a_build_that_timed_out_is_graded_again_on_resume(tmp_path):
    from grader.course.grade_all import grade_all
    klass, out = tmp_path / "class", tmp_path / "out"
    klass.mkdir()
    (klass / "alice.cpp").write_bytes((CORRECT / "if_chain.cpp").read_bytes())
    # A source no earlier run has built: a cached build would not time out.
    (klass / "tim.cpp").write_bytes((CORRECT / "if_chain.cpp").read_bytes() + f"// {uuid.uuid4()}\n".encode())
    options = {"quick": True, "only": ["fetch_sweep"]}
    first = {r.student: r for r in grade_all(klass, out, 2, options, progress=False,
                                             grade_one=grading_whose_first_build_times_out)}
    assert first["tim"].status == "build-error", first["tim"]
    assert "stopped" in (out / "tim" / "report.md").read_text()     # "The build took longer than ... stopped"
    assert first["alice"].status == "graded" and first["alice"].score == first["alice"].max_score > 0
    second = {r.student: r for r in grade_all(klass, out, 2, options, progress=False,
                                              grade_one=grading_whose_first_build_times_out)}
    assert second["tim"].status == "graded" and second["tim"].score == second["tim"].max_score > 0, second["tim"]
    assert second["alice"].skipped
    assert len((out / "attempts-tim.log").read_text().split()) == 2
    assert len((out / "attempts-alice.log").read_text().split()) == 1
