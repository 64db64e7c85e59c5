"""Grade a class: every submission in a folder, in parallel, resumable.

Each student's reports are graded into a temporary folder and renamed into
OUT/<student>/ when complete, with a record (.grade.json) that holds the key
they were graded under: the submission's content hash, the grader's own
(code, rubric, fixtures, maps, our C and C++ sources), the options and the
course secret. Re-run after an interruption, a student whose key is
unchanged is skipped, unless their status says another process may have
disturbed the grading (DISTURBED: timeout, ungradable). A timeout the
worker saw to be the code's own (its CPU-time limit used up: no other
process can spend it) is kept, and the summary says why (own_timeout). A grading process
that dies (killed, out of memory, unable to start a thread) breaks the
process pool and every grading in it: the pool is rebuilt for those not yet
started, and those that were being graded are graded again, each alone in a
process of its own; one that fails alone too is ungradable, with the reason. The gradebook (gradebook.csv) and the class summary
(summary.md, summary.html and their charts) are rebuilt from what is on
disk, so they are always complete.

Entries of the class folder that are not submissions (hidden files, notes,
the results folder) are skipped and listed with the reason in the summary
data (OUT/summary.json, "skipped"). An entry that looks like an archive or
a source file in any format is graded, so that a .rar gets its own
verdict ("unknown-format") instead of vanishing. With a roster (--roster
CSV, grader/course/roster.py) the gradebook gains student_id, name and email
columns and a row for every student who handed nothing in.
"""
from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import shutil
import tempfile
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from .. import PROJECT_ROOT
from ..grading.results import TIMEOUT, UNGRADABLE
from ..i18n import N_
from ..intake import SUFFIXES, student_name  # noqa: F401  (grade-all's names, re-exported)
from .class_files import MISSING, SKIP_REASONS, cell, write_text_atomic
from .lms_csv import FILES as LMS_FILES

# grade() imports this module for student_name: what only a class needs
# (process pools, the class summary's report code) is imported where used.

RECORD_FILE = ".grade.json"
SUMMARY_DATA = "summary.json"
# What grade-all writes beside the students' folders in OUT (lower case).
CLASS_FILES = ("gradebook.csv", SUMMARY_DATA, "summary.md", "summary.html", "summary_histogram.png",
               "summary_speed_accuracy.png", *LMS_FILES)
# Temporary folders are named after the student, cut short: a student name
# near the 255-byte limit made mkdtemp fail ("ungradable", the grader blamed).
TMP_NAME_CHARS = 40
# What goes into the grader's key: everything that can change a grade. The
# template contributes only the files the build uses (a student's local
# build/ in it must not force a regrade of the class).
KEY_ROOTS = ("grader", "reference/include", "reference/src", "fixtures", "Cubemap", "scenes")
KEY_FILES = ("envmap_test.cfg", "student_template/EnvironmentMapLoader.cpp")   # fixtures/ holds study.csv
# Statuses another process may have caused (a classmate's worker that
# signalled or starved this one, a grading process killed, a harness error):
# a resumed run grades them again instead of keeping them as final.
DISTURBED = (TIMEOUT, UNGRADABLE)
# In English in summary.json; the class page shows it translated.
OWN_TIMEOUT_WHY = N_("the code used up its CPU-time limit on a call (or stopped itself), which no other process "
                     "can cause: kept as it is when grade-all runs again")
# Metrics the class summary charts, copied from the checks into the record.
CHART_METRICS = ("ns_per_lookup", "uniform_smooth_rms", "speed_ratio", "flip_mean", "ssim")


def _skip_reason(p: Path, exclude: Path | None) -> dict[str, str]:
    """Why an entry of the class folder is not a submission: its key in
    SKIP_REASONS ("why") and the values its sentence names; {} when it is one."""
    if exclude is not None and p.resolve() == Path(exclude).resolve():
        return {"why": "results-folder"}
    if p.name.startswith("."):
        return {"why": "hidden"}
    if p.is_symlink():
        return {"why": "link"}
    if p.is_dir() or p.name.lower().endswith(SUFFIXES):
        return {}
    if not p.is_file():
        return {"why": "special"}
    return {"why": "file", "suffix": p.suffix} if p.suffix else {"why": "no-extension"}


