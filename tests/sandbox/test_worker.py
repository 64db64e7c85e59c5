"""grader/worker: the worker process, its protocol, guard pages, limits and
sandbox, driven by a small stand-in library written in C right here (it
implements grader/build/shim/submission_abi.h directly, so these tests do not depend
on the C++ build) and by the correct C++ solution built by grader/build/__init__.py.

The stand-in's lookups do what (u, v) or the direction tell them to:
readTexture returns addr[int(u)] (so u picks any float offset, in bounds or
not); fetchColor with x = 1 returns texels[int(y)], with x = 2 prints z
bytes, with x = 3 spins, with x = 4 writes garbage to every fd from 3 to 63,
with x = 5 writes into the texture, and otherwise returns (x, y, z).
"""
from __future__ import annotations

import os
import signal
import subprocess
from pathlib import Path

import numpy as np
import pytest

from grader import PROJECT_ROOT
from grader.build import build_submission
from grader.envmap.library import CubeMap
from grader.worker import (SubmissionFailure, SubmissionRunner, Worker, WorkerHarnessError,
                           describe_fetch, describe_read_texture, protocol, sandbox)
from project_paths import SUBMISSIONS

ABI_DIR = PROJECT_ROOT / "grader" / "build" / "shim"
CORRECT = SUBMISSIONS / "correct" / "axis_table.cpp"
SANDBOX_PROBLEM = sandbox.sandbox_problem()
MODES = ["plain", pytest.param("sandbox", marks=pytest.mark.skipif(
    SANDBOX_PROBLEM is not None, reason=f"no sandbox here: {SANDBOX_PROBLEM}"))]

STAND_IN = r"""
#include "submission_abi.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct { const float *texels; int w, h; } map_t;
int sub_abi_version(void) { return SUB_ABI_VERSION; }
void *sub_create(char *m, size_t s) { (void)m; (void)s; return calloc(1, sizeof(map_t)); }
void sub_destroy(void *map) { free(map); }
int sub_set_faces(void *map, const float *t, int w, int h, char *m, size_t s)
{ (void)m; (void)s; map_t *p = map; p->texels = t; p->w = w; p->h = h; return SUB_OK; }
int sub_fetch_batch(void *map, const double *d, size_t n, double *rgb, char *m, size_t s)
{
    map_t *p = map;
    for (size_t i = 0; i < n; i++) {
        double x = d[3*i], y = d[3*i+1], z = d[3*i+2];
        rgb[3*i] = x; rgb[3*i+1] = y; rgb[3*i+2] = z;
        if (x == 1) rgb[3*i] = p->texels[(long)y];
        if (x == 2) { for (long k = 0; k < (long)z; k++) putchar('a' + k % 26); fflush(stdout); }
        if (x == 3) for (volatile int spin = 1; spin;) {}
        if (x == 4) for (int fd = 3; fd < 64; fd++) (void)!write(fd, "garbage!garbage!garbage!garbage!", 32);
        if (x == 5) ((float *)p->texels)[0] = 1;
        if (x == 6) { snprintf(m, s, "thrown for %g", y); return SUB_ERR_EXCEPTION; }
    }
    return SUB_OK;
}
int sub_read_texture_batch(void *map, const float *addr, const double *uv, size_t n, double *rgb,
                           char *m, size_t s)
{
    (void)map; (void)m; (void)s;
    for (size_t i = 0; i < n; i++)
        rgb[3*i] = rgb[3*i+1] = rgb[3*i+2] = addr[(long)uv[2*i]];
    return SUB_OK;
}
int sub_record_fetch_batch(void *map, const double *d, size_t n, const double *t, double *rgb, double *c,
                           struct sub_texture_call *calls, char *m, size_t s)
{ (void)map; (void)d; (void)n; (void)t; (void)rgb; (void)c; (void)calls; (void)m; (void)s; return SUB_ERR_ARGUMENT; }
int sub_load_cross(void *map, const char *path, char *m, size_t s)
{ (void)map; snprintf(m, s, "stand-in: %s", path); return 0; }
"""


