#!/usr/bin/env python3
"""The self-check: the course's visible checks on your EnvironmentMap.cpp.

    make selfcheck          (or: cmake --build build-cmake --target selfcheck)

The driver (selfcheck/driver.cpp, compiled with your EnvironmentMap.cpp) runs
your fetchColor and readTexture on the inputs in selfcheck/data; this script
compares what they return with the expected answers stored there, scores the
checks with the course's points, names the mistakes it recognises, and writes
report.md and report.html. It needs Python 3.8+ and nothing else (standard
library only). The data holds answers for these public inputs only: the
grader also uses inputs you do not see, hidden checks and a speed check.
"""
from __future__ import annotations

import argparse
import array
import base64
import html
import json
import math
import os
import re
import signal
import struct
import subprocess
import sys
import time
import zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent
KIT = HERE.parent
DATA = HERE / "data"
FACE_NAMES = ("+X", "-X", "+Y", "-Y", "+Z", "-Z")
INF = float("inf")
NAN = float("nan")
# Each driver process may run this long before it counts as hung (a correct
# solution needs about a second for everything). After one hang the rest is
# not run: a student waits 20 s, not 20 s per check.
TIMEOUT_S = 20.0
CHUNK = 2048     # rows per driver call in large sets (a crash costs one chunk)
# Renders: how far the tone-mapped (display, 0..1) render may be from the
# reference's, as a root mean square over all pixels and channels. Measured
# on these 64x64 renders (7 scenes): the six correct solutions of the course's
# test set give at most 2.1e-7 (computing in float), the wrong ones the
# grader fails at least 2.4e-3 (weights swapped, on the sky map). 1e-4 sits
# 500 times above the first and 24 times below the second.
RENDER_RMS_MAX = 1e-4


# ---- data ------------------------------------------------------------------------

def load(name: str, typecode: str) -> array.array:
    a = array.array(typecode)
    a.frombytes((DATA / name).read_bytes())
    if sys.byteorder != "little":
        a.byteswap()
    return a


def rows(a, width: int = 3) -> list:
    return [tuple(a[i:i + width]) for i in range(0, len(a), width)]


def write_f64(path: Path, values) -> None:
    a = array.array("d", values)
    if sys.byteorder != "little":
        a.byteswap()
    path.write_bytes(a.tobytes())


def read_output(path: Path, n: int, typecode: str = "d") -> list | None:
    if not path.is_file():
        return None
    a = array.array(typecode)
    a.frombytes(path.read_bytes())
    if sys.byteorder != "little":
        a.byteswap()
    return list(a) if len(a) == n else None


# ---- running the driver ----------------------------------------------------------

class Failure:
    def __init__(self, kind: str, where: str, message: str):
        self.kind, self.where, self.message = kind, where, message


class Driver:
    """Runs the compiled driver on job files. A crash or hang loses one
    command only: the driver restarts after it, with the last texture."""

    def __init__(self, path: Path, raw: Path):
        self.path = path
        self.raw = raw
        self.count = 0
        self.hung = False

    def run(self, commands: list[tuple[str, list[str]]]) -> tuple[set[int], dict[int, set[int]], list[Failure]]:
        """commands: (description, fields). Returns the commands that failed,
        the rows that did not give an answer per command (an exception, or a
        crash in their chunk: NaN in the output), and the failures.

        Large fetch and texture calls run in chunks of CHUNK rows, so that a
        crash costs its chunk, not the whole set (the grader narrows a crash
        down to the input; the kit stays simpler)."""
        expanded, parts = [], []          # parts: (original index, first row, count, part output)
        for i, (what, fields) in enumerate(commands):
            rows_n = self._rows(fields)
            if rows_n is None or rows_n <= CHUNK:
                parts.append((i, 0, rows_n, None))
                expanded.append((what, fields))
                continue
            for first in range(0, rows_n, CHUNK):
                count = min(CHUNK, rows_n - first)
                part_out = f"{fields[-1]}.part{first}"
                parts.append((i, first, count, part_out))
                expanded.append((what, fields[:-1] + [part_out, str(first), str(count)]))
        failed_x, threw_x, failures = self._run_plain(expanded)
        failed: set[int] = set()
        threw: dict[int, set[int]] = {}
        chunks: dict[int, list] = {}
        for k, (i, first, count, part_out) in enumerate(parts):
            lost = set(threw_x.get(k, set()))
            if part_out is None:
                if k in failed_x:
                    failed.add(i)
                elif lost:
                    threw.setdefault(i, set()).update(lost)
                continue
            chunks.setdefault(i, []).append((first, count, part_out, k in failed_x, lost))
        for i, pieces in chunks.items():
            if all(p[3] for p in pieces):
                failed.add(i)
                continue
            width = 3
            values = []
            for first, count, part_out, part_failed, lost in pieces:
                got = None if part_failed else read_output(Path(part_out), width * count)
                values += got if got is not None else [NAN] * (width * count)
                threw.setdefault(i, set()).update(first + r for r in (range(count) if got is None else lost))
                Path(part_out).unlink(missing_ok=True)
            write_f64(Path(commands[i][1][-1]), values)
        return failed, threw, failures

    @staticmethod
    def _rows(fields: list[str]) -> int | None:
        """Rows of a fetch (3 doubles) or texture (2 doubles) call; None otherwise."""
        if fields[0] == "fetch":
            return Path(fields[1]).stat().st_size // 24
        if fields[0] == "texture":
            return Path(fields[2]).stat().st_size // 16
        return None

    def _run_plain(self, commands: list[tuple[str, list[str]]]) -> tuple[set[int], dict[int, set[int]], list[Failure]]:
        failed: set[int] = set()
        threw: dict[int, set[int]] = {}
        failures: list[Failure] = []
        if self.hung:
            return set(range(len(commands))), threw, [Failure("timeout", commands[0][0], "not run: an earlier call did not finish")]
        start = 0
        while start < len(commands):
            setup = [i for i in range(start) if commands[i][1][0] in ("faces", "cross")][-1:]
            todo = setup + list(range(start, len(commands)))
            self.count += 1
            job = self.raw / f"job{self.count}.txt"
            job.write_text("".join("\t".join(commands[i][1]) + "\n" for i in todo))
            status = self.raw / f"job{self.count}.status"
            code, timed_out = run_ended(self.path, job, status, self.raw / f"job{self.count}")
            err = (self.raw / f"job{self.count}.err").read_text(errors="replace") if not timed_out else ""
            out = status.read_text(errors="replace") if status.is_file() else ""
            done = set()
            for line in out.splitlines():
                fields = line.split("\t")
                if fields[0] == "done" and len(fields) == 2:
                    done.add(todo[int(fields[1])])
                elif fields[0] == "exception" and len(fields) >= 4:
                    i = todo[int(fields[1])]
                    if int(fields[2]) not in threw.setdefault(i, set()) and not threw[i]:
                        failures.append(Failure("exception", commands[i][0], f"threw an exception: {fields[3]}"))
                    threw[i].add(int(fields[2]))
            if code == 0 and not timed_out:
                return failed, threw, failures
            stuck = next((i for i in todo if i not in done), None)
            if stuck is None:
                return failed, threw, failures
            failed.add(stuck)
            what = commands[stuck][0]
            if timed_out:
                failures.append(Failure("timeout", what, f"did not finish within {TIMEOUT_S:.0f} s (an endless loop?)"))
            elif code == 86:
                failures.append(Failure("harness", what, err.strip()[-300:] or "the driver could not run this"))
            else:
                failures.append(Failure("crash", what, crash_message(code)))
            start = stuck + 1
            if timed_out:
                # One hang is enough: the rest is not run.
                self.hung = True
                failed.update(range(start, len(commands)))
                break
        return failed, threw, failures