def skipped_entries(folder: Path, exclude: Path | None = None) -> list[dict[str, str]]:
    """[{"entry": name, "reason": why in English, "why": its key, ...}] for
    every entry find_submissions leaves out."""
    out = []
    for p in sorted(Path(folder).iterdir()):
        reason = _skip_reason(p, exclude)
        if reason:
            out.append({"entry": p.name, "reason": SKIP_REASONS.msgid(reason["why"]) % reason, **reason})
    return out


def find_submissions(folder: Path, exclude: Path | None = None) -> dict[str, Path]:
    """{student: path}: one sub-folder, archive or source per student, by name.
    Two entries with the same student name (alice/ and alice.zip) keep
    their full file names, so neither hides the other. `exclude` is the
    results folder, when it sits among the submissions. skipped_entries
    says why the rest was left out."""
    found = [p for p in sorted(Path(folder).iterdir()) if not _skip_reason(p, exclude)]
    counts = Counter(student_name(p) for p in found)
    out = {}
    for p in found:
        name = student_name(p) if counts[student_name(p)] == 1 else p.name
        # A name that is not UTF-8 (a Shift-JIS zip unpacked here) as text:
        # its undecodable bytes stopped grade-all at the gradebook.
        name = name.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
        # A student's folder in OUT must not take the place of a class file
        # (a "summary.html.zip" made summary.html a folder and stopped the run).
        while name.lower() in CLASS_FILES or name in out:
            name += "_"
        out[name] = p
    return out


def _hash_tree(path: Path) -> str:
    # Links and special files are never followed or read (one link to
    # /proc/self/mem in one folder stopped the whole class); bounded in files.
    from ..intake import hash_submission
    return hash_submission(path)


def grader_key(options: dict) -> str:
    """Changes whenever the grading could change: grader code, rubric,
    fixtures, maps, reference, the template files the build uses, the
    options and the course secret."""
    h = hashlib.sha256()
    paths = [PROJECT_ROOT / f for f in KEY_FILES] + sorted((PROJECT_ROOT / "student_template").glob("*.h"))
    for root in KEY_ROOTS:
        paths += sorted(p for p in (PROJECT_ROOT / root).rglob("*") if p.is_file() and "__pycache__" not in p.parts)
    for f in paths:
        if f.is_file():
            h.update(f.relative_to(PROJECT_ROOT).as_posix().encode() + b"\0")
            h.update(hashlib.sha256(f.read_bytes()).digest())
    h.update(json.dumps(options, sort_keys=True).encode())
    # The secret changes the random directions: a hash of it, never the secret itself.
    h.update(hashlib.sha256(os.environ.get("GRADER_SECRET", "").encode()).digest())
    return h.hexdigest()


@dataclass
class Row:
    """One line of the gradebook."""
    student: str
    status: str
    score: float
    max_score: float
    checks: dict[str, float] = field(default_factory=dict)   # rubric name -> points
    diagnoses: list[str] = field(default_factory=list)       # ids, sorted
    metrics: dict[str, float] = field(default_factory=dict)  # CHART_METRICS found
    seconds: float = 0.0
    skipped: bool = False                                    # unchanged since the last run
    error: str = ""                                          # the harness's failure, when ungradable
    student_id: str = ""                                     # from the roster (--roster)
    name: str = ""
    email: str = ""
    first_diagnosis: str = ""                                # the id the report names first (its cause)


def _chart_metrics(result) -> dict[str, float]:
    out = {}
    for check in result.checks:
        for name in CHART_METRICS:
            if name in check.metrics and name not in out:
                out[name] = float(check.metrics[name])
    return out


