"""Text helpers shared by the reports: make captured text safe to embed, and
format numbers the same way everywhere.

Compiler messages and program output are the student's: they may hold ANSI
colour codes, control bytes, lone surrogates or backticks. Every report runs
them through clean() first; each format then escapes for itself.
"""
from __future__ import annotations

import math
import re

_ANSI = re.compile(r"\x1b(?:\[[0-?]*[ -/]*[@-~]|\][^\x07\x1b]*(?:\x07|\x1b\\)|[@-Z\\-_])")
# C0 controls except tab and newline, DEL, and C1 controls: invalid in XML 1.0
# or invisible and confusing in HTML.
_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")
# Characters that start inline markup or raw HTML anywhere in a line.
_MD_SPECIAL = re.compile(r"([\\`*_\[\]<>|~&])")


def clean(text: str) -> str:
    """Text without ANSI escapes or control characters, valid UTF-8."""
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    text = _ANSI.sub("", text)
    text = _CONTROL.sub("\ufffd", text)
    # Lone surrogates (from undecodable bytes) cannot be written as UTF-8.
    return text.encode("utf-8", "replace").decode("utf-8")


def md_escape(text: str, line_start: bool = False) -> str:
    """Plain text as inline Markdown: the characters that could start markup
    or raw HTML are backslash-escaped (CommonMark allows that for all ASCII
    punctuation) and newlines become spaces. With line_start, a leading
    block marker (#, >, -, +, =, "1.") is escaped too."""
    text = _MD_SPECIAL.sub(r"\\\1", clean(text).replace("\n", " "))
    if line_start:
        text = re.sub(r"^(\s*)([#>+\-=])", r"\1\\\2", text)
        text = re.sub(r"^(\s*\d+)([.)])", r"\1\\\2", text)
    return text


def md_fence(text: str, info: str = "") -> str:
    """A fenced code block that no backtick run inside `text` can close."""
    longest = max((len(m) for m in re.findall(r"`+", text)), default=0)
    fence = "`" * max(3, longest + 1)
    return f"{fence}{info}\n{clean(text).rstrip()}\n{fence}"


def points(value: float) -> str:
    """Points as people write them: 20, 12.5, 3.33."""
    if not math.isfinite(value):
        return str(value)
    text = f"{value:.2f}".rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def figure(value: float) -> str:
    """A measured figure with four significant digits (0.9912, 1.23e-05)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value)
    if isinstance(value, int):
        return str(value)
    if not math.isfinite(value):
        return str(value)
    return f"{value:.4g}"


def seconds(value: float) -> str:
    return f"{value:.1f} s" if value >= 1 else f"{value * 1000:.0f} ms"


def truncate_middle(text: str, limit: int = 20000) -> str:
    """Keep the head and the tail of a long text, say how much was left out."""
    if len(text) <= limit:
        return text
    head, tail = text[: limit // 2], text[-(limit // 2):]
    left_out = len(text) - len(head) - len(tail)
    return f"{head}\n[... {left_out} characters left out ...]\n{tail}"