def run_ended(driver: Path, job: Path, status: Path, stem: Path) -> tuple[int | None, bool]:
    """Run the driver on one job file: (exit code, timed out). The driver
    runs in a session of its own, and it ends with everything it started:
    the student's code runs in it (static initialisers too), and a process
    it left behind could otherwise rewrite the report after the self-check
    has written it. What the student's code prints goes to files (kept, not
    parsed), so a leftover holding a pipe open cannot stall the run."""
    with open(f"{stem}.out", "wb") as out, open(f"{stem}.err", "wb") as err:
        proc = subprocess.Popen([str(driver), str(job), str(status)], stdin=subprocess.DEVNULL, stdout=out,
                                stderr=err, cwd=str(KIT), start_new_session=True)
        try:
            code, timed_out = proc.wait(timeout=TIMEOUT_S), False
        except subprocess.TimeoutExpired:
            code, timed_out = None, True
        end_descendants(proc)
    return code, timed_out


def become_subreaper() -> bool:
    """Linux: make every process the driver leaves behind (even one that
    called setsid to leave its session) a child of this one when its parent
    dies, so end_descendants can find it. Elsewhere, or if it fails, only
    the driver's process group is ended."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes
        PR_SET_CHILD_SUBREAPER = 36
        return ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


SUBREAPER = False   # set by main()


def own_children() -> list[int]:
    me, found = os.getpid(), []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat", "rb") as f:
                    fields = f.read().rpartition(b")")[2].split()   # the name, in (), may hold anything
            except OSError:
                continue
            if len(fields) > 1 and int(fields[1]) == me:
                found.append(int(entry))
    return found


def end_descendants(proc: subprocess.Popen | None = None) -> None:
    """Kill the driver (if still running), its process group, and, as a
    subreaper, every process left behind, until none is left."""
    if proc is not None:
        if proc.poll() is None:
            proc.kill()
        if hasattr(os, "killpg"):
            try:
                os.killpg(proc.pid, signal.SIGKILL)   # its session's group: the driver's pid
            except OSError:
                pass   # nothing left in it
        proc.wait()
    while SUBREAPER:
        children = own_children()
        if not children:
            break
        for pid in children:   # orphans reparented to us, and any they still hold
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        for pid in children:
            try:
                os.waitpid(pid, 0)
            except ChildProcessError:
                pass


def crash_message(code: int | None) -> str:
    signals = {-11: "segmentation fault: a read outside memory (SIGSEGV)", -6: "abort (SIGABRT)",
               -8: "arithmetic error (SIGFPE)", -7: "bus error (SIGBUS)", -4: "illegal instruction (SIGILL)"}
    if code in signals:
        return f"crashed: {signals[code]}"
    if code is not None and code > 0xFFFF:
        return f"crashed (exit code 0x{code & 0xFFFFFFFF:08X})"   # Windows exceptions
    return f"crashed (exit status {code})"


FAILURE_DIAGNOSIS = {"crash": "crash", "exception": "exception", "timeout": "timeout",
                     "out-of-bounds-read": "out-of-bounds-read", "harness": "crash"}


def failure_diagnoses(failures: list[Failure], limit: int = 3) -> list[dict]:
    out, seen = [], set()
    for f in failures:
        kind = FAILURE_DIAGNOSIS.get(f.kind, "crash")
        if kind in seen:
            continue
        seen.add(kind)
        out.append(diag(kind, f"{f.where}: {f.message}."))
        if len(out) >= limit:
            break
    return out


def diag(id: str, detail: str, face: str | None = None) -> dict:
    return {"id": id, "detail": detail, "face": face}


def unique(diagnoses: list[dict]) -> list[dict]:
    seen, out = set(), []
    for d in diagnoses:
        if (d["id"], d.get("face")) not in seen:
            seen.add((d["id"], d.get("face")))
            out.append(d)
    return out


# ---- comparing -------------------------------------------------------------------

def finite(row) -> bool:
    return all(math.isfinite(x) for x in row)


def error_to(actual, candidates) -> float:
    """Distance (largest channel difference) to the nearest acceptable colour."""
    if not finite(actual):
        return INF
    best = INF
    for c in candidates:
        if any(math.isnan(x) for x in c):
            continue
        best = min(best, max(abs(a - b) for a, b in zip(actual, c)))
    return best


def fmt(v) -> str:
    return "(" + ", ".join(f"{x:.6g}" for x in v) + ")"


def describe_direction(d) -> str:
    return "fetchColor(Vector3(" + ", ".join(f"{x:.9g}" for x in d) + "))"


class Fetched:
    """Expected data of one direction set (grader/kit/data.py, _expected_fetch)."""

    def __init__(self, entry: dict, filter: str):
        self.dirs = rows(load(entry["dirs"], "d"))
        self.expected = rows(load(entry[f"expected_{filter}"], "f"))
        tied = load(entry["tied"], "i")
        alternatives = rows(load(entry[f"alternatives_{filter}"], "f"), 9)
        self.alternatives = {i: [alt[0:3], alt[3:6], alt[6:9]] for i, alt in zip(tied, alternatives)}
        self.faces = list(load(entry["faces"], "i")) if "faces" in entry else None

    def candidates(self, i: int):
        return [self.expected[i]] + self.alternatives.get(i, [])


def compare_rows(actual: list, fetched: Fetched, tol: float) -> list[bool]:
    return [error_to(actual[i], fetched.candidates(i)) <= tol for i in range(len(actual))]


def worst(actual, expected, ok, describe, limit=3) -> list[str]:
    bad = [i for i, good in enumerate(ok) if not good]
    bad.sort(key=lambda i: -min(error_to(actual[i], [expected[i]]), 1e300))
    lines = [f"- {describe(i)}: expected {fmt(expected[i])}, got {fmt(actual[i])}" for i in bad[:limit]]
    if len(bad) > limit:
        lines.append(f"- ... and {len(bad) - limit} more")
    return lines


# ---- the checks ------------------------------------------------------------------

class Context:
    def __init__(self, driver: Driver, manifest: dict, raw: Path):
        self.driver = driver
        self.manifest = manifest
        self.raw = raw
        self.texture_ok = True
        self.texture_mistake = None
        self.read_outside = False      # readTexture read the NaN around the faces
        self.pictures: dict[str, tuple] = {}

    def judging_filter(self) -> tuple[str, float]:
        """The expected data to judge fetchColor with, and the slack in
        texels: fetchColor is judged on its own. With a nearest-texel
        readTexture the expected answers are those of a correct fetchColor
        over it (stored); with another wrong readTexture, fetchColor still
        earns credit where every sample lands within a texel of the right
        spot (the grader fits a model of your readTexture instead)."""
        if self.texture_ok:
            return "bilinear", 0.0
        if self.texture_mistake == "nearest-neighbor":
            return "nearest", 0.0
        return "bilinear", 1.01

    def out(self, name: str) -> Path:
        return self.raw / name

    def fetch_command(self, what: str, dirs_file: str, out: str) -> tuple[str, list[str]]:
        return (what, ["fetch", str(DATA / dirs_file), str(self.out(out))])

    def faces_command(self, faces: dict, what: str = "setting the texture") -> tuple[str, list[str]]:
        return (what, ["faces", str(faces["width"]), str(faces["height"]), str(DATA / faces["file"])])


def outputs_or_nan(path: Path, n: int, failed: bool) -> list:
    values = None if failed else read_output(path, 3 * n)
    if values is None:
        return [(NAN, NAN, NAN)] * n
    return rows(values)


def check_read_texture(ctx: Context) -> dict:
    spec = ctx.manifest["checks"]["read_texture"]
    commands, cases = [], []
    for g in spec["groups"]:
        w, h = g["width"], g["height"]
        for t in g["textures"]:
            commands.append(ctx.faces_command(t["faces"]))
            for c in t["cases"]:
                out = f"rt_{w}x{h}_{t['kind']}_{c['face']}.out"
                name = FACE_NAMES[c["face"]]
                commands.append((f"readTexture(face {name}) on {w}x{h} {t['kind']} texels",
                                 ["texture", str(c["face"]), str(DATA / g["uv"]), str(ctx.out(out))]))
                cases.append((len(commands) - 1, g, t, c, out))
    failed, threw, failures = ctx.driver.run(commands)
    total = matched = 0
    lines, recognised, oob = [], {}, None
    for index, g, t, c, out in cases:
        w, h, n = g["width"], g["height"], g["count"]
        uv = rows(load(g["uv"], "d"), 2)
        actual = outputs_or_nan(ctx.out(out), n, index in failed)
        for row in threw.get(index, ()):
            actual[row] = (NAN, NAN, NAN)
        expected = rows(load(c["expected"], "f"))
        ok = [error_to(a, [e]) <= c["tolerance"] for a, e in zip(actual, expected)]
        total += n
        matched += sum(ok)
        name = FACE_NAMES[c["face"]]
        if index not in failed and oob is None:
            # The memory around the faces is NaN in the driver: NaN from
            # (u, v) in [0, 1] means a texel outside the face was read.
            bad = [i for i, a in enumerate(actual) if not finite(a) and i not in threw.get(index, ())]
            if bad:
                oob = Failure("out-of-bounds-read", f"readTexture(face {name}, u = {uv[bad[0]][0]:.6g}, v = {uv[bad[0]][1]:.6g})",
                              f"read memory outside the face ({w}x{h} texels): a texel index reached -1 or W (or H)")
        if sum(ok) < n and len(lines) < 6:
            lines.append(f"Face {name}, {w}x{h} {t['kind']} texels:")
            lines.extend(worst(actual, expected, ok, lambda i: f"readTexture(face {name}, u = {uv[i][0]:.6g}, v = {uv[i][1]:.6g})"))
        if t["kind"] == "coordinate" and sum(ok) / n < 0.99:
            best = None
            for mistake, file in c["mistakes"].items():
                predicted = rows(load(file, "f"))
                share = sum(error_to(a, [p]) <= c["tolerance"] for a, p in zip(actual, predicted)) / n
                if best is None or share > best[1]:
                    best = (mistake, share)
            if best and best[1] >= 0.9:
                recognised[best[0]] = recognised.get(best[0], 0) + 1
    diagnoses = []
    # Reading outside the face explains the differences (the grader's worker
    # crashes there): no other mistake is guessed from them.
    ctx.read_outside = oob is not None
    if recognised and not ctx.read_outside:
        name = max(sorted(recognised), key=recognised.get)
        mistake = spec["mistakes"][name]
        diagnoses.append(diag(mistake["id"], mistake["detail"]))
        ctx.texture_mistake = mistake["id"]
    diagnoses += failure_diagnoses(failures + ([oob] if oob else []))
    ctx.texture_ok = matched == total
    fraction = matched / total if total else 0.0
    if matched < total:
        output = f"{total - matched} of {total} readTexture calls differ from the reference bilinear filter.\n\n" + "\n".join(lines)
    else:
        output = f"All {total} readTexture calls match the reference (u, v at 0, 1, texel boundaries, centres and random points)."
    return {"fraction": fraction, "diagnoses": unique(diagnoses), "output": output, "cases": total, "matched": matched}


def check_fetch_sweep(ctx: Context) -> dict:
    spec = ctx.manifest["checks"]["fetch_sweep"]
    filter, slack = ctx.judging_filter()
    tol = spec["tolerance"] + slack
    commands = [ctx.faces_command(spec["faces"])]
    for i, s in enumerate(spec["sets"]):
        commands.append(ctx.fetch_command(f"fetchColor on the {s['name']} directions", s["dirs"], f"sweep{i}.out"))
    failed, threw, failures = ctx.driver.run(commands)
    total = matched = 0
    table_rows, lines, diagnoses = [], [], failure_diagnoses(failures)
    per_face_bad, per_face_all = [0] * 6, [0] * 6
    nan_input = None
    bad_tied = bad_clear = 0
    tie_example = None
    for i, s in enumerate(spec["sets"]):
        fetched = Fetched(s, filter)
        n = s["count"]
        actual = outputs_or_nan(ctx.out(f"sweep{i}.out"), n, (i + 1) in failed)
        thrown = threw.get(i + 1, set())
        ok = compare_rows(actual, fetched, tol)
        if nan_input is None and (i + 1) not in failed:
            fresh = [r for r in range(n) if r not in thrown and not finite(actual[r])]
            if fresh:
                nan_input = fetched.dirs[fresh[0]]
        total += n
        matched += sum(ok)
        if (i + 1) not in failed:
            for r in range(n):
                if not ok[r]:
                    if r in fetched.alternatives:
                        bad_tied += 1
                        tie_example = tie_example or fetched.dirs[r]
                    else:
                        bad_clear += 1
        for r, f in enumerate(fetched.faces):
            if f >= 0:
                per_face_all[f] += 1
                per_face_bad[f] += not ok[r]
        table_rows.append((s["name"], n, sum(ok)))
        if sum(ok) < n and len(lines) < 12:
            lines.append(f"**{s['name']}**:")
            lines.extend(worst(actual, fetched.expected, ok, lambda r: describe_direction(fetched.dirs[r])))
    # (With a readTexture that reads outside the face, NaN is what it read.)
    if nan_input is not None and not ctx.read_outside:
        diagnoses.append(diag("nan-output", f"{describe_direction(nan_input)} returned NaN or infinity for a finite, non-zero direction."))
    if bad_tied and not bad_clear and not failed:
        # Right everywhere but on edges and corners: the face choice at ties.
        diagnoses.append(diag("tie-untouched-face", f"{describe_direction(tie_example)} lies on an edge or corner of the cube "
                              f"and samples a face it does not touch ({bad_tied} such directions)."))
    fraction = matched / total if total else 0.0
    table = ["| direction set | cases | match |", "|---|---:|---:|"]
    table += [f"| {name} | {n} | {ok / n:.1%} |" for name, n, ok in table_rows]
    table += ["", "| face | directions | match |", "|---|---:|---:|"]
    table += [f"| {FACE_NAMES[k]} | {per_face_all[k]} | {1 - per_face_bad[k] / max(per_face_all[k], 1):.1%} |" for k in range(6)]
    if matched < total:
        output = (f"{total - matched} of {total} directions give a colour different from the reference.\n\n"
                  + "\n".join(table) + "\n\nWorst cases:\n\n" + "\n".join(lines))
    else:
        output = f"All {total} directions match the reference.\n\n" + "\n".join(table)
    ctx.sweep_fraction = fraction      # robustness is scored only for a lookup that works (as the grader's)
    return {"fraction": fraction, "diagnoses": unique(diagnoses), "output": output, "cases": total, "matched": matched}


def decode(rgb) -> tuple[int, float, float]:
    """Face and texel position sampled, from a coordinate-encoding texture
    (R = x + 1, G = y + 1, B = face + 1); face -1 when not one of ours."""
    if not finite(rgb):
        return -1, NAN, NAN
    face = round(rgb[2]) - 1
    if abs(rgb[2] - (face + 1)) >= 1e-3 or not 0 <= face <= 5:
        face = -1
    return face, rgb[0] - 1.0, rgb[1] - 1.0


# (swap, flip_u, flip_v) in the grader's order, and the position columns
# (u, 1-u, v, 1-v) that give the swapped/flipped u and v.
TRANSFORMS = [(s, fu, fv) for s in (False, True) for fu in (False, True) for fv in (False, True)]


def transform_ids(swap, flip_u, flip_v) -> list[str]:
    return [name for name, on in (("uv-swapped", swap), ("u-flipped", flip_u), ("v-flipped", flip_v)) if on]


def best_transform(pos, rows_, px, py, tol) -> tuple[list[str], float]:
    best = ([], -1.0)
    for swap, fu, fv in TRANSFORMS:
        cx = (3 if fu else 2) if swap else (1 if fu else 0)
        cy = (1 if fv else 0) if swap else (3 if fv else 2)
        hits = sum(1 for r in rows_ if abs(pos[r][cx] - px[r]) <= tol and abs(pos[r][cy] - py[r]) <= tol)
        share = hits / len(rows_)
        if share > best[1]:
            best = (transform_ids(swap, fu, fv), share)
    return best


def mapping_detail(mistake: str, name: str) -> str:
    return {
        "u-flipped": f"On the {name} face, u runs the wrong way (your u is 1 - u of the (u, v) table in README.md).",
        "v-flipped": f"On the {name} face, v runs the wrong way (your v is 1 - v of the (u, v) table in README.md).",
        "uv-swapped": f"On the {name} face, u and v are swapped.",
    }[mistake]


def check_diagnosis(ctx: Context) -> dict:
    spec = ctx.manifest["checks"]["diagnosis"]
    filter = ctx.judging_filter()[0]
    tol = 1e-3 if ctx.texture_ok else 1.01
    dirs = rows(load(spec["dirs"], "d"))
    n = spec["count"]
    write_f64(ctx.out("diag_dirs10.f64"), [10.0 * x for d in dirs for x in d])
    # Lengths that break a lookup computing in float, or squaring the
    # components, on a subset of the directions away from edges.
    clear_all = [r for r, c in enumerate(load(spec["clear"], "i")) if c]
    subset = clear_all[::max(1, len(clear_all) // 1500)]
    write_f64(ctx.out("diag_subset.f64"), [x for r in subset for x in dirs[r]])
    commands = [ctx.faces_command(spec["faces"]),
                ctx.fetch_command("fetchColor on the Fibonacci sphere", spec["dirs"], "diag.out"),
                ("fetchColor on the same directions, 10 times longer",
                 ["fetch", str(ctx.out("diag_dirs10.f64")), str(ctx.out("diag10.out"))]),
                ("fetchColor on directions of length 1",
                 ["fetch", str(ctx.out("diag_subset.f64")), str(ctx.out("diag_subset.out"))])]
    for k, scale in enumerate(LENGTH_SCALES):
        write_f64(ctx.out(f"diag_scale{k}.f64"), [scale * x for r in subset for x in dirs[r]])
        commands.append((f"fetchColor on directions of length {scale:g}",
                         ["fetch", str(ctx.out(f"diag_scale{k}.f64")), str(ctx.out(f"diag_scale{k}.out"))]))
    failed, threw, _ = ctx.driver.run(commands)
    sub = outputs_or_nan(ctx.out("diag.out"), n, 1 in failed)
    evaluated = [1 not in failed and r not in threw.get(1, ()) for r in range(n)]
    ref_faces = list(load(spec["reference_faces"], "i"))
    clear = [bool(c) and e for c, e in zip(load(spec["clear"], "i"), evaluated)]
    decoded = [decode(c) for c in sub]
    sub_faces = [d[0] for d in decoded]
    px = [d[1] for d in decoded]
    py = [d[2] for d in decoded]
    share_min = spec["share"]
    diagnoses, lines = [], []
    clear_rows = [r for r in range(n) if clear[r]]
    if clear_rows and all(sub_faces[r] < 0 for r in clear_rows):
        diagnoses.append(diag("not-implemented", "fetchColor returns black (or a colour that is not in the texture) for every direction: it still looks like the starting code."))
    else:
        scaled = outputs_or_nan(ctx.out("diag10.out"), n, 2 in failed)
        moved = 0
        for r in clear_rows:
            f2, x2, y2 = decode(scaled[r])
            moved += (f2 != sub_faces[r]) or not (abs(x2 - px[r]) <= tol) or not (abs(y2 - py[r]) <= tol)
        if clear_rows and moved / len(clear_rows) > 0.1:
            diagnoses.append(diag("not-normalized", "The answer changes when the direction is made 10 times longer: divide the face-plane coordinates by the major component's magnitude m."))
        lengths = [] if diagnoses else length_diagnoses(ctx, len(subset), failed, spec["tolerance"])
        pos = rows(load(spec[f"positions_{filter}_uv"], "f"), 4)
        pos_len = rows(load(spec[f"positions_{filter}_uvlen"], "f"), 4)
        lost = set(range(n)) if 1 in failed else threw.get(1, set())
        for f in range(6):
            toward = [r for r in clear_rows if ref_faces[r] == f]
            if len(toward) < 20:
                crashed = [r for r in clear_all if ref_faces[r] == f and r in lost]
                if crashed:
                    diagnoses.append(diag("face-not-analysed", f"Directions toward {FACE_NAMES[f]} could not be analysed "
                                          f"(crash at {describe_direction(dirs[crashed[0]])}).", FACE_NAMES[f]))
                continue
            rows_ = [r for r in toward if sub_faces[r] >= 0]
            name = FACE_NAMES[f]
            if not rows_:
                diagnoses.append(diag("wrong-face", f"Directions toward {name} return a colour that is not in the texture (black?).", name))
                continue
            sampled = [0] * 6
            for r in rows_:
                sampled[sub_faces[r]] += 1
            g = max(range(6), key=lambda k: (sampled[k], -k))
            if g != f and sampled[g] >= share_min * len(rows_):
                diagnoses.append(diag("wrong-face", f"Directions toward {name} sample the {FACE_NAMES[g]} face.", name))
            ids, share = best_transform(pos, rows_, px, py, tol)
            if share < share_min:
                ids_len, share_len = best_transform(pos_len, rows_, px, py, tol)
                if share_len >= share_min:
                    if not any(d["id"] == "not-normalized" for d in diagnoses):
                        diagnoses.append(diag("not-normalized", "fetchColor divides by the direction's length instead of the major component's magnitude m, so (u, v) do not reach the face's edges."))
                    ids, share = ids_len, share_len
            for mistake in ids if share >= share_min else []:
                diagnoses.append(diag(mistake, mapping_detail(mistake, name), name))
            if share < share_min:
                diagnoses.append(diag("uv-mismatch", f"On the {name} face, (u, v) follow no pattern we recognise ({share:.0%} of directions explained by the best guess).", name))
            lines.append(f"| {name} | {FACE_NAMES[g]} | {', '.join(ids) if share >= share_min else '?'} | {share:.0%} |")
        # Dividing by the length squares the components too: one mistake, one fix (divide by m).
        diagnoses += [d for d in lengths if d["id"] == "float-precision"
                      or not any(x["id"] == "not-normalized" for x in diagnoses)]
    if diagnoses:
        table = ["| direction toward | face sampled | (u, v) mistakes | explained |", "|---|---|---|---:|"] + lines
        output = "\n".join(["What fetchColor does, recovered from a texture whose texels encode their own position:", ""] + (table if lines else []))
    else:
        output = "On every face, fetchColor samples the right face with u and v running the right way."
    return {"fraction": 0.0 if diagnoses else 1.0, "diagnoses": diagnoses, "output": output}


# Lengths that break a lookup computing in float (below float's normal range,
# above its largest value) and one that squares the components (x*x
# overflows above 1.3e154, underflows to 0 below 1e-162): the grader's.
FLOAT_TINY, FLOAT_HUGE = 1e-41, 1e39
SQUARE_HUGE, SQUARE_TINY = 1e155, 1e-170
LENGTH_SCALES = (FLOAT_TINY, FLOAT_HUGE, SQUARE_HUGE, SQUARE_TINY)


def length_diagnoses(ctx: Context, n: int, failed: set, tol: float) -> list[dict]:
    base = outputs_or_nan(ctx.out("diag_subset.out"), n, 3 in failed)
    judged = [r for r in range(n) if finite(base[r])]
    broken = {}
    for k, scale in enumerate(LENGTH_SCALES):
        got = outputs_or_nan(ctx.out(f"diag_scale{k}.out"), n, 4 + k in failed)
        bad = sum(1 for r in judged if not (finite(got[r]) and all(abs(a - b) <= tol for a, b in zip(got[r], base[r]))))
        broken[scale] = bad / len(judged) if judged else 0.0
    if broken[FLOAT_TINY] > 0.1 or broken[FLOAT_HUGE] > 0.1:
        which = [w for w, s in (("tiny (|d| = 1e-41)", FLOAT_TINY), ("huge (|d| = 1e39)", FLOAT_HUGE)) if broken[s] > 0.1]
        return [diag("float-precision", f"fetchColor gives another answer for {' and '.join(which)} directions than for the same "
                     "directions at length 1: the components go through float (float x = direction.x, or a float "
                     "parameter), which cannot hold magnitudes below 1.2e-38 exactly or above 3.4e38 at all. "
                     "Keep them in double until you have divided by m.")]
    if broken[SQUARE_HUGE] > 0.1 or broken[SQUARE_TINY] > 0.1:
        which = [w for w, s in (("huge (|d| = 1e155)", SQUARE_HUGE), ("tiny (|d| = 1e-170)", SQUARE_TINY)) if broken[s] > 0.1]
        return [diag("length-overflow", f"fetchColor breaks for {' and '.join(which)} directions but not for 1e39 or 1e-41: "
                     "x*x + y*y + z*z overflows to infinity above |d| = 1.3e154 (and underflows to 0 below "
                     "about 1e-162), so normalising first divides by infinity or 0. Divide by m, the largest "
                     "|component|, instead: it needs no squares.")]
    return []


def colour_class(rgb) -> int:
    """0, 1, 2 for clearly red, green, blue; -1 for grey or anything else."""
    v = [x if math.isfinite(x) else 0.0 for x in rgb]
    top = max(range(3), key=lambda k: (v[k], -k))
    peak = v[top]
    rest = sorted(v)[1]
    return top if peak > 0.2 and rest < 0.5 * peak else -1


def check_arrows(ctx: Context) -> dict:
    spec = ctx.manifest["checks"]["arrows"]
    commands = [("loading Cubemap/test_environment_map.hdr", ["cross", str(KIT / "Cubemap" / "test_environment_map.hdr")]),
                ctx.fetch_command("fetchColor near the six axes", spec["caps"], "caps.out"),
                ctx.fetch_command("fetchColor on the Fibonacci sphere", spec["sphere"], "sphere.out")]
    failed, _, failures = ctx.driver.run(commands)
    per_cap = spec["per_cap"]
    caps = outputs_or_nan(ctx.out("caps.out"), 6 * per_cap, 1 in failed)
    sphere = outputs_or_nan(ctx.out("sphere.out"), spec["sphere_count"], 2 in failed)
    diagnoses = failure_diagnoses(failures)
    cap_classes = [[colour_class(c) for c in caps[i * per_cap:(i + 1) * per_cap]] for i in range(6)]
    sub_sphere = [colour_class(c) for c in sphere]
    ref_sphere = list(load(spec["reference_classes"], "i"))
    axis_names = spec["axis_names"]
    verdicts, passed, metrics = [], 0, {}
    for k, (colour, axis) in enumerate(spec["arrows"]):
        where = [axis_names[i] for i in range(6) if sum(c == k for c in cap_classes[i]) / per_cap > 0.5]
        mine = [s for s, r in zip(sub_sphere, ref_sphere) if r == k]
        shape = sum(s == k for s in mine) / len(mine) if mine else 0.0
        pole_ok = where == [axis]
        shape_ok = shape >= spec["shape_agreement"]
        passed += pole_ok + shape_ok
        metrics[f"{colour}_shape"] = shape
        if not where:
            verdicts.append(f"{colour} arrow: missing (no {colour} disc at any axis)")
            diagnoses.append(diag("arrow-missing", f"The {colour} arrow's head ({colour} disc at {axis}) appears nowhere along the axes."))
        elif not pole_ok:
            verdicts.append(f"{colour} arrow: points toward {' and '.join(where)}, should be {axis}")
            diagnoses.append(diag("arrow-wrong", f"The {colour} arrow points toward {' and '.join(where)} instead of {axis}."))
        elif not shape_ok:
            verdicts.append(f"{colour} arrow: points to {axis} but is drawn wrongly ({shape:.0%} of it in place)")
            diagnoses.append(diag("arrow-wrong", f"The {colour} arrow points toward {axis}, but only {shape:.0%} of it is where it should be: part of it is flipped or on the wrong face."))
        else:
            verdicts.append(f"{colour} arrow: points along {axis}")
    return {"fraction": passed / 6, "diagnoses": unique(diagnoses), "output": "\n".join(f"- {v}" for v in verdicts)}


def check_stability(ctx: Context) -> dict:
    spec = ctx.manifest["checks"]["stability"]
    filter, slack = ctx.judging_filter()
    tol = spec["tolerance"] + slack
    smooth = spec["smooth"]
    commands = [ctx.faces_command(spec["faces"]),
                ctx.fetch_command("fetchColor on zero, NaN and infinite directions", spec["degenerate"], "degenerate.out"),
                ctx.fetch_command("fetchColor on tiny and huge directions", spec["extreme"]["dirs"], "extreme.out"),
                ctx.fetch_command("fetchColor on edges and corners moved by one ulp", spec["ties"]["dirs"], "ties.out"),
                ctx.faces_command(smooth["faces"], "setting a smooth texture"),
                ctx.fetch_command("fetchColor just on one side of the cube's edges", smooth["a"], "edge_a.out"),
                ctx.fetch_command("fetchColor just on the other side of the cube's edges", smooth["b"], "edge_b.out")]
    failed, threw, failures = ctx.driver.run(commands)
    diagnoses = failure_diagnoses(failures)
    parts, lines = [], []
    n_degenerate = len(load(spec["degenerate"], "d")) // 3
    ran = 0 if 1 in failed else n_degenerate - len(threw.get(1, ()))
    parts.append(("zero, NaN and infinite directions do not crash", n_degenerate, ran))

    extreme = Fetched(spec["extreme"], filter)
    actual = outputs_or_nan(ctx.out("extreme.out"), len(extreme.dirs), 2 in failed)
    if 2 not in failed:
        nan_rows = [r for r in range(len(actual)) if r not in threw.get(2, ()) and not finite(actual[r])]
        if nan_rows and not ctx.read_outside:
            diagnoses.append(diag("nan-output", f"{describe_direction(extreme.dirs[nan_rows[0]])} returned NaN or infinity; the direction is finite and not zero. Divide by the major component's magnitude, never by a squared length (which underflows or overflows)."))
    ok = compare_rows(actual, extreme, tol)
    parts.append(("tiny and huge directions give the reference colour", len(ok), sum(ok)))
    bad = [r for r in range(len(ok)) if not ok[r]]
    bad.sort(key=lambda r: -min(error_to(actual[r], extreme.candidates(r)), 1e300))
    for r in bad[:3]:
        lines.append(f"- {describe_direction(extreme.dirs[r])}: expected {fmt(extreme.expected[r])}, got {fmt(actual[r])}")

    ties = Fetched(spec["ties"], filter)
    actual = outputs_or_nan(ctx.out("ties.out"), len(ties.dirs), 3 in failed)
    ok = compare_rows(actual, ties, tol)
    parts.append(("edges and corners moved by one ulp", len(ok), sum(ok)))

    edges = list(load(smooth["edge"], "i"))
    out_a = outputs_or_nan(ctx.out("edge_a.out"), len(edges), 5 in failed)
    out_b = outputs_or_nan(ctx.out("edge_b.out"), len(edges), 6 in failed)
    ref_jump = list(load(smooth[f"jump_{filter}"], "d"))
    step = smooth["step"] if slack else 0.0
    bad_edges = set()
    for r, e in enumerate(edges):
        jump = max(abs(x - y) for x, y in zip(out_a[r], out_b[r]))
        if not jump <= ref_jump[r] + 2 * smooth["tolerance"] + 2 * step:   # NaN is bad too
            bad_edges.add(e)
    parts.append(("no seam larger than the reference's at the 12 edges", 12, 12 - len(bad_edges)))
    if bad_edges:
        diagnoses.append(diag("discontinuous-seam", f"The colour jumps across {len(bad_edges)} of the 12 cube edges where the reference is continuous: neighbouring faces disagree about (u, v) along their shared edge."))
    total = sum(n for _, n, _ in parts)
    passed = sum(k for _, _, k in parts)
    table = ["| case | tried | passed |", "|---|---:|---:|"] + [f"| {name} | {n} | {k} |" for name, n, k in parts]
    output = "\n".join(table + ([""] + lines if lines else []))
    sweep = getattr(ctx, "sweep_fraction", 1.0)
    if sweep < 0.5:
        # As the grader: robustness needs a lookup that works (black never crashes).
        return {"fraction": 0.0, "diagnoses": unique(diagnoses),
                "output": f"Robustness is scored once fetchColor matches the reference on at least 50% of the sweep "
                          f"directions (yours: {sweep:.0%}). What was found:\n\n" + output}
    return {"fraction": passed / total, "diagnoses": unique(diagnoses), "output": output}


def srgb(c: float) -> float:
    return 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1 / 2.4) - 0.055


def display(x: float) -> float:
    """The grader's tone map: Reinhard x / (1 + x), then the sRGB curve."""
    if x != x or x <= 0:
        return 0.0
    if x == INF:
        return 1.0
    return srgb(x / (1.0 + x))