def _grade_one(student: str, submission: str, out: str, key: str, options: dict) -> Row:
    """Runs in a pool process: grade into a fresh folder, then put it in place.

    The record is written inside the new folder before it is renamed, so a
    folder with a record is always complete; an interruption leaves at most
    a .tmp- folder, which the next run removes."""
    from ..grading.grade import GradeOptions, grade
    final = Path(out)
    work = Path(tempfile.mkdtemp(prefix=f".tmp-{student[:TMP_NAME_CHARS]}-", dir=final.parent))
    try:
        result = grade(Path(submission), work, GradeOptions(**options))
        record = {"key": key, "metrics": _chart_metrics(result), "build_timed_out": result.build_timed_out,
                  "check_seconds": {c.name: round(c.duration_s, 3) for c in result.checks},
                  # what stopped each timeout ("code" or "grader"), as the worker saw it (own_timeout)
                  "timeouts": [d.stopped_by for d in result.diagnoses if d.id == TIMEOUT]}
        (work / RECORD_FILE).write_text(json.dumps(record, indent=1, sort_keys=True) + "\n")
        work.chmod(0o755)
        _replace_dir(work, final)
    except BaseException:
        shutil.rmtree(work, ignore_errors=True)
        raise
    return read_row(student, final)


def _replace_dir(new: Path, final: Path) -> None:
    old = None
    if final.exists():
        old = Path(tempfile.mkdtemp(prefix=f".old-{final.name[:TMP_NAME_CHARS]}-", dir=final.parent))
        os.replace(final, old / final.name)
    os.replace(new, final)
    if old:
        shutil.rmtree(old, ignore_errors=True)


def read_record(out_dir: Path) -> dict | None:
    try:
        return json.loads((out_dir / RECORD_FILE).read_text())
    except (OSError, ValueError):
        return None


def read_row(student: str, out_dir: Path) -> Row:
    """A gradebook row from a student's results.json (Gradescope's format,
    grader/reports/gradescope_json.py) and the record beside it."""
    data = json.loads((out_dir / "results.json").read_text())
    extra = data.get("extra_data", {})
    tests = data.get("tests", [])
    checks = {t.get("extra_data", {}).get("check", t["name"]): float(t.get("score", 0.0)) for t in tests}
    record = read_record(out_dir) or {}
    found = [d["id"] for d in extra.get("diagnoses", [])]
    return Row(student, extra.get("status", "graded"), float(data.get("score", 0.0)),
               float(extra.get("max_score", sum(t.get("max_score", 0) for t in tests))),
               checks, sorted(set(found)), dict(record.get("metrics", {})), float(data.get("execution_time", 0.0)),
               first_diagnosis=found[0] if found else "")


def own_timeout(row: Row, record: dict | None) -> bool:
    """A timeout that is the code's own: every one the grading met stopped
    by the code's CPU-time limit, which no other process can use up. Kept
    on a resumed run; any timeout stopped only by a wall-clock bound (which a
    busy machine reaches too), or one an older grader did not record, is
    graded again."""
    stops = (record or {}).get("timeouts") or []
    return row.status == TIMEOUT and bool(stops) and all(s == "code" for s in stops)


def _clean_leftovers(out: Path) -> None:
    """Folders an interrupted run left half-written."""
    for p in out.glob(".tmp-*"):
        shutil.rmtree(p, ignore_errors=True) if p.is_dir() else p.unlink(missing_ok=True)
    for p in out.glob(".old-*"):
        shutil.rmtree(p, ignore_errors=True)


def _ignore_interrupts() -> None:
    # Ctrl-C reaches the whole process group: the pool's processes leave it
    # to the parent, which stops handing out work and ends them.
    import signal
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class Interrupted(Exception):
    def __init__(self, done: int, total: int):
        super().__init__(f"interrupted after {done} of {total} submissions")
        self.done, self.total = done, total


