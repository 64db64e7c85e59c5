"""Red team (H9): attacks a motivated student tried against the grader after
issue 11's fixes, each with the verdict the grader must give.

tests/submissions/redteam/*.cpp say on line 1 what they do and the verdict.
Attacks that worked before (and the fix):
- warning_flood: a macro repeating `#pragma GCC warning` made the compiler
  print gigabytes, all held in the grader's memory (4.8 GB RSS for 1 GB) and
  written to the build cache, and the submission still scored 100. Now the
  compiler is stopped at 4 MiB of messages (grader/build/__init__.py `_read_capped`).
- ballast: 240 MiB of zeros in .data (a 4 KiB source) made a 240 MiB
  library, stored in the build cache and copied into every worker's folder;
  it scored 100. Now a library over 64 MiB is refused (forbidden-object).
- fast_when_timed: ten times slow, except on the speed check's 256 x 256
  faces (told by their size) where it took the nearest texel, within the 1%
  the timed colours were checked to: 5 / 5. The timing faces are now judged
  as the sweep judges them, through the student's own readTexture called
  live (grader/checks/speed.py, timing-faces-wrong).
- black_on_axes: wrong on 6 of ~127,000 sweep directions scored 30 / 30 on
  a *failed* check (rounding to 0.01 point). Now a failed check never shows
  full points (grader/grading/score.py).
- terminal_escapes: an exception's text reached the terminal summary with
  its ANSI escapes (cursor up, erase line: the score line can be
  overwritten), and right-to-left overrides reached every report. Now
  diagnosis details are clean()ed in the view, and clean() removes bidi
  controls (grader/reports/view.py, text.py).
- grade-all: a submission named summary.html.zip (or gradebook.csv.zip, ...)
  became a folder where the class summary goes, and grade-all stopped with a
  traceback after grading everyone; a name near the 255-byte limit made the
  temporary folder's name too long and the student "ungradable". Now class
  files' names are kept free and temporary names are cut short
  (grader/course/grade_all.py). A file name that is not UTF-8 (a Shift-JIS zip
  unpacked on Linux: no malice needed) stopped grade-all at the gradebook
  (UnicodeEncodeError); names are now made text first.
- asleep_everywhere: correct but asleep 0.3 ms per lookup (no CPU time):
  every large batch timed out and was narrowed down, each call up to the
  runner's 120 s, and one grading ran for more than 11 minutes. Now all the
  lookups of one grading share a wall-clock budget (grader/worker/lookups.py
  BudgetedRunner, GRADING_BUDGET_S); past it a call fails at once.
- starve_other_worker: in privilege-drop mode every worker is uid nobody
  with no pid namespace, so a submission could put another process of that
  uid (another student's worker in grade-all, the speed check's reference)
  into SCHED_IDLE at nice 19 on one CPU, to starve it into timeouts. Now the
  seccomp filter refuses (EPERM) scheduling, priority and page placement of
  any process but the worker itself (grader/worker/seccomp.c on_other_pid).
Attacks the grader already handled, kept as regression tests at the worker:
exit status 73 from a static initialiser, a destructor that never returns,
an interval timer interrupting the worker, SIGSTOP to itself.
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from grader.build import build_submission
from grader.grading.grade import GradeOptions, grade
from grader.envmap.library import CubeMap
from grader.grading.results import FAILED, GRADED, PASSED, UNGRADABLE, CheckResult, GradeResult
from grader.worker import Limits, SubmissionRunner, WorkerHarnessError, sandbox, sandbox_problem
from project_paths import SUBMISSIONS

CAP_BYTES = 4 << 20    # grader.build.messages.MAX_COMPILER_OUTPUT_BYTES
REDTEAM = SUBMISSIONS / "redteam"
SYNTAX_ERROR = SUBMISSIONS / "wrong" / "syntax-error.cpp"
PROBLEM = sandbox_problem()
MODE = "sandbox" if PROBLEM is None else "plain"

FACES = np.random.default_rng(9).random((6, 8, 8, 3), dtype=np.float32)
DIRS = np.array([[0.2, 0.3, -1], [0, 1, 0.1], [-1, 0.2, 0.3], [0.1, -1, 0.5],
                 [0.3, 0.3, 1], [1, 0, 0], [0.5, -0.2, -1], [-0.3, 0.9, 0.1]])
TRIGGER = 5     # DIRS[TRIGGER] is +x, where the hostile acts fire

TESTED = {"warning_flood", "black_on_axes", "terminal_escapes", "exit_as_setup_error", "hang_at_exit",
          "interval_timer", "stop_itself", "asleep_everywhere", "starve_other_worker",
          "ballast", "fast_when_timed"}


def test_every_redteam_submission_has_a_test():
    assert {p.stem for p in REDTEAM.glob("*.cpp")} == TESTED
    for p in REDTEAM.glob("*.cpp"):
        assert p.read_text().startswith("// ") and "Verdict" in p.read_text().splitlines()[0]


# ---- build: compiler messages are capped ------------------------------------------

# slow: several real builds each, in more than one isolation mode (12-16 s)
@pytest.mark.slow
@pytest.mark.sandbox
def test_a_flood_of_warnings_stops_the_compiler_and_is_a_build_error(tmp_path):
    result = build_submission(REDTEAM / "warning_flood.cpp", cache_dir=tmp_path)
    assert not result.ok and result.diagnosis_id == "build-error"
    assert result.log.splitlines()[0].startswith(
        f"The compiler printed more than {CAP_BYTES >> 20} MiB of messages")
    assert len(result.log) < 10_000
    # The cache holds at most the cap, not what the compiler would have printed.
    records = list(tmp_path.glob("*/build.json"))
    assert records and all(r.stat().st_size < CAP_BYTES * 1.5 for r in records)


# slow: several real builds each, in more than one isolation mode (12-16 s)
@pytest.mark.slow
@pytest.mark.sandbox
def test_a_huge_library_is_refused_and_not_cached(tmp_path):
    result = build_submission(REDTEAM / "ballast.cpp", cache_dir=tmp_path)
    assert not result.ok and result.diagnosis_id == "forbidden-object"
    assert "more than 64 MiB" in result.log
    # Our own objects (common-*, with a 28 MB precompiled header) are in the cache whatever was built.
    stored = sum(f.stat().st_size for f in tmp_path.rglob("*")
                 if f.is_file() and not f.relative_to(tmp_path).parts[0].startswith("common-"))
    assert stored < 16 << 20


# ---- score: a failed check never shows full points --------------------------------

def test_a_failed_check_never_rounds_up_to_full_points():
    from grader.grading import score
    rubric = {"checks": {"sweep": {"points": 30, "partial": "fraction"}, "speed": {"points": 5, "partial": "all"},
                         "ok": {"points": 10, "partial": "fraction"}}}
    result = GradeResult("x", checks=[CheckResult("sweep", "S", FAILED, fraction=1 - 6 / 126_662),
                                      CheckResult("speed", "T", FAILED, fraction=1.0),
                                      CheckResult("ok", "O", PASSED, fraction=1.0)])
    score.apply(result, rubric)
    assert [c.score for c in result.checks] == [29.99, 0.0, 10.0]
    assert result.score < result.max_score


@pytest.mark.slow
@pytest.mark.sandbox
def test_black_on_the_axes_is_not_full_marks(tmp_path):
    result = grade(REDTEAM / "black_on_axes.cpp", tmp_path, GradeOptions(allow_stale=True, only=("fetch_sweep",)))
    (sweep,) = result.checks
    assert sweep.status == FAILED and sweep.score < sweep.max_score == 30
    assert "axes" in sweep.output and result.score < result.max_score
    assert json.loads((tmp_path / "results.json").read_text())["score"] < 30


@pytest.mark.slow
@pytest.mark.sandbox
def test_a_cheaper_path_on_the_timing_faces_fails_the_speed_check(tmp_path):
    result = grade(REDTEAM / "fast_when_timed.cpp", tmp_path, GradeOptions(allow_stale=True, quick=True,
                                                                           only=("speed",)))
    (speed,) = result.checks
    assert speed.status == FAILED and speed.score == 0
    assert [d.id for d in speed.diagnoses] == ["timing-faces-wrong"]
    assert speed.metrics["timed_match"] < 0.5


# ---- reports: no escapes or bidi controls from the submission ----------------------

@pytest.mark.slow
@pytest.mark.sandbox
def test_escapes_in_an_exception_reach_no_terminal_and_no_report(tmp_path):
    from grader.reports.terminal import print_summary
    from rich.console import Console
    import io
    result = grade(REDTEAM / "terminal_escapes.cpp", tmp_path,
                   GradeOptions(allow_stale=True, quick=True, only=("fetch_sweep",)))
    assert result.status == GRADED and "exception" in {d.id for d in result.diagnoses}
    assert any("001 / 001 :erocS" in d.detail for d in result.diagnoses)   # the text itself is kept, as data
    screen = io.StringIO()
    print_summary(result, Console(file=screen, force_terminal=True, width=120))
    shown = screen.getvalue()
    assert "001 / 001 :erocS" in shown
    # Rich's own colours are escapes too: none may come from the submission's text.
    assert "\x1b[2A" not in shown and "\x1b[2K" not in shown and "\x1b]0;" not in shown and "\x1b[8m" not in shown
    assert "\u202e" not in shown
    for name in ("report.md", "report.html", "results.json", "junit.xml"):
        text = (tmp_path / name).read_text()
        assert "\x1b" not in text and "\u202e" not in text and "\\u202e" not in text, name


# ---- the worker: tricks that must not blame the grader or hang it ------------------

@pytest.fixture(scope="module")
def libraries() -> dict[str, Path]:
    out = {}
    for name in ("exit_as_setup_error", "hang_at_exit", "interval_timer", "stop_itself", "asleep_everywhere"):
        built = build_submission(REDTEAM / f"{name}.cpp")
        assert built.ok, built.log
        out[name] = built.library
    return out


def runner(library: Path) -> SubmissionRunner:
    return SubmissionRunner(library, FACES, sandbox=MODE, limits=Limits(address_space_mb=1024), timeout_s=1.0)


@pytest.mark.sandbox
def test_exit_status_73_while_loading_is_the_submissions_failure(libraries):
    with runner(libraries["exit_as_setup_error"]) as r:
        try:
            outcome = r.fetch(DIRS)
        except WorkerHarnessError as e:   # the grader's own failure: the attack worked
            pytest.fail(f"blamed on the grader: {e}")
    assert [(f.kind, f.function, f.index) for f in outcome.failures] == [("exited", "loading", None)]
    assert "exit status 73" in outcome.failures[0].message
    assert not outcome.evaluated.any()


@pytest.mark.sandbox
@pytest.mark.parametrize("name", ["hang_at_exit", "interval_timer"])
def test_a_worker_that_hangs_at_exit_or_is_interrupted_gives_correct_values(libraries, name):
    with runner(libraries[name]) as r:
        outcome = r.fetch(DIRS)
        again = r.read_texture(2, np.array([[0.5, 0.5], [1.0, 1.0], [0.0, 0.25]]))
    assert outcome.ok and again.ok, [f.describe() for f in outcome.failures + again.failures]
    np.testing.assert_allclose(outcome.values, CubeMap(FACES).fetch(DIRS), rtol=1e-12, atol=1e-12)


# slow: waits out wall-clock bounds on purpose (7-10 s)
@pytest.mark.slow
@pytest.mark.sandbox
def test_a_worker_that_stops_itself_times_out_at_that_input(libraries):
    with runner(libraries["stop_itself"]) as r:
        outcome = r.fetch(DIRS)
    assert [(f.kind, f.index) for f in outcome.failures] == [("timeout", TRIGGER)]
    keep = [i for i in range(len(DIRS)) if i != TRIGGER]
    assert outcome.evaluated[keep].all()
    np.testing.assert_allclose(outcome.values[keep], CubeMap(FACES).fetch(DIRS)[keep], rtol=1e-12, atol=1e-12)


# slow: waits out wall-clock bounds on purpose (7-10 s)
@pytest.mark.slow
@pytest.mark.sandbox
def test_a_lookup_asleep_everywhere_uses_up_the_gradings_budget_and_stops(libraries):
    from grader.worker.lookups import BudgetedRunner
    # About 1 s asleep (1,000 lookups of 0.3 ms sleeps, which take up to 1 ms in the sandbox; 4,000
    # of them outlasted the bound here, and passed only on the retry): within the wall-clock outer
    # bound (4 x 0.6 s + 1 s, issue 21) with 2.4 s to spare for a loaded machine, using no CPU
    # time; the grading's budget is what stops it.
    dirs = np.random.default_rng(4).normal(size=(1000, 3))
    with BudgetedRunner(libraries["asleep_everywhere"], FACES, sandbox=MODE, timeout_s=0.5, per_input_s=1e-4,
                        max_failures=4, max_timeouts=1, total_budget_s=3.0) as r:
        first = r.fetch(dirs)
        while r.spent_s < r.total_budget_s:   # each call spends at least one time limit
            r.fetch(dirs)
        starts = r.worker_starts
        later = [r.fetch(dirs), r.read_texture(0, np.full((10, 2), 0.5)), r.time_fetch([dirs])]
    assert first.ok
    for outcome in later[:2]:
        assert outcome.gave_up and not outcome.evaluated.any()
        assert [(f.kind, f.index) for f in outcome.failures] == [("timeout", None)]
        assert "used up the 3 s" in outcome.failures[0].message
    assert later[2].failure.kind == "timeout" and not later[2].cpu_ns
    assert r.worker_starts == starts          # nothing more was started


@pytest.mark.sandbox
@pytest.mark.parametrize("mode", ["plain", pytest.param("privilege-drop", marks=pytest.mark.skipif(
    sandbox.privilege_drop_problem() is not None, reason="no privilege drop here"))])
def test_a_worker_cannot_starve_another_worker(mode):
    import os
    from grader.worker import Worker
    attacker = build_submission(REDTEAM / "starve_other_worker.cpp")
    victim = build_submission(sorted((REDTEAM.parent / "correct").glob("*.cpp"))[0])
    assert attacker.ok and victim.ok, attacker.log + victim.log
    with Worker(victim.library, sandbox=mode) as v, Worker(attacker.library, sandbox=mode) as a:
        v.set_faces(FACES)
        a.set_faces(FACES)
        pid = v._worker_pid
        before = (os.sched_getscheduler(pid), os.getpriority(os.PRIO_PROCESS, pid), os.sched_getaffinity(pid))
        np.testing.assert_array_equal(a.fetch([[pid, 0, 12345]]), [[0, 0, 0]])   # it ran, and lived
        after = (os.sched_getscheduler(pid), os.getpriority(os.PRIO_PROCESS, pid), os.sched_getaffinity(pid))
        np.testing.assert_allclose(v.fetch(DIRS), CubeMap(FACES).fetch(DIRS), rtol=1e-12, atol=1e-12)
    assert after == before and before[0] != os.SCHED_IDLE


# ---- grade-all: names a student chooses -------------------------------------------

@pytest.mark.slow
@pytest.mark.sandbox
def test_grade_all_survives_names_of_class_files_and_long_names(tmp_path):
    from grader.course.grade_all import grade_all
    klass = tmp_path / "class"
    klass.mkdir()
    long_name = "b" * 246                               # 250 bytes with .cpp: a legal file name
    for name in ("alice.cpp", "summary.html.cpp", "gradebook.csv.cpp", f"{long_name}.cpp"):
        shutil.copyfile(SYNTAX_ERROR, klass / name)
    import os
    shutil.copyfile(SYNTAX_ERROR, klass / os.fsdecode(b"sj\x83e\x83X\x83g.cpp"))   # Shift-JIS, not UTF-8
    (klass / "summary.json").mkdir()                   # a folder, as an unzipped upload would be
    shutil.copyfile(SYNTAX_ERROR, klass / "summary.json" / "EnvironmentMap.cpp")
    out = tmp_path / "out"
    rows = grade_all(klass, out, 1, {"quick": True, "allow_stale": True}, progress=False)
    assert len(rows) == 6
    assert all(r.status == "build-error" for r in rows), [(r.student[:20], r.status, r.error) for r in rows]
    assert UNGRADABLE not in (out / "gradebook.csv").read_text()
    for name in ("gradebook.csv", "summary.json", "summary.html", "summary.md"):
        assert (out / name).is_file(), name
    # The class's own summary data, not a student's folder in its place.
    assert {"skipped", "roster", "similarity"} <= set(json.loads((out / "summary.json").read_text()))
    assert (out / long_name / "results.json").is_file()
    assert (out / "summary.html_" / "results.json").is_file()
    assert "sj\ufffde\ufffdX\ufffdg" in (out / "gradebook.csv").read_text(encoding="utf-8")