def check_renders(ctx: Context) -> dict:
    spec = ctx.manifest["checks"]["renders"]
    w, h, spp = spec["width"], spec["height"], spec["samples"]
    commands = []
    for item in spec["items"]:
        commands.append((f"rendering {item['scene']} with {item['map']}",
                         ["render", str(KIT / item["scene"]), str(KIT / "Cubemap" / item["map"]), str(w), str(h), str(spp),
                          str(ctx.out(item["name"] + ".out"))]))
    failed, _, failures = ctx.driver.run(commands)
    diagnoses = failure_diagnoses(failures)
    table, passed, worst_item = [], 0, None
    for i, item in enumerate(spec["items"]):
        label = f"{Path(item['scene']).stem} with {item['map']}"
        values = None if i in failed else read_output(ctx.out(item["name"] + ".out"), w * h * 3, "f")
        expected = [display(x) for x in load(item["expected"], "f")]
        got = [display(x) for x in values] if values is not None else [0.0] * len(expected)
        rms = math.sqrt(sum((a - b) ** 2 for a, b in zip(expected, got)) / len(expected))
        ok = values is not None and rms <= RENDER_RMS_MAX
        passed += ok
        table.append(f"| {label} | {rms:.2e} | {'pass' if ok else 'FAIL' if values is not None else 'FAIL (did not finish)'} |")
        if worst_item is None or rms > worst_item[0]:
            worst_item = (rms, label, expected, got)
    if worst_item:
        ctx.pictures["renders"] = (worst_item[1], w, h, worst_item[2], worst_item[3])
    n = len(spec["items"])
    if passed < n:
        diagnoses.append(diag("render-mismatch", f"{n - passed} of {n} renders differ visibly from the reference (display RMS difference above {RENDER_RMS_MAX:g})."))
    output = (f"Pass: root mean square difference of the tone-mapped {w}x{h} renders at most {RENDER_RMS_MAX:g}.\n\n"
              + "\n".join(["| render | RMS difference | |", "|---|---:|---|"] + table))
    if worst_item:
        output += f"\n\nThe pictures show {worst_item[1]}, the render that differs most."
    return {"fraction": passed / n if n else 1.0, "diagnoses": unique(diagnoses), "output": output}