def grade_all(folder: Path, out: Path, jobs: int | None = None, options: dict | None = None,
              progress: bool = True, force: bool = False, roster: Path | None = None,
              similarity: bool = False, grade_one=None, assignment: str | None = None,
              zero_missing: bool = False) -> list[Row]:
    """Grade every submission in `folder` into `out`; returns the gradebook rows.
    Raises Interrupted on Ctrl-C (what finished is kept: run again to go on),
    RosterError when the roster cannot be read, TargetError when its export
    has several assignments and `assignment` names none of them, and
    SimilarityUnavailable when --similarity cannot run (all before anything
    is graded). With a roster, the grade files for Canvas, Moodle and
    Gradescope are written too (grader/course/lms_csv.py), filling
    `assignment` (0 for who handed in nothing when `zero_missing`).
    `grade_one` (a module-level function with _grade_one's signature, run in
    the grading processes) replaces _grade_one: tests use it to break a
    grading process."""
    options = dict(options or {})
    if similarity:   # before grading: a missing tool must not cost a class's grading time
        from .similarity import require_tool
        require_tool()
    class_roster = target = None
    if roster is not None:
        from .lms_csv import choose_target
        from .roster import load_roster
        class_roster = load_roster(roster)
        target = choose_target(class_roster, assignment, zero_missing)
    if not options.get("allow_stale"):
        from ..grading.fixtures import check_stale
        check_stale()   # once, here: raises StaleFixtures for the instructor to read
    options["allow_stale"] = True
    jobs = max(1, jobs or os.cpu_count() or 1)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    _clean_leftovers(out)
    submissions = find_submissions(folder, exclude=out)
    key_base = grader_key({k: v for k, v in options.items() if k != "allow_stale"})
    todo, rows = [], {}
    for student, path in submissions.items():
        key = f"{key_base}:{_hash_tree(path)}"
        record = read_record(out / student)
        kept = None
        if not force and record and record.get("key") == key and (out / student / "results.json").is_file():
            kept = read_row(student, out / student)
        # A build stopped at its deadline is graded again too: a loaded
        # machine (or a classmate) may have cost it its time.
        if kept is not None and (kept.status not in DISTURBED or own_timeout(kept, record)) \
                and not record.get("build_timed_out"):
            kept.skipped = True
            rows[student] = kept
        else:
            todo.append((student, path, key))
    with _Progress(progress, len(submissions), len(submissions) - len(todo)) as advance:
        if todo:
            try:
                _run_pool(todo, out, jobs, options, rows, advance, grade_one or _grade_one)
            except KeyboardInterrupt:
                raise Interrupted(len(rows), len(submissions)) from None
    _clean_leftovers(out)   # what a broken pool's processes left half-written
    ordered = [rows[s] for s in submissions]
    own = [r.student for r in ordered if own_timeout(r, read_record(out / r.student))]
    data = {"skipped": skipped_entries(folder, exclude=out), "roster": None, "similarity": None,
            "grade_again": {"statuses": list(DISTURBED),
                            "students": [r.student for r in ordered if r.status in DISTURBED and r.student not in own]},
            "own_timeouts": {"students": own, "why": OWN_TIMEOUT_WHY}}
    missing: list[Row] = []
    if class_roster is not None:
        data["roster"], missing, entries = _apply_roster(class_roster, Path(roster), ordered)
        from .lms_csv import write_lms_files
        files, lms_left_out = write_lms_files(entries, out, target)
        data["roster"].update(lms_files=[p.name for p in files], lms_left_out=lms_left_out, lms_notes=target.notes,
                              lms_columns={"canvas": target.canvas_column, "moodle": target.moodle_column},
                              canvas_points=target.canvas_points)
    if similarity:
        from .similarity import class_similarity
        data["similarity"] = class_similarity(submissions, out)
    write_gradebook(ordered + missing, out / "gradebook.csv", roster_columns=class_roster is not None)
    write_text_atomic(out / SUMMARY_DATA, json.dumps(data, indent=1, sort_keys=True) + "\n")
    from ..grading.grade import GradeOptions
    _summary(ordered, out, data, GradeOptions(**options))
    return ordered


