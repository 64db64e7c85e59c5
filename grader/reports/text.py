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
# Lone surrogates (from undecodable bytes) and the noncharacters U+FFFE,
# U+FFFF: not valid in XML 1.0, and not text anyway.
_NON_TEXT = re.compile("[\ud800-\udfff\ufffe\uffff]")
# Bidirectional embeddings, overrides and isolates: they make a submission's
# text display in another order than it reads ("Trojan source").
_BIDI = re.compile("[\u202a-\u202e\u2066-\u2069]")
# Characters that start inline markup or raw HTML anywhere in a line.
_MD_SPECIAL = re.compile(r"([\\`*_\[\]<>|~&])")
# What GitHub's autolink extension turns into a link without any markup:
# "scheme://" and "www." (an escape breaks them) and e-mail addresses (it
# links them whatever the escaping: they become code spans instead).
_AUTOLINK = re.compile(r"(?i)(?<=[a-z0-9])(:)(?=//)|\b(www)(\.)")
_EMAIL = re.compile(r"[\w.+-]+@[\w-]+(?:\.[\w-]+)+")
# numpy's repr of a vector, e.g. "[16. 16.  1.]" or "[ 1.5e-01 -2.0e+00]".
_NUMPY_VECTOR = re.compile(
    r"\[\s*((?:[-+]?(?:\d+\.?\d*(?:e[-+]?\d+)?|nan|inf)\s+)+[-+]?(?:\d+\.?\d*(?:e[-+]?\d+)?|nan|inf))\s*\]")


def clean(text: str) -> str:
    """Text without ANSI escapes or control characters, valid UTF-8."""
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    text = _ANSI.sub("", text)
    text = _CONTROL.sub("\ufffd", text)
    text = _BIDI.sub("\ufffd", text)
    return _NON_TEXT.sub("\ufffd", text)


def md_escape(text: str, line_start: bool = False) -> str:
    """Plain text as inline Markdown: the characters that could start markup
    or raw HTML are backslash-escaped (CommonMark allows that for all ASCII
    punctuation) and newlines become spaces. With line_start, a leading
    block marker (#, >, -, +, =, "1.") is escaped too. Nothing in it can
    become a link, not even on GitHub: e-mail addresses are code spans."""
    text = clean(text).replace("\n", " ")
    parts = _EMAIL.split(text)
    emails = [md_code(m) for m in _EMAIL.findall(text)]
    text = "".join(_escape_inline(p) + (emails[i] if i < len(emails) else "") for i, p in enumerate(parts))
    if line_start:
        text = re.sub(r"^(\s*)([#>+\-=])", r"\1\\\2", text)
        text = re.sub(r"^(\s*\d+)([.)])", r"\1\\\2", text)
    return text


def _escape_inline(text: str) -> str:
    text = _MD_SPECIAL.sub(r"\\\1", text)
    return _AUTOLINK.sub(lambda m: f"\\{m.group(1)}" if m.group(1) else f"{m.group(2)}\\.", text)


def md_fence(text: str, info: str = "") -> str:
    """A fenced code block that no backtick run inside `text` can close."""
    longest = max((len(m) for m in re.findall(r"`+", text)), default=0)
    fence = "`" * max(3, longest + 1)
    return f"{fence}{info}\n{clean(text).rstrip()}\n{fence}"


def md_code(text: str) -> str:
    """Plain text as one inline code span, which nothing inside can close or
    turn into markup (CommonMark: the span ends at a backtick run of the
    same length; one space of padding each side is stripped)."""
    text = clean(text).replace("\n", " ")
    longest = max((len(m) for m in re.findall(r"`+", text)), default=0)
    ticks = "`" * (longest + 1)
    return f"{ticks} {text} {ticks}" if longest or not text.strip() else f"{ticks}{text}{ticks}"


# Markdown a check may write (CheckResult.output): what the grader's own
# outputs use. Anything else (headings, links, images, raw HTML, quotes,
# code blocks, rules) means text that was not the grader's got in, and the
# whole output is shown literally instead (markdown_is_inert).
_ALLOWED_BLOCKS = {
    "paragraph_open", "paragraph_close", "inline",
    "bullet_list_open", "bullet_list_close", "ordered_list_open", "ordered_list_close",
    "list_item_open", "list_item_close",
    "table_open", "table_close", "thead_open", "thead_close", "tbody_open", "tbody_close",
    "tr_open", "tr_close", "th_open", "th_close", "td_open", "td_close",
}
_ALLOWED_INLINE = {"text", "code_inline", "softbreak", "hardbreak", "em_open", "em_close",
                   "strong_open", "strong_close", "s_open", "s_close"}
# Text GitHub would still link by itself (a URL, www., an e-mail address),
# and text that looks like a tag (a less careful Markdown renderer, such as
# the one behind Gradescope's "md", might pass it on as HTML).
_BARE_LINK = re.compile(r"(?i)[a-z][a-z0-9+.-]*:/?/|\bwww\.|[\w.+-]@[\w-]+\.\w|<[a-z/!?]")
_PARSER = None


def markdown_is_inert(text: str) -> bool:
    """Whether `text` (Markdown) forms nothing but paragraphs, lists, tables,
    emphasis and code spans, and holds no text GitHub would autolink."""
    global _PARSER
    if _PARSER is None:
        from markdown_it import MarkdownIt
        # Raw HTML on, so that it is seen (and refused) rather than shown as text.
        _PARSER = MarkdownIt("commonmark", {"html": True}).enable(["table", "strikethrough"])
    for token in _PARSER.parse(text):
        if token.type not in _ALLOWED_BLOCKS:
            return False
        for child in token.children or []:
            if child.type not in _ALLOWED_INLINE:
                return False
            if child.type == "text" and _BARE_LINK.search(child.content):
                return False
    return True


def inert_markdown(text: str) -> str:
    """A check's Markdown output as it may be shown: itself when inert, else
    the whole text as a literal code block."""
    text = tidy_numbers(clean(text))
    return text if markdown_is_inert(text) else md_fence(text, "text")


def tidy_numbers(text: str) -> str:
    """numpy's vector reprs ("[16. 16.  1.]") as people write them: (16, 16, 1)."""
    def vector(m: re.Match) -> str:
        parts = m.group(1).split()
        try:
            return "(" + ", ".join(figure(float(p)) if "." in p or "e" in p.lower() or "n" in p.lower()
                                   else p for p in parts) + ")"
        except ValueError:
            return m.group(0)
    return _NUMPY_VECTOR.sub(vector, text)


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