CHECKS = {
    "read_texture": check_read_texture,
    "fetch_sweep": check_fetch_sweep,
    "diagnosis": check_diagnosis,
    "arrows": check_arrows,
    "stability": check_stability,
    "renders": check_renders,
}


# ---- scoring and reports ---------------------------------------------------------

def score(points: float, partial: str, fraction: float) -> float:
    if partial == "all":
        return points if fraction >= 1.0 else 0.0
    return round(points * min(max(fraction, 0.0), 1.0), 2)


def grade(driver_path: Path, out: Path) -> dict:
    manifest = json.loads((DATA / "manifest.json").read_text())
    raw = out / "raw"
    raw.mkdir(parents=True, exist_ok=True)
    ctx = Context(Driver(driver_path, raw), manifest, raw)
    checks = []
    for entry in manifest["rubric"]:          # the rubric's order: read_texture first
        name = entry["name"]
        run = CHECKS.get(name)
        if run is None:
            continue
        t0 = time.monotonic()
        result = run(ctx)
        result.update(name=name, title=entry["title"], max_score=entry["points"],
                      score=score(entry["points"], entry["partial"], result["fraction"]),
                      seconds=round(time.monotonic() - t0, 2))
        result["status"] = "passed" if result["fraction"] >= 1.0 else "failed"
        checks.append(result)
    # Leave out symptoms (a render that differs, a seam) when their cause was found.
    consequences = set(manifest["diagnoses"]["consequences"])
    if any(d["id"] not in consequences for c in checks for d in c["diagnoses"]):
        for c in checks:
            c["diagnoses"] = [d for d in c["diagnoses"] if d["id"] not in consequences]
    total = round(sum(c["score"] for c in checks), 2)
    maximum = sum(c["max_score"] for c in checks)
    return {"score": total, "max_score": maximum, "checks": checks, "pictures": ctx.pictures,
            "grader_only": manifest.get("grader_only", {}), "catalogue": manifest["diagnoses"]}


