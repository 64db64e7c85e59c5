"""The audit's figures and its report: terminal text, audit.json, audit.html.

    kill rate        behaviour-changing mutants graded below full marks / those graded
    false-fail rate  equivalent mutants graded below full marks / those graded
    escaped          behaviour-changing mutants with full marks (the grader missed them)
    alone            for each check, the behaviour-changing mutants it is the only one
                     to mark down: a check that catches none alone is redundant on
                     these mutants, one that does is essential
    caught by two    the mutants exactly two checks mark down: what a rubric without
                     both would let through
"""
from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

from ...reports.html import CSP
from ...reports.templating import render_page
from .mutants import OPERATORS
from .truth import BEHAVIOUR_CHANGING, CLASS_WORDS, CLASSES, EQUIVALENT, UNJUDGED

JSON_NAME = "audit.json"
HTML_NAME = "audit.html"


def _graded_ok(a) -> bool:
    """Graded and not ungradable (a harness failure is neither a kill nor a pass)."""
    return a.graded is not None and not a.graded.error and a.graded.status != "ungradable"


def _row(a) -> dict:
    m, g = a.mutant, a.graded
    row = {"id": a.name, "class": a.truth.klass, "groups": a.truth.groups, "truth": a.truth.example,
           "truth_seconds": a.truth.seconds}
    if m is not None:
        row.update(solution=m.solution, operator=m.operator, line=m.line, diff=m.diff)
    if g is not None:
        row.update(score=round(g.score, 4), max_score=g.max_score, status=g.status, lost=g.lost,
                   checks={k: round(v, 4) for k, v in g.checks.items()}, diagnoses=g.diagnoses, error=g.error)
    return row


def summarise(result) -> dict:
    """Everything the report shows, as plain data (audit.json)."""
    graded = [a for a in result.mutants if _graded_ok(a)]
    changing = [a for a in graded if a.truth.klass in BEHAVIOUR_CHANGING]
    equivalent = [a for a in graded if a.truth.klass == EQUIVALENT]
    escaped = [a for a in changing if a.graded.full_marks]
    false_fails = [a for a in equivalent if not a.graded.full_marks]
    ungradable = [a for a in result.mutants if a.graded is not None and not _graded_ok(a)]
    checks = {}
    for name, points in result.checks.items():
        catches = [a for a in changing if name in a.graded.lost]
        alone = [a for a in changing if a.graded.lost == [name]]
        checks[name] = {"points": points, "catches": len(catches), "alone": [a.name for a in alone],
                        "alone_diffs": [a.mutant.diff for a in alone],
                        "marks_down_equivalent": [a.name for a in equivalent if name in a.graded.lost]}
    # Mutants that exactly two checks catch: what dropping both would let through.
    pairs: dict[str, list[str]] = {}
    for a in changing:
        if len(a.graded.lost) == 2:
            pairs.setdefault(" + ".join(a.graded.lost), []).append(a.name)
    controls_ok = all(c.truth.klass == EQUIVALENT and c.graded is not None and c.graded.full_marks
                      for c in result.controls)
    by_class = Counter(a.truth.klass for a in result.mutants)
    return {
        "rubric": str(result.rubric),
        "settings": result.settings,
        "seconds": result.seconds,
        "controls_ok": controls_ok,
        "controls": [_row(c) for c in result.controls],
        "classes": {k: by_class.get(k, 0) for k in CLASSES},
        "operators": {op: Counter(a.mutant.operator for a in result.mutants).get(op, 0) for op in OPERATORS},
        "behaviour_changing": len(changing),
        "equivalent": len(equivalent),
        "killed": len(changing) - len(escaped),
        "kill_rate": (len(changing) - len(escaped)) / len(changing) if changing else None,
        "false_fail_rate": len(false_fails) / len(equivalent) if equivalent else None,
        "escaped": [_row(a) for a in escaped],
        "false_fails": [_row(a) for a in false_fails],
        "ungradable": [_row(a) for a in ungradable],
        "unjudged": [_row(a) for a in result.mutants if a.truth.klass == UNJUDGED],
        "checks": checks,
        "caught_by_two_only": dict(sorted(pairs.items())),
        "mutants": [_row(a) for a in result.mutants],
    }