@pytest.fixture(scope="module")
def stand_in(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("stand_in")
    (folder / "stand_in.c").write_text(STAND_IN)
    library = folder / "stand_in.so"
    subprocess.run(["cc", "-std=c11", "-O1", "-shared", "-fPIC", f"-I{ABI_DIR}", "-o", str(library),
                    str(folder / "stand_in.c")], check=True)
    return library


@pytest.fixture(scope="module")
def correct_library() -> Path:
    built = build_submission(CORRECT)
    assert built.ok, built.log
    return built.library


def faces(w: int = 8, h: int = 8, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).random((6, h, w, 3), dtype=np.float32)


# ---- the correct solution, both modes -----------------------------------------

def first_fault(worker: Worker, values: np.ndarray) -> SubmissionFailure:
    """The failure of the first input that faulted in the worker's last call,
    which went on past it: that input's row is NaN (issue 19)."""
    from grader.worker.failures import from_crash
    assert worker.faults, "no input faulted"
    index, report = worker.faults[0]
    assert np.isnan(values[index]).all()
    return from_crash(report, "")


@pytest.mark.parametrize("mode", MODES)
def test_correct_solution_matches_reference(correct_library, mode):
    cube = faces(7, 5)
    rng = np.random.default_rng(1)
    dirs = rng.normal(size=(200, 3))
    uv = rng.random((50, 2))
    with Worker(correct_library, sandbox=mode) as worker:
        assert worker.mode == mode and worker.warning is None
        worker.set_faces(cube)
        np.testing.assert_allclose(worker.fetch(dirs), CubeMap(cube).fetch(dirs), rtol=1e-12, atol=1e-12)
        for face in range(6):
            np.testing.assert_allclose(worker.read_texture(face, uv, "start"),
                                       CubeMap(cube).read_texture(np.full(50, face), uv), rtol=1e-12, atol=1e-12)
        assert worker.time_fetch(dirs, repeats=3) > 0


# ---- guard pages ------------------------------------------------------------------

FLOATS_PER_FACE = 8 * 8 * 3


@pytest.mark.parametrize("face", [0, 5])
def test_reading_one_float_past_a_face_is_an_out_of_bounds_read(stand_in, face):
    cube = faces()
    with Worker(stand_in, sandbox="plain") as worker:
        worker.set_faces(cube)
        last = worker.read_texture(face, [[FLOATS_PER_FACE - 1, 0]], "end")
        assert last[0, 0] == cube[face].reshape(-1)[-1]
        failure = first_fault(worker, worker.read_texture(face, [[FLOATS_PER_FACE, 0]], "end"))
        assert worker.alive      # it goes on past a fault (issue 19)
    assert failure.kind == "out-of-bounds-read" and failure.detail == "after"
    assert failure.crash.where == face and failure.crash.distance == 0
    assert "right after the last texel of face " + ("+X", "-Z")[face == 5] in failure.message


def test_reading_before_a_face_placed_at_a_page_start_is_an_out_of_bounds_read(stand_in):
    with Worker(stand_in, sandbox="plain") as worker:
        worker.set_faces(faces())
        assert worker.read_texture(2, [[0, 0]], "start")[0, 0] == faces()[2, 0, 0, 0]
        failure = first_fault(worker, worker.read_texture(2, [[-3, 0]], "start"))
    assert failure.kind == "out-of-bounds-read"
    assert "12 bytes before the first texel of face +Y" in failure.message


def test_fetch_past_the_six_faces_is_an_out_of_bounds_read(stand_in):
    with Worker(stand_in, sandbox="plain") as worker:
        worker.set_faces(faces(), "end")
        inside = worker.fetch([[1, 6 * FLOATS_PER_FACE - 1, 0]])
        assert inside[0, 0] == faces()[5].reshape(-1)[-1]
        failure = first_fault(worker, worker.fetch([[1, 6 * FLOATS_PER_FACE + 2, 0]]))
    assert failure.kind == "out-of-bounds-read"
    assert "8 bytes after the last texel of the six faces' buffer" in failure.message


def test_writing_into_the_texture_is_a_crash(stand_in):
    with Worker(stand_in, sandbox="plain") as worker:
        worker.set_faces(faces())
        failure = first_fault(worker, worker.fetch([[5, 0, 0]]))
    assert failure.kind == "crash" and "read-only" in failure.message


# ---- timeouts, output, protocol, exceptions --------------------------------------------

@pytest.mark.parametrize("mode", MODES)
def test_a_spinning_call_times_out_and_the_worker_is_killed(stand_in, mode):
    worker = Worker(stand_in, sandbox=mode)
    worker.start()
    try:
        worker.set_faces(faces())
        with pytest.raises(SubmissionFailure) as caught:
            worker.fetch([[3, 0, 0]], timeout_s=0.5)
        assert caught.value.kind == "timeout"
        assert not worker.alive
        with pytest.raises(WorkerHarnessError):
            worker.fetch([[0, 0, 0]])
    finally:
        worker.close()


def test_output_is_captured_and_capped_with_head_and_tail(stand_in):
    with Worker(stand_in, sandbox="plain", output_head=100, output_tail=50) as worker:
        worker.set_faces(faces())
        worker.fetch([[2, 0, 1_000_000]])
    text = worker.output()          # complete: close() waited for the end of the output
    assert text.startswith("abcdefghij")
    assert "[... 999850 bytes of output elided ...]" in text
    assert len(text) < 300


def test_garbage_on_the_reply_channel_is_a_protocol_violation(stand_in):
    with Worker(stand_in, sandbox="plain") as worker:
        worker.set_faces(faces())
        with pytest.raises(SubmissionFailure) as caught:
            worker.fetch([[4, 0, 0]])
    assert caught.value.kind == "protocol"


def test_an_exception_is_reported_and_the_worker_survives(stand_in):
    with Worker(stand_in, sandbox="plain") as worker:
        worker.set_faces(faces())
        with pytest.raises(SubmissionFailure) as caught:
            worker.fetch([[6, 2.5, 0]])
        assert caught.value.kind == "exception" and not caught.value.fatal
        assert "thrown for 2.5" in caught.value.message
        np.testing.assert_array_equal(worker.fetch([[7, 8, 9]]), [[7, 8, 9]])


def test_a_library_without_the_entry_points_is_a_load_error(tmp_path):
    source = tmp_path / "empty.c"
    source.write_text("int nothing_here(void) { return 0; }\n")
    library = tmp_path / "empty.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-o", str(library), str(source)], check=True)
    with pytest.raises(SubmissionFailure) as caught:
        Worker(library, sandbox="plain").start()
    assert caught.value.kind == "load-error" and "sub_abi_version" in caught.value.message