def all_diagnoses(result: dict) -> list[dict]:
    seen, out = set(), []
    for c in result["checks"]:
        for d in c["diagnoses"]:
            key = (d["id"], d.get("face"), d["detail"])
            if key not in seen:
                seen.add(key)
                out.append(d)
    return out


def describe(result: dict, id: str) -> dict:
    entry = result["catalogue"]["entries"].get(id)
    return entry or {"title": id, "explanation": "", "what_to_do": ""}


def grouped_diagnoses(result: dict) -> list[tuple[dict, list[dict]]]:
    """One entry per diagnosis id, in the order found, with its details."""
    groups: dict[str, list[dict]] = {}
    for d in all_diagnoses(result):
        groups.setdefault(d["id"], []).append(d)
    return [(dict(describe(result, id), id=id), ds) for id, ds in groups.items()]


FOOTER = ("This self-check runs the course's visible checks on public inputs. Your grade may include checks "
          "you do not see here (and a speed check), and the grader's random directions differ from these: "
          "make your code right, not just this report green.")


def markdown_report(result: dict) -> str:
    lines = ["# Self-check of EnvironmentMap.cpp", "", f"**Score: {result['score']:g} / {result['max_score']:g}** (visible checks)", ""]
    groups = grouped_diagnoses(result)
    if groups:
        lines += ["## What to fix", ""]
        for info, ds in groups:
            lines.append(f"- **{info['title']}** (`{info['id']}`)")
            for d in ds[:6]:
                lines.append(f"  - {d['detail']}")
            if info.get("what_to_do"):
                lines.append(f"  - What to do: {info['what_to_do']}")
        lines.append("")
    lines += ["## Checks", "", "| check | score | |", "|---|---:|---|"]
    for c in result["checks"]:
        lines.append(f"| {c['title']} | {c['score']:g} / {c['max_score']:g} | {c['status']} |")
    lines.append("")
    for c in result["checks"]:
        lines += [f"### {c['title']}", "", f"{c['score']:g} / {c['max_score']:g}, {c['status']}", "", c["output"], ""]
    if result["grader_only"]:
        lines += ["## Not checked here", ""]
        lines += [f"- `{name}`: {why}" for name, why in result["grader_only"].items()]
        lines.append("")
    lines += ["---", "", FOOTER, ""]
    return "\n".join(lines)


