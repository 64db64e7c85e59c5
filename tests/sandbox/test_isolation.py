"""Isolation modes on a host where bubblewrap fails (a fake failing `bwrap`
first on PATH), issue 11: as root the worker runs in privilege-drop mode
(chroot into a folder holding only the submission, uid/gid nobody, then
seccomp), grades a correct submission, and a submission that reads the
grader's environment, writes the grader's tree or stops the grader gets a
verdict and changes nothing; as a non-root user the grader refuses unless
--unsafe-no-sandbox.

The grader side of the attacks runs in a child Python process started with
GRADER_SECRET in its environment: that child is the "parent" the submission
reads and signals, so a successful SIGSTOP hangs the child (caught by a
timeout), never pytest itself.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from grader import PROJECT_ROOT
from grader.build import build_submission
from grader.envmap.library import CubeMap
from grader.worker import sandbox
from grader.worker.lookups import open_lookups
from project_paths import SUBMISSIONS

pytestmark = [pytest.mark.slow, pytest.mark.sandbox]   # whole gradings / workers (tests/conftest.py's markers)

ABI_DIR = PROJECT_ROOT / "grader" / "build" / "shim"
CORRECT = SUBMISSIONS / "correct" / "axis_table.cpp"
PYTHON = sys.executable
root_only = pytest.mark.skipif(os.geteuid() != 0, reason="privilege-drop mode needs root")
FAKE_BWRAP = "#!/bin/sh\necho 'bwrap: setting up uid map: Permission denied' >&2\nexit 1\n"
SECRET = "hunter2-course-secret"

INTRUDER = r"""
#define _GNU_SOURCE
#include "submission_abi.h"
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int readable(const char *path, const char *needle)
{
    char buf[65536];
    int fd = open(path, O_RDONLY);
    if (fd < 0) return 0;
    ssize_t n = read(fd, buf, sizeof buf - 1);
    close(fd);
    if (n <= 0) return 0;
    buf[n] = 0;
    for (ssize_t i = 0; i < n; i++) if (!buf[i]) buf[i] = '\n';
    return needle ? strstr(buf, needle) != NULL : 1;
}

int sub_abi_version(void) { return SUB_ABI_VERSION; }
void *sub_create(char *m, size_t s) { (void)m; (void)s; return calloc(1, 8); }
void sub_destroy(void *map) { free(map); }
int sub_set_faces(void *map, const float *t, int w, int h, char *m, size_t s)
{ (void)map; (void)t; (void)w; (void)h; (void)m; (void)s; return SUB_OK; }
int sub_fetch_batch(void *map, const double *d, size_t n, double *rgb, char *m, size_t s)
{
    (void)map; (void)m; (void)s;
    for (size_t i = 0; i < n; i++) {
        int x = (int)d[3*i];
        rgb[3*i] = rgb[3*i+1] = rgb[3*i+2] = 0.25;
        if (x == 1) {
            char path[64];
            snprintf(path, sizeof path, "/proc/%d/environ", (int)getppid());
            if (readable(path, "GRADER_SECRET")) printf("LEAK parent environment\n");
            if (readable(TREE_FILE, NULL)) printf("LEAK grader tree\n");
            if (readable("/etc/passwd", NULL)) printf("LEAK /etc/passwd\n");
        }
        if (x == 2) {
            int fd = open(TREE_FILE, O_WRONLY | O_TRUNC);
            if (fd >= 0) { (void)!write(fd, "pwned", 5); close(fd); printf("WROTE\n"); }
            else printf("could not write\n");
        }
        if (x == 3) { if (kill(getppid(), SIGSTOP) != 0) printf("could not stop the grader\n"); }
        if (x == 4) { if (kill(getppid(), SIGKILL) != 0) printf("could not kill the grader\n"); }
    }
    return SUB_OK;
}
int sub_read_texture_batch(void *map, const float *a, const double *uv, size_t n, double *rgb, char *m, size_t s)
{ (void)map; (void)a; (void)uv; (void)m; (void)s; for (size_t i = 0; i < 3 * n; i++) rgb[i] = 0; return SUB_OK; }
int sub_record_fetch_batch(void *map, const double *d, size_t n, const double *t, double *rgb, double *c,
                           struct sub_texture_call *calls, char *m, size_t s)
{ (void)map; (void)d; (void)n; (void)t; (void)rgb; (void)c; (void)calls; (void)m; (void)s; return SUB_ERR_ARGUMENT; }
int sub_load_cross(void *map, const char *p, char *m, size_t s) { (void)map; (void)p; (void)m; (void)s; return 0; }
"""

# The grader's side, in a child process: one lookup with x = argv[3].
DRIVER = textwrap.dedent("""
    import json, sys
    sys.path.insert(0, sys.argv[1])
    from grader.worker import Limits, SubmissionFailure, Worker
    library, mode, x, seccomp = sys.argv[2], sys.argv[3], float(sys.argv[4]), sys.argv[5] == "1"
    with Worker(library, sandbox=mode, limits=Limits(seccomp=seccomp)) as worker:
        worker.set_faces(__import__("numpy").zeros((6, 2, 2, 3), "float32"))
        try:
            values = worker.fetch([[x, 0, 0]]).tolist()
            verdict = None
        except SubmissionFailure as failure:
            values, verdict = None, [failure.kind, failure.detail, failure.message]
    print(json.dumps({"values": values, "verdict": verdict, "output": worker.output(),
                      "isolation": worker.isolation}))