def test_load_cross_reaches_the_submission_with_a_path_it_can_read(stand_in, tmp_path):
    hdr = tmp_path / "map.hdr"
    hdr.write_bytes(b"#?RADIANCE\n")
    with Worker(stand_in, sandbox="plain") as worker:
        loaded, message = worker.load_cross(hdr)
    assert not loaded and message.startswith("stand-in: ") and message.endswith("cross.hdr")


# ---- protocol validation ---------------------------------------------------------------

def test_reply_headers_are_validated():
    with pytest.raises(protocol.ProtocolViolation):
        protocol.decode_header(protocol.HEADER.pack(0x12345678, protocol.OK, 1, 24))
    with pytest.raises(protocol.ProtocolViolation):
        protocol.decode_header(protocol.HEADER.pack(protocol.RESPONSE_MAGIC, 99, 1, 24))
    with pytest.raises(protocol.ProtocolViolation):
        protocol.check_reply_size(protocol.OK, 2, 48, expected_count=3, expected_bytes=72)
    with pytest.raises(protocol.ProtocolViolation):
        protocol.check_reply_size(protocol.OK, 3, 80, expected_count=3, expected_bytes=72)
    with pytest.raises(protocol.ProtocolViolation):
        protocol.check_reply_size(protocol.CRASH, 0, 255, None, None)
    protocol.check_reply_size(protocol.OK, 3, 72, expected_count=3, expected_bytes=72)


# ---- sandbox selection ----------------------------------------------------------------