def png_data_uri(width: int, height: int, display_values: list, scale: int = 3) -> str:
    """An RGB PNG (zlib from the standard library) as a data: URI."""
    raw = bytearray()
    for y in range(height):
        row = bytearray()
        for x in range(width):
            i = 3 * (y * width + x)
            px = bytes(max(0, min(255, int(v * 255 + 0.5))) for v in display_values[i:i + 3])
            row += px * scale
        for _ in range(scale):
            raw += b"\x00" + row
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width * scale, height * scale, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b""))
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def inline(text: str) -> str:
    """Escaped text, with `code` spans of the catalogue's words as <code>."""
    return re.sub(r"`([^`<>]+)`", r"<code>\1</code>", html.escape(text))


def html_report(result: dict) -> str:
    e = html.escape
    parts = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
             '<meta name="viewport" content="width=device-width, initial-scale=1">',
             "<title>Self-check of EnvironmentMap.cpp</title>",
             "<style>body{font-family:system-ui,sans-serif;max-width:60rem;margin:2rem auto;padding:0 1rem;line-height:1.45;color:#222}"
             "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:.25rem .6rem;text-align:left}"
             "pre{background:#f6f6f6;padding:.6rem;overflow-x:auto;white-space:pre-wrap}"
             ".passed{color:#176f2c}.failed{color:#b00020}.score{font-size:1.6rem;font-weight:bold}"
             ".fix{border-left:4px solid #b00020;padding-left:.8rem;margin:.8rem 0}figure{display:inline-block;margin:0 1rem 0 0}"
             "img{image-rendering:pixelated}td.n{white-space:nowrap}</style></head><body>",
             "<h1>Self-check of EnvironmentMap.cpp</h1>",
             f'<p class="score">Score: {result["score"]:g} / {result["max_score"]:g}</p><p>(the visible checks)</p>']
    groups = grouped_diagnoses(result)
    if groups:
        parts.append("<h2>What to fix</h2>")
        for info, ds in groups:
            parts.append(f'<div class="fix"><strong>{e(info["title"])}</strong> <code>{e(info["id"])}</code>')
            if info.get("explanation"):
                parts.append(f"<p>{inline(info['explanation'])}</p>")
            parts.append("<ul>" + "".join(f"<li>{e(d['detail'])}</li>" for d in ds[:6]) + "</ul>")
            if info.get("what_to_do"):
                parts.append(f"<p><em>What to do:</em> {inline(info['what_to_do'])}</p>")
            parts.append("</div>")
    parts.append("<h2>Checks</h2><table><tr><th>check</th><th>score</th><th></th></tr>")
    for c in result["checks"]:
        parts.append(f'<tr><td>{e(c["title"])}</td><td class="n">{c["score"]:g} / {c["max_score"]:g}</td>'
                     f'<td class="{e(c["status"])}">{e(c["status"])}</td></tr>')
    parts.append("</table>")
    for c in result["checks"]:
        parts.append(f"<h3>{e(c['title'])}</h3><p class=\"{e(c['status'])}\">{c['score']:g} / {c['max_score']:g}, {e(c['status'])}</p>")
        parts.append(f"<pre>{e(c['output'])}</pre>")
        if c["name"] == "renders" and "renders" in result["pictures"]:
            label, w, h, expected, got = result["pictures"]["renders"]
            parts.append(f"<p>{e(label)}:</p>")
            for title, values in (("reference", expected), ("your fetchColor", got)):
                parts.append(f'<figure><img alt="{e(title)}" width="{3 * w}" height="{3 * h}" src="{png_data_uri(w, h, values)}">'
                             f"<figcaption>{e(title)}</figcaption></figure>")
    if result["grader_only"]:
        parts.append("<h2>Not checked here</h2><ul>")
        parts += [f"<li><code>{e(n)}</code>: {e(why)}</li>" for n, why in result["grader_only"].items()]
        parts.append("</ul>")
    parts.append(f"<hr><p>{e(FOOTER)}</p></body></html>")
    return "\n".join(parts) + "\n"