""")


@pytest.fixture
def no_bwrap(monkeypatch):
    """A bwrap that fails the way it does without user namespaces (in a folder
    nobody can reach too: pytest's tmp_path is private to root)."""
    import shutil
    import tempfile
    folder = Path(tempfile.mkdtemp(prefix="fake-bin-"))
    folder.chmod(0o755)
    (folder / "bwrap").write_text(FAKE_BWRAP)
    (folder / "bwrap").chmod(0o755)
    monkeypatch.setenv("PATH", f"{folder}:{os.environ['PATH']}")
    sandbox.sandbox_problem.cache_clear()
    sandbox.privilege_drop_problem.cache_clear()
    yield folder
    sandbox.sandbox_problem.cache_clear()
    sandbox.privilege_drop_problem.cache_clear()
    shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(scope="module")
def tree(tmp_path_factory) -> Path:
    """A stand-in for a file of the grader's tree (a copy, never the real one)."""
    folder = tmp_path_factory.mktemp("grader-tree")
    module = folder / "grade.py"
    module.write_text("SCORE = compute()\n")
    module.chmod(0o644)
    return module


@pytest.fixture(scope="module")
def intruder(tmp_path_factory, tree) -> Path:
    folder = tmp_path_factory.mktemp("intruder")
    (folder / "intruder.c").write_text(INTRUDER)
    library = folder / "intruder.so"
    subprocess.run(["cc", "-std=c11", "-O1", "-shared", "-fPIC", f"-I{ABI_DIR}", f'-DTREE_FILE="{tree}"',
                    "-o", str(library), str(folder / "intruder.c")], check=True)
    return library


def attack(library: Path, x: int, mode: str, seccomp: bool = True) -> dict:
    env = {**os.environ, "GRADER_SECRET": SECRET}
    done = subprocess.run([PYTHON, "-c", DRIVER, str(PROJECT_ROOT), str(library), mode, str(x), "1" if seccomp else "0"],
                          env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


# ---- root without bubblewrap: privilege-drop ------------------------------------

@root_only
def test_root_without_bubblewrap_grades_in_privilege_drop_mode(no_bwrap):
    assert sandbox.sandbox_problem().startswith("bwrap failed: bwrap: setting up uid map")
    built = build_submission(CORRECT)
    assert built.ok, built.log
    faces = np.random.default_rng(5).random((6, 9, 7, 3), dtype=np.float32)
    dirs = np.random.default_rng(6).normal(size=(500, 3))
    with open_lookups(built.library) as lookups:
        assert lookups.isolation == "privilege-drop" and lookups.warnings == []
        lookups.set_faces(faces)
        outcome = lookups.fetch(dirs)
        texels = lookups.read_texture(2, np.random.default_rng(7).random((50, 2)), "start")
    assert outcome.ok and texels.ok
    np.testing.assert_allclose(outcome.values, CubeMap(faces).fetch(dirs), rtol=1e-12, atol=1e-12)


@root_only
def test_the_grade_command_says_privilege_drop_in_the_results(no_bwrap, tmp_path):
    out = tmp_path / "out"
    done = subprocess.run([PYTHON, "-m", "grader", "grade", str(CORRECT), "--quick", "--allow-stale", "--out", str(out)],
                          cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    results = json.loads((out / "results.json").read_text())
    assert results["score"] == results.get("max_score", 100.0)
    assert "privilege-drop" in json.dumps(results)
    assert "sandbox unavailable" not in json.dumps(results)


@root_only
@pytest.mark.parametrize("seccomp", [True, False], ids=["seccomp", "privileges-alone"])
def test_reading_the_grader_secret_or_tree_finds_nothing(no_bwrap, intruder, seccomp):
    seen = attack(intruder, 1, "privilege-drop", seccomp)
    assert seen["isolation"] == "privilege-drop" and seen["verdict"] is None
    assert seen["values"] == [[0.25, 0.25, 0.25]]
    assert "LEAK" not in seen["output"]


@root_only
def test_the_leak_probe_does_find_the_secret_without_isolation(no_bwrap, intruder):
    # The same probe, unsafe mode: the test above can fail.
    seen = attack(intruder, 1, "plain")
    assert "LEAK parent environment" in seen["output"] and "LEAK grader tree" in seen["output"]


@root_only
@pytest.mark.parametrize("seccomp", [True, False], ids=["seccomp", "privileges-alone"])
def test_writing_the_grader_tree_changes_nothing(no_bwrap, intruder, tree, seccomp):
    before = tree.read_bytes()
    seen = attack(intruder, 2, "privilege-drop", seccomp)
    assert tree.read_bytes() == before
    if seccomp:
        assert seen["verdict"][:2] == ["forbidden-syscall", "openat"]
        assert f"tried to open '{tree}' for writing" in seen["verdict"][2]
    else:
        assert "could not write" in seen["output"] and "WROTE" not in seen["output"]


@root_only
@pytest.mark.parametrize("x", [3, 4], ids=["SIGSTOP", "SIGKILL"])
@pytest.mark.parametrize("seccomp", [True, False], ids=["seccomp", "privileges-alone"])
def test_signalling_the_grader_changes_nothing(no_bwrap, intruder, x, seccomp):
    seen = attack(intruder, x, "privilege-drop", seccomp)   # a stopped or killed grader fails here
    if seccomp:
        assert seen["verdict"][:2] == ["forbidden-syscall", "kill"]
    else:
        assert seen["verdict"] is None and "could not" in seen["output"]


# ---- not root, no bubblewrap: refuse unless told ----------------------------------

NOBODY = ["setpriv", "--reuid", "65534", "--regid", "65534", "--clear-groups"]


@root_only
def test_without_root_or_bubblewrap_the_grader_refuses(no_bwrap, tmp_path, nobody_project):
    out = no_bwrap / "out"
    correct = nobody_project.root / "tests" / "submissions" / "correct" / CORRECT.name   # (a copy in a 0700 checkout)
    done = subprocess.run([*NOBODY, nobody_project.python, "-m", "grader", "grade", str(correct), "--quick",
                           "--out", str(out)], cwd=nobody_project.root, capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"})
    assert done.returncode == 3, done.stderr
    assert "No isolation is possible" in done.stderr and "--unsafe-no-sandbox" in done.stderr
    assert "Traceback" not in done.stderr
    assert not out.exists()


@root_only
def test_without_root_or_bubblewrap_unsafe_must_be_asked_for(no_bwrap, nobody_project):
    script = textwrap.dedent("""
        import sys
        sys.path.insert(0, sys.argv[1])
        from grader.worker.sandbox import SandboxUnavailable, resolve_mode
        try:
            resolve_mode("auto")
            print("ran")
        except SandboxUnavailable:
            print("refused")
        mode, warning = resolve_mode("auto", allow_unsafe=True)
        print(mode, warning)
    """)
    done = subprocess.run([*NOBODY, nobody_project.python, "-c", script, str(nobody_project.root)],
                          capture_output=True, text=True,
                          timeout=60, env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"})
    assert done.returncode == 0, done.stderr
    first, second = done.stdout.splitlines()
    assert first == "refused"
    assert second.startswith("plain sandbox unavailable: bwrap failed") and "unsafe-none" in second