def test_mode_resolution_never_falls_back_silently(stand_in, monkeypatch):
    monkeypatch.setattr(sandbox, "sandbox_problem", lambda: "no user namespaces (test)")
    monkeypatch.setattr(sandbox, "privilege_drop_problem", lambda: "not root (test)")
    with pytest.raises(sandbox.SandboxUnavailable) as refused:
        Worker(stand_in, sandbox="auto")
    assert "no user namespaces (test)" in str(refused.value) and "--unsafe-no-sandbox" in str(refused.value)
    with pytest.raises(sandbox.SandboxUnavailable):
        SubmissionRunner(stand_in, faces())
    worker = Worker(stand_in, sandbox="auto", allow_unsafe=True)
    assert (worker.mode, worker.isolation) == ("plain", "unsafe-none")
    assert worker.warning.startswith("sandbox unavailable: no user namespaces (test); ")
    runner = SubmissionRunner(stand_in, faces(), allow_unsafe=True)
    assert runner.isolation == "unsafe-none" and runner.warnings == [worker.warning]
    with pytest.raises(sandbox.SandboxUnavailable):
        Worker(stand_in, sandbox="sandbox")
    # Root without bubblewrap: privilege-drop, no warning needed.
    monkeypatch.setattr(sandbox, "privilege_drop_problem", lambda: None)
    runner = SubmissionRunner(stand_in, faces())
    assert runner.isolation == "privilege-drop" and runner.warnings == []
    monkeypatch.setattr(sandbox, "sandbox_problem", lambda: None)
    assert SubmissionRunner(stand_in, faces()).isolation == "bubblewrap"
    assert SubmissionRunner(stand_in, faces(), sandbox="no-bwrap").isolation == "privilege-drop"


@pytest.mark.skipif(SANDBOX_PROBLEM is not None, reason=f"no sandbox here: {SANDBOX_PROBLEM}")
def test_the_sandbox_hides_the_project_and_has_no_network():
    cmd = sandbox.bwrap_command(Path("/usr/bin/sh"), PROJECT_ROOT / "grader", [], {})
    cmd[cmd.index("--") + 1:] = ["/usr/bin/sh", "-c",
                                 f"test ! -e {PROJECT_ROOT}/Makefile && test ! -e /etc/passwd && "
                                 "test -e /sandbox/input/__init__.py && "
                                 "test \"$(ls /sys/class/net 2>/dev/null | grep -v '^lo$')\" = '' && "
                                 "test \"$(id -u)\" = 65534"]
    assert subprocess.run(cmd).returncode == 0


# ---- the runner ------------------------------------------------------------------------

def test_runner_narrows_a_crash_to_its_input_and_keeps_the_other_values(stand_in):
    dirs = np.array([[0, 1, 2], [7, 7, 7], [1, 6 * FLOATS_PER_FACE + 10, 0], [8, 8, 8], [9, 9, 9]], float)
    with SubmissionRunner(stand_in, faces(), sandbox="plain", timeout_s=2) as runner:
        outcome = runner.fetch(dirs)
    assert [f.index for f in outcome.failures] == [2]
    assert outcome.failures[0].input == "fetchColor(Vector3(1, 1162, 0))"
    assert outcome.failures[0].kind == "out-of-bounds-read"
    np.testing.assert_array_equal(outcome.evaluated, [True, True, False, True, True])
    np.testing.assert_array_equal(outcome.values[[0, 1, 3, 4]], dirs[[0, 1, 3, 4]])
    assert np.isnan(outcome.values[2]).all()


def test_runner_gives_up_after_the_failure_cap(stand_in):
    dirs = np.array([[6, i, 0] for i in range(10)], float)
    with SubmissionRunner(stand_in, faces(), sandbox="plain", max_failures=3) as runner:
        outcome = runner.fetch(dirs)
    assert [f.index for f in outcome.failures] == [0, 1, 2]
    assert outcome.gave_up and not outcome.evaluated.any()


def test_input_descriptions():
    assert describe_fetch([1.0, 0.0, -0.5]) == "fetchColor(Vector3(1, 0, -0.5))"
    assert describe_read_texture(0, 1.0, 0.5) == "readTexture(face +X, u = 1.0, v = 0.5)"