def terminal_report(result: dict) -> str:
    lines = [f"Score: {result['score']:g} / {result['max_score']:g} (visible checks)", ""]
    for c in result["checks"]:
        mark = "ok  " if c["status"] == "passed" else "FAIL"
        lines.append(f"  {mark} {c['score']:>5g} / {c['max_score']:<4g} {c['title']}")
    groups = grouped_diagnoses(result)
    if groups:
        lines += ["", "What to fix:"]
        for info, ds in groups:
            lines.append(f"  - {info['title']} [{info['id']}]")
            for d in ds[:3]:
                lines.append(f"      {d['detail']}")
            if info.get("what_to_do"):
                lines.append(f"      What to do: {info['what_to_do']}")
    return "\n".join(lines)


def write_reports(result: dict, out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    (out / "report.md").write_text(markdown_report(result), encoding="utf-8")
    (out / "report.html").write_text(html_report(result), encoding="utf-8")
    summary = {k: result[k] for k in ("score", "max_score")}
    summary["checks"] = [dict({k: c[k] for k in ("name", "title", "score", "max_score", "status", "fraction")},
                              diagnoses=c["diagnoses"]) for c in result["checks"]]
    (out / "selfcheck.json").write_text(json.dumps(summary, indent=1) + "\n", encoding="utf-8")


def write_build_failure(log_path: Path, out: Path) -> None:
    log = log_path.read_text(errors="replace")[-20000:] if log_path.is_file() else "(no compiler output)"
    hint = ""
    if "em_" in log and any(s in log for s in ("not declared", "undeclared", "undefined reference", "identifier not found")):
        hint = ("A name starting with em_ that the compiler does not know belongs to the grader's reference "
                "lookup, which is not in the kit (and not allowed in your submission): write that part yourself.")
    text = "Your EnvironmentMap.cpp did not compile, so no check ran." + (" " + hint if hint else "")
    md = "\n".join(["# Self-check of EnvironmentMap.cpp", "", "**Score: 0** (did not compile)", "", text, "",
                    "````", log.replace("````", "` ` ` `"), "````", ""])
    page = ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Self-check: did not compile</title></head>"
            f"<body><h1>Self-check of EnvironmentMap.cpp</h1><p><strong>Score: 0</strong> (did not compile)</p>"
            f"<p>{html.escape(text)}</p><pre>{html.escape(log)}</pre></body></html>\n")
    out.mkdir(parents=True, exist_ok=True)
    (out / "report.md").write_text(md, encoding="utf-8")
    (out / "report.html").write_text(page, encoding="utf-8")
    (out / "selfcheck.json").write_text(json.dumps({"score": 0, "max_score": None, "build_failed": True}) + "\n")
    print(text)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--driver", type=Path, help="the compiled selfcheck driver")
    p.add_argument("--out", type=Path, default=KIT / "build" / "selfcheck")
    p.add_argument("--fail-under", type=float, metavar="SCORE")
    p.add_argument("--build-failed", type=Path, metavar="LOG", help="report a compile failure (the compiler's output)")
    args = p.parse_args(argv)
    if args.build_failed:
        write_build_failure(args.build_failed, args.out)
        return 1
    if not args.driver:
        p.error("--driver is required")
    driver = args.driver.resolve()
    if not driver.is_file():
        print(f"selfcheck: no driver at {driver}: build it first (make selfcheck does)", file=sys.stderr)
        return 2
    global SUBREAPER
    SUBREAPER = become_subreaper()
    t0 = time.monotonic()
    result = grade(driver, args.out.resolve())
    end_descendants()   # nothing the driver started may outlive the run and touch the reports
    write_reports(result, args.out)
    print(terminal_report(result))
    print(f"\n({time.monotonic() - t0:.1f} s) Reports: {args.out / 'report.md'} and {args.out / 'report.html'} (with pictures)")
    if args.fail_under is not None and result["score"] < args.fail_under:
        print(f"score {result['score']:g} is below {args.fail_under:g}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