def _rate(x) -> str:
    return "n/a" if x is None else f"{100 * x:.1f}%"


def terminal_text(data: dict) -> str:
    """The summary for the instructor's terminal."""
    s = data["settings"]
    lines = [f"audit of {data['rubric']}: {s['sampled']} of {s['available']} mutants (seed {s['seed']}) "
             f"of {', '.join(s['solutions'])}" + (" (quick grading)" if s["quick"] else "")]
    if not data["controls_ok"]:
        bad = [c["id"] for c in data["controls"]
               if c["class"] != EQUIVALENT or c.get("score", -1) < c.get("max_score", 0) - 1e-9]
        lines.append(f"WARNING: the unchanged solutions are not all equivalent with full marks ({', '.join(bad)}): "
                     "the figures below cannot be trusted")
    lines.append("by class: " + ", ".join(f"{n} {CLASS_WORDS[k]}" for k, n in data["classes"].items() if n))
    lines.append(f"kill rate: {_rate(data['kill_rate'])} ({data['killed']} of {data['behaviour_changing']} "
                 f"behaviour-changing mutants below full marks)")
    lines.append(f"false-fail rate: {_rate(data['false_fail_rate'])} ({len(data['false_fails'])} of "
                 f"{data['equivalent']} equivalent mutants marked down)")
    lines.append("checks (points: mutants caught, caught by it alone):")
    for name, c in data["checks"].items():
        tag = "essential" if c["alone"] else ("redundant here" if c["points"] else "scores nothing")
        lines.append(f"  {name:<14} {c['points']:>5g}: {c['catches']:>4} caught, {len(c['alone']):>3} alone  ({tag})")
    for pair, ids in data.get("caught_by_two_only", {}).items():
        lines.append(f"  caught only by {pair}: {len(ids)}")
    for title, rows in (("ESCAPED (wrong, full marks)", data["escaped"]),
                        ("FALSELY FAILED (equivalent, marked down)", data["false_fails"]),
                        ("UNGRADABLE (the grader failed)", data["ungradable"]),
                        ("NOT JUDGED (the audit failed)", data.get("unjudged", []))):
        if rows:
            lines.append(f"{title}: {len(rows)}")
            for r in rows:
                extra = f"lost {', '.join(r['lost'])}" if r.get("lost") else r.get("truth", "")
                lines.append(f"  [{r['class']}] {r['diff']}")
                lines.append(f"      {extra}")
    sec = data["seconds"]
    lines.append(f"time: {sec.get('total', 0):.0f} s ({sec.get('truth', 0):.0f} s judging, "
                 f"{sec.get('grading', 0):.0f} s grading) with {s['jobs']} jobs on {s['cpus']} cores")
    return "\n".join(lines)


def _cell(value) -> str:
    return "\n".join(map(str, value)) if isinstance(value, (list, tuple)) else str(value)


def html_page(data: dict) -> str:
    """audit.html: one self-contained page (templates/audit.html)."""
    checks = [{"check": n, "points": c["points"], "caught": c["catches"], "alone": len(c["alone"]),
               "alone_diffs": c["alone_diffs"][:8] + ([f"... {len(c['alone_diffs']) - 8} more"]
                                                       if len(c["alone_diffs"]) > 8 else []),
               "equivalent marked down": len(c["marks_down_equivalent"])} for n, c in data["checks"].items()]
    cols = [("class", "truth"), ("diff", "mutant"), ("score", "score"), ("max_score", "of"), ("lost", "checks lost"),
            ("truth", "where it differs")]
    return render_page(
        "audit.html", CSP=CSP, cell=_cell, summary=terminal_text(data).split("\nchecks")[0],
        checks=checks, check_columns=[(k, k) for k in checks[0]] if checks else [],
        escaped=data["escaped"], false_fails=data["false_fails"], controls=data["controls"],
        mutants=data["mutants"], columns=cols, control_columns=[("id", "solution")] + cols[::2])


def write_reports(result, out: Path) -> dict:
    data = summarise(result)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / JSON_NAME).write_text(json.dumps(data, indent=1) + "\n")
    (out / HTML_NAME).write_text(html_page(data))
    return data