# ---- timing from outside ---------------------------------------------------------------

@pytest.mark.parametrize("mode", MODES)
def test_the_worker_pid_is_found_from_outside_and_its_cpu_time_read(stand_in, mode):
    import os
    from grader.worker.native import worker_binary
    with Worker(stand_in, sandbox=mode) as worker:
        pid = worker._worker_pid
        assert os.stat(f"/proc/{pid}/exe").st_ino == os.stat(worker_binary()).st_ino
        if mode == "sandbox":
            assert pid != worker._proc.pid      # bubblewrap's child, not bubblewrap
        worker.set_faces(faces())
        rgb, used = worker.fetch_timed(np.tile([[7.0, 8.0, 9.0]], (20000, 1)))
        np.testing.assert_array_equal(rgb[-1], [7, 8, 9])
        assert used > 0


def test_children_are_found_without_the_children_file(monkeypatch):
    import builtins
    from grader.worker import process
    child = subprocess.Popen(["sleep", "5"])
    try:
        real_open = builtins.open

        def no_children(path, *args, **kwargs):
            if str(path).endswith("/children"):
                raise FileNotFoundError(path)
            return real_open(path, *args, **kwargs)

        monkeypatch.setattr(builtins, "open", no_children)
        assert child.pid in process._children(__import__("os").getpid())
    finally:
        child.kill()
        child.wait()


def test_reading_far_before_the_six_faces_placed_at_the_end_is_an_out_of_bounds_read(stand_in):
    # The window fits these faces: 1 page of guard is 4 KiB away at most.
    with Worker(stand_in, sandbox="plain", texture_shape=(8, 8)) as worker:
        worker.set_faces(faces(), "end")
        failure = first_fault(worker, worker.fetch([[1, -2000, 0]]))
    assert failure.kind == "out-of-bounds-read" and failure.detail == "before"
    assert "before the first texel of the six faces' buffer" in failure.message


def test_the_runner_sizes_a_worker_for_each_face_size(stand_in):
    with SubmissionRunner(stand_in, faces(8, 8), sandbox="plain") as runner:
        runner.fetch([[0, 0, 1]])
        first = runner._worker
        assert first.texture_bytes == 8 * 8 * 72
        runner.set_faces(faces(8, 8, seed=1))
        assert runner._worker is first                   # same size: same worker
        runner.set_faces(faces(16, 5))
        outcome = runner.fetch([[1, 6 * 16 * 5 * 3 - 1, 0]])
        assert runner._worker is not first and runner._worker.texture_bytes == 16 * 5 * 72
    assert outcome.ok and outcome.values[0, 0] == faces(16, 5)[5].reshape(-1)[-1]


def test_a_worker_that_cannot_set_up_is_the_graders_problem(stand_in):
    from grader.worker import Limits
    # The windows do not fit the address-space limit: SETUP_ERROR, before any student code.
    with pytest.raises(WorkerHarnessError, match="cannot reserve the texture windows"):
        Worker(stand_in, sandbox="plain", limits=Limits(address_space_mb=64, texture_mb=200),
               texture_shape=(1024, 1024)).start()
    # A worker that exits before its set-up report.
    with pytest.raises(WorkerHarnessError, match="exited during set-up"):
        Worker(stand_in, sandbox="plain", limits=Limits(texture_mb=8192), texture_shape=(8000, 8000)).start()


def test_without_a_grading_cgroup_the_machines_oom_count_is_read_once_per_worker(stand_in, monkeypatch):
    """/proc/vmstat costs each call a tenth of a millisecond of kernel time
    (issue 29's bench): read when the worker starts, not before every call.
    A grading's own cgroup is read before every call (test_resource_bounds)."""
    from grader.worker import memory
    reads = []
    monkeypatch.setattr(memory, "oom_kills_on_machine", lambda: reads.append(1) or 0)
    assert memory.current() is None
    with Worker(stand_in, sandbox="plain") as worker:
        worker.set_faces(faces())
        for _ in range(5):
            worker.fetch([[0.5, 7, 1]])
    assert len(reads) == 1


# ---- prepared workers (Worker.prepare, the runner's spare) --------------------

