"""`grade-all --similarity`: which submissions of a class are suspiciously alike.

The comparison is copydetect's (PyPI; winnowed k-gram fingerprints of the
token stream, as MOSS does): identifiers, comments and layout do not count,
so renaming variables and reformatting a copy does not hide it. The
template's EnvironmentMap.cpp is the boilerplate: lines every student got
from us (includes, signatures, the starter comments) are left out, so only
what students wrote themselves can make two submissions similar.

The result is plain data for the class summary (summary.json, "similarity";
grader/reports/class_summary.py renders it):

    {"tool": "copydetect 0.5.0", "boilerplate": "student_template/EnvironmentMap.cpp",
     "noise_tokens": 25, "guarantee_tokens": 30, "compared": 12, "min_listed": 0.5,
     "not_compared": [{"student": "dave", "reason": "..."}],
     "pairs": [{"a": "alice", "b": "bob", "similarity": 0.91,       # the larger of the two shares
                "share_a": 0.91, "share_b": 0.88,                   # of each one's own code found in the other
                "shared_tokens": 412,
                "passages": [{"a_lines": [12, 40], "b_lines": [10, 37],
                              "a_text": "...", "b_text": "..."}]}]}

A pair is listed when its similarity is at least min_listed, the most
similar first, at most MAX_PAIRS. Similar code is a reason to look, not a
verdict: the summary says so. Submission text is hostile: it stays data.
"""
from __future__ import annotations

import io
from pathlib import Path

from .. import PROJECT_ROOT
from ..i18n import N_

BOILERPLATE = PROJECT_ROOT / "student_template" / "EnvironmentMap.cpp"
NOISE_TOKENS = 25        # shorter shared runs are noise (copydetect's noise threshold, its default)
GUARANTEE_TOKENS = 30    # shared runs this long are always found (its guarantee threshold, its default)
MIN_LISTED = 0.5         # share of a submission's own code found in the other
MAX_PAIRS = 20
MAX_PASSAGES = 3         # per pair, the longest
MAX_PASSAGE_CHARS = 1200
# Why a submission was not compared, when it is ours to say: in English in
# summary.json; the class page shows it translated (an intake error's
# message comes in the words it was made in).
NOTHING_OF_ITS_OWN = N_("nothing of its own beyond the template")


class SimilarityUnavailable(Exception):
    """copydetect is not installed (it is in requirements.lock: `make venv`)."""


def _copydetect():
    try:
        from copydetect import CodeFingerprint, compare_files
    except ImportError as e:
        raise SimilarityUnavailable(f"--similarity needs copydetect ({e}); `make venv` installs it "
                                    "from requirements.lock.") from None
    from importlib import metadata
    return f"copydetect {metadata.version('copydetect')}", CodeFingerprint, compare_files


def require_tool() -> str:
    """The tool's name and version; SimilarityUnavailable when it is missing."""
    return _copydetect()[0]


def _fingerprint(CodeFingerprint, text: str, boilerplate=None):
    # The file name only picks the lexer; language= forces C++ whatever students named it.
    win = GUARANTEE_TOKENS - NOISE_TOKENS + 1
    return CodeFingerprint("EnvironmentMap.cpp", NOISE_TOKENS, win, boilerplate=boilerplate,
                           language="cpp", fp=io.StringIO(text))


def _line(text: str, offset: int) -> int:
    return text.count("\n", 0, max(0, int(offset))) + 1


def _passages(text_a: str, slices_a, text_b: str, slices_b) -> list[dict]:
    """The longest shared passages, with their line ranges, on each side.
    copydetect gives each side's copied spans separately (not paired):
    the i-th longest of one is shown beside the i-th longest of the other."""
    def spans(text, slices):
        if len(slices) < 2:    # no overlap: copydetect gives an empty array
            return []
        out = [(int(s), int(e)) for s, e in zip(slices[0], slices[1]) if e > s]
        return sorted(out, key=lambda se: (se[0] - se[1], se[0]))[:MAX_PASSAGES]
    found = []
    for (sa, ea), (sb, eb) in zip(spans(text_a, slices_a), spans(text_b, slices_b)):
        found.append({"a_lines": [_line(text_a, sa), _line(text_a, ea - 1)],
                      "b_lines": [_line(text_b, sb), _line(text_b, eb - 1)],
                      "a_text": text_a[sa:ea][:MAX_PASSAGE_CHARS], "b_text": text_b[sb:eb][:MAX_PASSAGE_CHARS]})
    return sorted(found, key=lambda p: p["a_lines"][0])


def compare_sources(sources: dict[str, str], boilerplate: str | None = None,
                    min_listed: float = MIN_LISTED, max_pairs: int = MAX_PAIRS) -> dict:
    """{student: source text} -> the similarity data described above."""
    tool, CodeFingerprint, compare_files = _copydetect()
    bp_hashes = None
    if boilerplate:
        import numpy as np
        # Every k-gram of the template (window 1), as copydetect builds its boilerplate.
        bp = CodeFingerprint("EnvironmentMap.cpp", NOISE_TOKENS, 1, language="cpp", fp=io.StringIO(boilerplate))
        bp_hashes = np.unique(np.array(list(bp.hashes)))
    prints, not_compared = {}, []
    for student, text in sources.items():
        fp = _fingerprint(CodeFingerprint, text, bp_hashes)
        if fp.token_coverage == 0:
            not_compared.append({"student": student, "reason": NOTHING_OF_ITS_OWN})
        else:
            prints[student] = fp
    pairs = []
    names = sorted(prints)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            shared, (share_a, share_b), (slices_a, slices_b) = compare_files(prints[a], prints[b])
            similarity = max(float(share_a), float(share_b))
            if similarity >= min_listed:
                pairs.append({"a": a, "b": b, "similarity": round(similarity, 4),
                              "share_a": round(float(share_a), 4), "share_b": round(float(share_b), 4),
                              "shared_tokens": int(shared),
                              "passages": _passages(sources[a], slices_a, sources[b], slices_b)})
    pairs.sort(key=lambda p: (-p["similarity"], p["a"], p["b"]))
    return {"tool": tool, "boilerplate": _rel(BOILERPLATE) if boilerplate else None,
            "noise_tokens": NOISE_TOKENS, "guarantee_tokens": GUARANTEE_TOKENS, "compared": len(prints),
            "min_listed": min_listed, "not_compared": not_compared, "pairs": pairs[:max_pairs]}


def _rel(path: Path) -> str:
    try:
        return path.relative_to(PROJECT_ROOT).as_posix()
    except ValueError:
        return str(path)


def class_similarity(submissions: dict[str, Path], out: Path | None = None) -> dict:
    """Read each submission's EnvironmentMap.cpp the way grading does
    (grader/intake.py: archives, caps, no links followed) and compare
    them all. A submission whose source cannot be found is not compared
    (its own report says why)."""
    from ..intake import SubmissionError, select_source
    sources, unread = {}, []
    for student, path in submissions.items():
        try:
            chosen = select_source(path, PROJECT_ROOT / "student_template")
        except SubmissionError as e:
            unread.append({"student": student, "reason": str(e)})
            continue
        sources[student] = chosen.text.decode("utf-8", errors="replace")
    boilerplate = BOILERPLATE.read_text(encoding="utf-8", errors="replace") if BOILERPLATE.is_file() else None
    data = compare_sources(sources, boilerplate)
    data["not_compared"] = unread + data["not_compared"]
    return data