def _apply_roster(class_roster, path: Path, rows: list[Row]) -> tuple[dict, list[Row], list]:
    """Fill the rows' id, name and email; rows for students who handed in
    nothing; the summary's "roster" entry; (row, student) for every student
    on the roster, in gradebook order."""
    matched, unmatched, absent = class_roster.match([r.student for r in rows])
    for r in rows:
        if r.student in matched:
            st = matched[r.student]
            r.student_id, r.name, r.email = st.id, st.name, st.email
    missing = [Row(st.name or st.id or st.email, MISSING, 0.0, 0.0, student_id=st.id, name=st.name, email=st.email)
               for st in absent]
    entries = [(r, matched[r.student]) for r in rows if r.student in matched] + list(zip(missing, absent))
    summary = {"file": path.name, "columns": class_roster.columns, "students": len(class_roster.students),
               "matched": len(matched), "unmatched": unmatched,
               "missing": [{"id": st.id, "name": st.name, "email": st.email} for st in absent],
               "left_out": class_roster.left_out}
    return summary, missing, entries


def _summary(rows: list[Row], out: Path, data: dict, options) -> None:
    """The class summary (grader/reports/class_summary.py), given the summary
    data when it takes it, in the language the students' reports are in
    (--lang, else GRADER_LANG, else the rubric's: grade() chooses the same
    way, in each grading process)."""
    import inspect

    from ..grading.score import load_rubric
    from ..i18n import choose, language, set_language
    from ..reports.class_summary import write_summary
    before = language()
    set_language(choose(options.lang, load_rubric(options.rubric)))
    try:
        if "data" in inspect.signature(write_summary).parameters:
            write_summary(rows, out, data=data)
        else:
            write_summary(rows, out)
    finally:
        set_language(before)


def _run_pool(todo, out: Path, jobs: int, options: dict, rows: dict, advance, grade_one) -> None:
    """Grade `todo` in pools of `jobs` processes. A grading process that dies
    breaks its pool and fails every grading in it: those not yet started go
    to a fresh pool; those that were started, like every grading that
    raised, are graded again alone (_grade_alone), since any of them may
    be the one that broke it."""
    queue, suspects = list(todo), []
    while queue:
        failed, started = _pool_round(queue, out, jobs, options, rows, advance, grade_one)
        again = [t for t in queue if t[0] in failed and t[0] not in started]
        suspects += [(t, failed[t[0]]) for t in queue if t[0] in failed and t[0] in started]
        if again and len(again) == len(queue):
            # Nothing started: the pool cannot run here at all (no process or
            # thread to be had). Each is tried alone, and says why if it fails.
            suspects += [(t, failed[t[0]]) for t in again]
            again = []
        queue = again
    for (student, path, key), first in suspects:
        rows[student] = _grade_alone(student, path, out / student, key, options, grade_one, first)
        advance(student)


def _pool_round(queue, out: Path, jobs: int, options: dict, rows: dict, advance, grade_one):
    """One pool over `queue`: fills `rows` with what was graded; returns
    ({student: why their grading failed}, {students whose grading started})."""
    import concurrent.futures as futures
    import multiprocessing
    ctx = multiprocessing.get_context("spawn")   # no copy of the parent's threads or state
    starts = ctx.SimpleQueue()   # each grading process says whom it starts, before it starts
    pool = futures.ProcessPoolExecutor(max_workers=min(jobs, len(queue)), mp_context=ctx,
                                       initializer=_pool_process_init, initargs=(starts,))
    failed: dict[str, str] = {}
    started: set[str] = set()
    try:
        pending = {pool.submit(_started_then, grade_one, student, str(path), str(out / student), key, options): student
                   for student, path, key in queue}
        waiting = set(pending)
        while waiting:
            # A short wait: a name waiting in `starts` must not fill its pipe.
            done, waiting = futures.wait(waiting, timeout=0.5, return_when=futures.FIRST_COMPLETED)
            while not starts.empty():
                started.add(starts.get())
            for future in done:
                student = pending[future]
                try:
                    rows[student] = future.result()
                    advance(student)
                except Exception as e:   # the harness failed on this one, or the pool broke
                    failed[student] = _failure_text(e)
    except KeyboardInterrupt:
        for process in list(getattr(pool, "_processes", {}).values()):
            process.terminate()   # their half-graded folders are .tmp- ones, removed next run
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()
    while not starts.empty():
        started.add(starts.get())
    return failed, started