def _maps_of_tree(top: int) -> str:
    """/proc/PID/maps of `top` and every process below it, joined."""
    from grader.worker.process import _children
    text, todo = "", [top]
    while todo:
        pid = todo.pop()
        try:
            text += Path(f"/proc/{pid}/maps").read_text()
        except OSError:
            pass
        todo += _children(pid)
    return text


@pytest.mark.parametrize("mode", MODES)
def test_a_prepared_worker_loads_nothing_of_the_submission_until_started(stand_in, mode):
    import time
    from grader.worker.process import LIBRARY_NAME
    worker = Worker(stand_in, sandbox=mode, texture_shape=(8, 8))
    try:
        worker.prepare()
        assert worker.prepared and worker.alive
        # Wait until the worker has preloaded the C++ runtime: it is at its gate, just after that.
        deadline = time.monotonic() + 10
        while "libstdc++" not in _maps_of_tree(worker._proc.pid) and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(0.2)
        maps = _maps_of_tree(worker._proc.pid)
        assert "libstdc++" in maps and LIBRARY_NAME not in maps
        worker.size_for((5, 16))
        worker.start()
        assert LIBRARY_NAME in _maps_of_tree(worker._proc.pid)
        assert not worker.prepared and worker.texture_bytes == 5 * 16 * 72
        worker.set_faces(faces(16, 5), "end", timeout_s=5)
        values = worker.fetch([[1, 6 * 16 * 5 * 3 - 1, 0]])      # the last float of the window
        assert values[0, 0] == faces(16, 5)[5].reshape(-1)[-1]
        with pytest.raises(WorkerHarnessError, match="keeps its size"):
            worker.size_for((8, 8))
    finally:
        worker.close()


def test_a_prepared_worker_given_no_whole_size_says_so(stand_in):
    from grader.worker.process import WallBound
    worker = Worker(stand_in, sandbox="plain", texture_shape=(8, 8))
    worker.prepare()
    os.write(worker._gate, b"\x01\x02\x03")     # three bytes of the eight, then the gate's end
    os.close(worker._gate)
    worker._gate = -1
    try:
        with pytest.raises(WorkerHarnessError, match="no face size at the gate"):
            worker._setup(worker._binary, WallBound(5.0))
    finally:
        worker.close()
    assert worker._tmp is None


def test_a_prepared_worker_closed_unstarted_leaves_no_process(stand_in):
    worker = Worker(stand_in, sandbox="plain", texture_shape=(8, 8))
    worker.prepare()
    proc = worker._proc
    worker.close()
    assert proc.poll() is not None and not worker.prepared and worker._tmp is None


def test_a_prepared_worker_that_ended_is_the_graders_problem(stand_in):
    worker = Worker(stand_in, sandbox="plain", texture_shape=(8, 8))
    worker.prepare()
    os.killpg(worker._proc.pid, signal.SIGKILL)
    worker._proc.wait()
    with pytest.raises(WorkerHarnessError, match="exited during set-up"):
        worker.start()
    assert worker._tmp is None


def test_the_runner_starts_its_next_worker_from_a_spare_of_any_size(stand_in):
    with SubmissionRunner(stand_in, faces(8, 8), sandbox="plain") as runner:
        runner.fetch([[0, 0, 1]])
        assert runner._spare is None         # one start so far: it may never start another
        runner.restart()
        runner.fetch([[0, 0, 1]])
        spare = runner._spare
        assert spare is not None and spare.prepared
        runner.set_faces(faces(16, 5))
        outcome = runner.fetch([[1, 6 * 16 * 5 * 3 - 1, 0]])
        assert runner._worker is spare and spare.texture_bytes == 16 * 5 * 72
        assert outcome.ok and outcome.values[0, 0] == faces(16, 5)[5].reshape(-1)[-1]
        # A spare that ended is passed over for a fresh worker.
        os.killpg(runner._spare._proc.pid, signal.SIGKILL)
        runner._spare._proc.wait()
        runner.restart()
        assert runner.fetch([[1, 0, 0]]).ok
        assert runner.worker_starts == 4
    assert runner._spare is None
