"""Grade a class: every submission in a folder, in parallel, resumable.

Each student's results land atomically in OUT/<student>/ as they finish,
with a key (the submission's content hash and the grader's own) beside them:
re-run after an interruption, unchanged submissions are skipped. The
gradebook (gradebook.csv) and the class summary are rebuilt from what is on
disk, so they are always complete.
"""
from __future__ import annotations

import concurrent.futures as futures
import csv
import hashlib
import io
import json
import multiprocessing
import os
import tempfile
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from . import PROJECT_ROOT

KEY_FILE = ".grade-key"
ARCHIVES = (".zip", ".tar.gz", ".tgz", ".cpp")


def student_name(path: Path) -> str:
    name = path.name
    for suffix in ARCHIVES:
        if name.endswith(suffix):
            return name[: -len(suffix)]
    return name


def find_submissions(folder: Path) -> list[Path]:
    """One sub-folder or archive per student, sorted by name."""
    out = []
    for p in sorted(Path(folder).iterdir()):
        if p.name.startswith("."):
            continue
        if p.is_dir() or p.name.endswith(ARCHIVES):
            out.append(p)
    return out


def _hash_tree(path: Path) -> str:
    h = hashlib.sha256()
    files = [path] if path.is_file() else sorted(p for p in path.rglob("*") if p.is_file())
    for f in files:
        h.update(f.relative_to(path).as_posix().encode() if f != path else b"")
        h.update(b"\0")
        h.update(f.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


def grader_key() -> str:
    """Changes whenever the grading could change: grader code, rubric, fixtures, reference."""
    h = hashlib.sha256()
    roots = [PROJECT_ROOT / "grader", PROJECT_ROOT / "reference", PROJECT_ROOT / "fixtures", PROJECT_ROOT / "student_template"]
    for root in roots:
        for f in sorted(root.rglob("*")):
            if f.is_file() and "__pycache__" not in f.parts:
                h.update(f.relative_to(PROJECT_ROOT).as_posix().encode())
                h.update(f.read_bytes())
    return h.hexdigest()


@dataclass
class Row:
    student: str
    status: str
    score: float
    max_score: float
    checks: dict[str, float]
    diagnoses: list[str]
    skipped: bool = False


def _grade_one(submission: str, out: str, key: str, options: dict) -> Row:
    """Runs in a pool process: grade, then mark the results with the key."""
    from .grade import GradeOptions, grade
    out_dir = Path(out)
    try:
        result = grade(Path(submission), out_dir, GradeOptions(**options))
    except SystemExit as e:   # e.g. stale fixtures: the instructor's problem, say so
        raise RuntimeError(str(e)) from None
    _write_text_atomic(out_dir / KEY_FILE, key)
    return _row_from_results(student_name(Path(submission)), out_dir)


def _write_text_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".tmp-")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def _row_from_results(student: str, out_dir: Path) -> Row:
    data = json.loads((out_dir / "results.json").read_text())
    extra = data.get("extra_data", {})
    checks = {t["name"]: t.get("score", 0.0) for t in data.get("tests", [])}
    return Row(student, extra.get("status", "graded"), float(data.get("score", 0.0)),
               float(extra.get("max_score", sum(t.get("max_score", 0) for t in data.get("tests", [])))),
               checks, sorted({d["id"] for d in extra.get("diagnoses", [])}))


def grade_all(folder: Path, out: Path, jobs: int | None = None, options: dict | None = None, progress: bool = True) -> list[Row]:
    options = options or {}
    jobs = jobs or os.cpu_count() or 1
    submissions = find_submissions(folder)
    key_base = grader_key()
    todo, rows = [], {}
    for s in submissions:
        name = student_name(s)
        key = f"{key_base}:{_hash_tree(s)}"
        key_file = out / name / KEY_FILE
        if key_file.exists() and key_file.read_text() == key and (out / name / "results.json").exists():
            rows[name] = _row_from_results(name, out / name)
            rows[name].skipped = True
        else:
            todo.append((s, key))
    failures = {}
    with _progress(progress, len(submissions), len(submissions) - len(todo)) as advance:
        ctx = multiprocessing.get_context("spawn")
        with futures.ProcessPoolExecutor(max_workers=jobs, mp_context=ctx) as pool:
            pending = {pool.submit(_grade_one, str(s), str(out / student_name(s)), key, options): s for s, key in todo}
            for done in futures.as_completed(pending):
                s = pending[done]
                try:
                    rows[student_name(s)] = done.result()
                except Exception as e:   # the harness failed on this one: ungradable, never silently dropped
                    failures[student_name(s)] = str(e)
                    rows[student_name(s)] = Row(student_name(s), "ungradable", 0.0, 0.0, {}, [])
                advance(student_name(s))
    ordered = [rows[student_name(s)] for s in submissions]
    write_gradebook(ordered, out / "gradebook.csv")
    write_summary(ordered, out, failures)
    return ordered


class _progress:
    """A rich progress bar, or nothing when not wanted."""

    def __init__(self, enabled: bool, total: int, already: int):
        self.enabled, self.total, self.already = enabled, total, already

    def __enter__(self):
        if not self.enabled:
            return lambda name: None
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
        self.bar = Progress(TextColumn("grading"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                            TextColumn("{task.description}"))
        self.bar.__enter__()
        task = self.bar.add_task("", total=self.total, completed=self.already)
        return lambda name: self.bar.update(task, advance=1, description=name)

    def __exit__(self, *exc):
        if self.enabled:
            self.bar.__exit__(*exc)


def write_gradebook(rows: list[Row], path: Path) -> None:
    names = sorted({c for r in rows for c in r.checks})
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["student", "score", "max_score", "status", *names, "diagnoses"])
    for r in rows:
        w.writerow([r.student, f"{r.score:g}", f"{r.max_score:g}", r.status,
                    *[f"{r.checks.get(n, 0.0):g}" for n in names], " ".join(r.diagnoses)])
    _write_text_atomic(path, buf.getvalue())


def write_summary(rows: list[Row], out: Path, failures: dict[str, str]) -> None:
    """summary.md with the score histogram (summary_histogram.png) and the most common diagnoses."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scores = [r.score for r in rows]
    fig, ax = plt.subplots(figsize=(6, 3.2), dpi=100)
    ax.hist(scores, bins=20, range=(0, max([r.max_score for r in rows] + [100])), color="#4a7bd0")
    ax.set_xlabel("score")
    ax.set_ylabel("submissions")
    ax.set_title(f"{len(rows)} submissions")
    fig.tight_layout()
    fig.savefig(out / "summary_histogram.png", metadata={"Software": None})
    plt.close(fig)
    counts = Counter(d for r in rows for d in r.diagnoses)
    statuses = Counter(r.status for r in rows)
    lines = ["# Class summary", "", f"{len(rows)} submissions; " + ", ".join(f"{n} {s}" for s, n in sorted(statuses.items())), "",
             "![score histogram](summary_histogram.png)", "", "## Most common diagnoses", "",
             "| diagnosis | submissions |", "|---|---:|"]
    lines += [f"| {d} | {n} |" for d, n in counts.most_common()]
    if failures:
        lines += ["", "## Could not be graded (harness errors)", ""] + [f"- {s}: {m}" for s, m in sorted(failures.items())]
    _write_text_atomic(out / "summary.md", "\n".join(lines) + "\n")