_STARTS = None   # in a grading process: where it says whom it starts grading


def _pool_process_init(starts) -> None:
    global _STARTS
    _STARTS = starts
    _ignore_interrupts()


def _started_then(grade_one, student: str, *args) -> Row:
    _STARTS.put(student)
    return grade_one(student, *args)


def _failure_text(e: BaseException) -> str:
    from concurrent.futures.process import BrokenProcessPool
    if isinstance(e, BrokenProcessPool):
        return "a grading process died while this submission was in its pool"
    return f"{type(e).__name__}: {e}"


def _grade_alone(student: str, path: Path, out: Path, key: str, options: dict, grade_one, first: str) -> Row:
    """Grade one student in a process of its own, with nothing else being
    graded; ungradable, saying why, if that fails too."""
    import multiprocessing
    ctx = multiprocessing.get_context("spawn")
    receive, send = ctx.Pipe(duplex=False)
    process = ctx.Process(target=_grade_in_process, args=(send, grade_one, student, str(path), str(out), key, options),
                          daemon=True)
    try:
        process.start()
        send.close()
        try:
            message = receive.recv()
        except EOFError:   # it died without a word
            message = None
        process.join()
    except KeyboardInterrupt:
        process.terminate()
        raise
    finally:
        receive.close()
    if message is not None and message[0] == "ok":
        return message[1]
    why = message[1] if message is not None else f"its grading process {_exit_text(process.exitcode)}"
    return Row(student, UNGRADABLE, 0.0, 0.0,
               error=f"{why} (graded alone, after a first try in the pool failed: {first})")


def _grade_in_process(send, grade_one, student: str, *args) -> None:
    _ignore_interrupts()
    try:
        message = ("ok", grade_one(student, *args))
    except Exception as e:
        message = ("error", f"{type(e).__name__}: {e}")
    send.send(message)
    send.close()


def _exit_text(code: int | None) -> str:
    import signal
    if code is not None and code < 0:
        try:
            return f"was killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"was killed by signal {-code}"
    return f"exited with status {code} before grading finished"


class _Progress:
    """A rich progress bar (on stderr), or nothing when not wanted."""

    def __init__(self, enabled: bool, total: int, already: int):
        self.enabled, self.total, self.already = enabled, total, already

    def __enter__(self):
        if not self.enabled:
            return lambda name: None
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
        self.bar = Progress(TextColumn("grading"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                            TextColumn("{task.description}", markup=False), console=Console(stderr=True))   # names are not markup
        self.bar.__enter__()
        task = self.bar.add_task(f"({self.already} unchanged)" if self.already else "",
                                 total=self.total, completed=self.already)
        return lambda name: self.bar.update(task, advance=1, description=name)

    def __exit__(self, *exc):
        if self.enabled:
            self.bar.__exit__(*exc)


def write_gradebook(rows: list[Row], path: Path, roster_columns: bool = False) -> None:
    """gradebook.csv: one row per student, the rubric's checks as columns.
    With a roster: student_id, name and email after the student column (an
    LMS imports by them), and students who handed in nothing with a blank
    score (an import leaves their grade alone)."""
    from ..reports.class_summary import check_names
    names = check_names(rows)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    who = ["student_id", "name", "email"] if roster_columns else []
    w.writerow(["student", *who, "score", "max_score", "status", *names, "diagnoses"])
    for r in rows:
        ids = [cell(r.student_id), cell(r.name), cell(r.email)] if roster_columns else []
        score = ["", ""] if r.status == MISSING else [f"{r.score:g}", f"{r.max_score:g}"]
        # A check that did not run is blank, not 0: the difference matters when an instructor regrades.
        w.writerow([cell(r.student), *ids, *score, r.status,
                    *[f"{r.checks[n]:g}" if n in r.checks else "" for n in names], " ".join(r.diagnoses)])
    write_text_atomic(path, buf.getvalue())
