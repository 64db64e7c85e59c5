"""Finding the student's EnvironmentMap.cpp in an upload, without trusting it.

An upload is a folder, a single file, or an archive (.zip, .tar, .tar.gz,
.tar.bz2, .tar.xz). What a file is comes from its first bytes, never from
its name: a .rar renamed .zip is "unknown-format", a zip named
EnvironmentMap.cpp is unpacked as a zip.

Nothing is extracted to disk and no symbolic link is followed. Every read
is capped (bytes per member, bytes in all, members, wall time), so a
decompression bomb, a tar declaring a 1 TiB member or a folder of a
million files ends quickly with a verdict. Anything an archive library
raises on a damaged archive (bad CRC, encryption, unsupported compression,
truncation) becomes SubmissionError("unreadable-archive", ...), never a
traceback.

Every name in a message comes from the upload: it is plain text, escaped
by whoever writes it into a report.
"""
from __future__ import annotations

import bz2
import gzip
import hashlib
import lzma
import os
import re
import stat
import struct
import tarfile
import time
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from .i18n import N_, _

SOURCE_NAME = "EnvironmentMap.cpp"
# A submission holds one small source file: far larger is refused unread.
MAX_SOURCE_BYTES = 1 << 20
MAX_UPLOAD_BYTES = 64 << 20          # the upload file itself (compressed)
MAX_UNPACKED_BYTES = 64 << 20        # bytes read out of an archive in all
MAX_MEMBERS = 20000                  # files (archive members or folder entries)
MAX_UNPACK_SECONDS = 10.0            # wall time spent finding the source
MAX_DEPTH = 32                       # folder levels looked into
# Folders that hold no submission: version control, macOS archive debris.
SKIPPED_DIRS = ("__MACOSX",)
EXPECTED_TEXT = N_("%(source)s itself, a folder holding it, or a .zip, .tar or .tar.gz of either")
EXPECTED = EXPECTED_TEXT % {"source": SOURCE_NAME}   # in English
# The files of an upload that are read at all: sources and headers.
_READ_SUFFIXES = (".cpp", ".h", ".hpp", ".cc", ".cxx")


class SubmissionError(Exception):
    """The upload holds no usable EnvironmentMap.cpp; the message says why
    in words for the student, `diagnosis_id` names the kind of problem
    (grader/grading/catalogue.py)."""

    def __init__(self, diagnosis_id: str, message: str):
        super().__init__(message)
        self.diagnosis_id = diagnosis_id


@dataclass
class ChosenSource:
    text: bytes
    name: str                 # path inside the submission, e.g. "src/EnvironmentMap.cpp"
    origin: Path | None       # the file on disk, None when it came out of an archive
    notes: list[str]


Reader = Callable[[], bytes]   # the bytes of one file of a submission (capped)


# ---- what a file is ----------------------------------------------------------------

# (magic, offset, name): formats recognised by their first bytes.
_MAGIC = [
    (b"PK\x03\x04", 0, "zip"), (b"PK\x05\x06", 0, "zip"), (b"PK\x07\x08", 0, "zip"),
    (b"\x1f\x8b", 0, "gzip"), (b"BZh", 0, "bzip2"), (b"\xfd7zXZ\x00", 0, "xz"),
    (b"ustar", 257, "tar"),
    # Descriptions (marked: messages show them in the student's language, _a()).
    (b"Rar!\x1a\x07", 0, N_("RAR archive")), (b"7z\xbc\xaf\x27\x1c", 0, N_("7-Zip archive")),
    (b"\x28\xb5\x2f\xfd", 0, N_("Zstandard-compressed file")), (b"MSCF", 0, N_("Windows cabinet archive")),
    (b"%PDF", 0, N_("PDF document")), (b"\x7fELF", 0, N_("compiled program or object file (ELF)")),
    (b"\x89PNG", 0, N_("PNG image")), (b"\xff\xd8\xff", 0, N_("JPEG image")),
    (b"\xd0\xcf\x11\xe0", 0, N_("Microsoft Office document")), (b"\xcf\xfa\xed\xfe", 0, N_("Mach-O program")),
    (b"MZ", 0, N_("Windows program")), (b"#?RADIANCE", 0, N_("Radiance .hdr image")),
    (b"\xef\xbb\xbf", 0, "text"),  # UTF-8 byte order mark: text
]
_ARCHIVES = ("zip", "gzip", "bzip2", "xz", "tar")
_NAMED_ARCHIVE = re.compile(r"\.(zip|tar|tgz|tar\.gz|tar\.bz2|tbz2?|tar\.xz|txz|gz|rar|7z)$", re.I)


def sniff(head: bytes) -> str:
    """The format of a file from its first 512 bytes: one of _ARCHIVES,
    "text", "empty", or a description of something else."""
    if not head:
        return "empty"
    for magic, offset, name in _MAGIC:
        if head[offset:offset + len(magic)] == magic:
            return name
    if head[:2] in (b"\xff\xfe", b"\xfe\xff"):
        return N_("UTF-16 text")
    return "text" if is_text(head) else N_("binary data")


def is_text(data: bytes) -> bool:
    """Source text: no NUL byte, few control characters, and UTF-8 (or a
    legacy 8-bit encoding: comments in latin-1 are common and harmless)."""
    if b"\x00" in data:
        return False
    controls = sum(1 for b in data if b < 32 and b not in b"\t\n\r\f\v")
    return controls <= max(2, len(data) // 200)


def _text_problem(data: bytes, name: str) -> str | None:
    """Why `data` (the chosen source) cannot be a C++ source, or None."""
    kind = sniff(data[:512])
    if kind == "text":
        return None
    if kind == "empty":
        return None  # reported as empty-submission by the caller
    if kind == "UTF-16 text":
        return (_("%(name)s is saved as UTF-16 text, which the compiler cannot read: "
                  "save it as UTF-8 (your editor's \"Save with encoding\") and submit it again.") % {"name": name})
    return (_("%(name)s is not a C++ source file: it holds %(what)s (%(size)d bytes). "
              "Expected: %(expected)s.") % {"name": name, "what": _a(kind), "size": len(data), "expected": _expected()})


def _a(kind: str) -> str:
    """A file kind (sniff) with its article, in the student's language."""
    if kind[:1].lower() in "aeiou":
        return _("an %(kind)s") % {"kind": _(kind)}
    return _("a %(kind)s") % {"kind": _(kind)}


def _expected() -> str:
    return _(EXPECTED_TEXT) % {"source": SOURCE_NAME}


# ---- bounded reading ----------------------------------------------------------------

class _Budget:
    """Bytes and seconds left for unpacking one submission."""

    def __init__(self, what: str):
        self.what = what
        self.bytes_left = MAX_UNPACKED_BYTES
        self.deadline = time.monotonic() + MAX_UNPACK_SECONDS

    def spend(self, n: int) -> None:
        self.bytes_left -= n
        if self.bytes_left < 0:
            raise SubmissionError(
                "unreadable-archive",
                _("your archive could not be read: %(what)s holds more than "
                  "%(mib)d MiB once unpacked. Submit %(source)s alone "
                  "(or a small archive of your source files).")
                % {"what": self.what, "mib": MAX_UNPACKED_BYTES >> 20, "source": SOURCE_NAME})
        self.check_time()

    def check_time(self) -> None:
        if time.monotonic() > self.deadline:
            raise SubmissionError(
                "unreadable-archive",
                _("your archive could not be read: unpacking %(what)s took longer than "
                  "%(seconds)s s. Submit %(source)s alone.")
                % {"what": self.what, "seconds": f"{MAX_UNPACK_SECONDS:g}", "source": SOURCE_NAME})


class _CappedStream:
    """A read-only stream that charges every byte it returns to a budget
    (tarfile reads the decompressed stream through it)."""

    def __init__(self, raw, budget: _Budget):
        self.raw, self.budget = raw, budget
        self.empty_reads = 0

    def read(self, size: int = -1) -> bytes:
        if size is None or size < 0:
            size = self.budget.bytes_left + 1
        data = self.raw.read(min(size, self.budget.bytes_left + 1))
        self.budget.spend(len(data))
        # tarfile skips a member by reading up to its declared end, even
        # past the end of the data: a member declaring 1 TiB would take hours.
        if size and not data:
            self.empty_reads += 1
            if self.empty_reads > 8:
                raise EOFError("it ends before the end of a file it declares")
        return data

    def close(self) -> None:
        self.raw.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _read_member(stream, name: str, budget: _Budget) -> bytes:
    with stream:
        data = stream.read(MAX_SOURCE_BYTES + 1)
    budget.spend(len(data))
    if len(data) > MAX_SOURCE_BYTES:
        raise SubmissionError("no-source", _("%(name)s is larger than %(mib)d MiB: "
                                             "not a source file.") % {"name": name, "mib": MAX_SOURCE_BYTES >> 20})
    return data


def _unreadable(where: str, exc: BaseException) -> SubmissionError:
    reason = str(exc).strip() or type(exc).__name__
    if isinstance(exc, RuntimeError) and "encrypted" in reason:
        reason = _("it is encrypted (password-protected); submit it without a password")
    elif isinstance(exc, NotImplementedError) or "compression method" in reason:
        reason = _("it uses a compression method this grader does not read "
                   "(e.g. Deflate64); use the ordinary zip of your system")
    elif isinstance(exc, (EOFError, zlib.error)) or "truncated" in reason.lower() or "end of" in reason:
        reason = _("it is damaged or incomplete (%(reason)s)") % {"reason": reason}
    return SubmissionError("unreadable-archive", _("your archive could not be read: %(where)s: %(reason)s. "
                                                   "Make the archive again and resubmit it.") % {"where": where, "reason": reason})


def _safe_member(name: str) -> str | None:
    """A member path as a relative POSIX path, or None when it is unsafe
    (absolute, '..') or in a folder that holds no submission."""
    parts = [p for p in name.replace("\\", "/").split("/") if p not in ("", ".")]
    if not parts or name.startswith(("/", "\\")) or ".." in parts or re.match(r"^[A-Za-z]:", name):
        return None
    if any(p in SKIPPED_DIRS or p.startswith(".") for p in parts[:-1]):
        return None
    if any(ord(c) < 32 for c in name):
        return None
    return "/".join(parts)


def _wanted(name: str) -> bool:
    return name.lower().endswith(_READ_SUFFIXES)


def _zip_entry_count(path: Path) -> int | None:
    """The member count a zip's end-of-central-directory record declares,
    read before zipfile parses (and allocates for) the whole directory."""
    size = path.stat().st_size
    with path.open("rb") as f:
        f.seek(max(0, size - 65557))
        tail = f.read()
    at = tail.rfind(b"PK\x05\x06")
    if at < 0 or at + 22 > len(tail):
        return None
    count = struct.unpack_from("<H", tail, at + 10)[0]
    if count == 0xFFFF and at >= 20 and tail[at - 20:at - 16] == b"PK\x06\x07":
        # Zip64: the real count is in the zip64 end record the locator points to.
        offset = struct.unpack_from("<Q", tail, at - 12)[0]
        with path.open("rb") as f:
            f.seek(min(offset, size))
            record = f.read(56)
        if record[:4] == b"PK\x06\x06" and len(record) >= 40:
            count = struct.unpack_from("<Q", record, 32)[0]
    return count


def _zip_files(path: Path, budget: _Budget) -> tuple[dict[str, Reader], list[str]]:
    declared = _zip_entry_count(path)
    if declared is not None and declared > MAX_MEMBERS:
        raise SubmissionError("unreadable-archive", _("your archive could not be read: %(name)s "
                                                      "holds more than %(count)d files.") % {"name": path.name, "count": MAX_MEMBERS})
    archive = zipfile.ZipFile(path)
    members = archive.infolist()
    if len(members) > MAX_MEMBERS:
        raise SubmissionError("unreadable-archive", _("your archive could not be read: %(name)s "
                                                      "holds more than %(count)d files.") % {"name": path.name, "count": MAX_MEMBERS})
    files: dict[str, Reader] = {}
    listed: list[str] = []
    cache: dict[str, bytes] = {}
    for info in members:
        mode = info.external_attr >> 16
        is_link = stat.S_IFMT(mode) == stat.S_IFLNK
        name = _safe_member(info.filename)
        if info.is_dir() or is_link or name is None:
            continue
        listed.append(name)
        if not _wanted(name):
            continue

        def read(info=info, name=name) -> bytes:
            if name not in cache:
                if info.file_size > MAX_SOURCE_BYTES:
                    raise SubmissionError("no-source", _("%(name)s is larger than %(mib)d MiB: "
                                                         "not a source file.") % {"name": name, "mib": MAX_SOURCE_BYTES >> 20})
                try:
                    cache[name] = _read_member(archive.open(info), name, budget)
                except SubmissionError:
                    raise
                except Exception as exc:  # any damage the zip library finds
                    raise _unreadable(f"{path.name} ({name})", exc) from None
            return cache[name]
        files[name] = read
    return files, listed


def _tar_files(path: Path, kind: str, budget: _Budget) -> tuple[dict[str, Reader], list[str]]:
    """One sequential pass over a tar (never a seek, never a second pass):
    the sources and headers are read as they pass, every byte counted."""
    opener = {"gzip": gzip.open, "bzip2": bz2.open, "xz": lzma.open}.get(kind, open)
    stream = _CappedStream(opener(path, "rb"), budget)
    contents: dict[str, bytes] = {}
    listed: list[str] = []
    try:
        archive = tarfile.open(fileobj=stream, mode="r|")
    except tarfile.ReadError:
        stream.close()
        if kind in ("gzip", "bzip2", "xz"):
            raise SubmissionError("unknown-format", _("%(name)s is a %(kind)s-compressed file but "
                                  "not a compressed tar archive. Expected: %(expected)s.")
                                  % {"name": path.name, "kind": kind, "expected": _expected()}) from None
        raise
    with stream, archive:
        for count, info in enumerate(archive, 1):
            if count > MAX_MEMBERS:
                raise SubmissionError("unreadable-archive", _("your archive could not be read: %(name)s "
                                                              "holds more than %(count)d files.") % {"name": path.name, "count": MAX_MEMBERS})
            budget.check_time()
            name = _safe_member(info.name)
            if not info.isreg() or info.issparse() or name is None:
                continue
            listed.append(name)
            if _wanted(name) and name not in contents and info.size <= MAX_SOURCE_BYTES:
                contents[name] = _read_member(archive.extractfile(info), name, budget)
    return {name: (lambda data=data: data) for name, data in contents.items()}, listed


def _archive_files(path: Path, kind: str, budget: _Budget) -> tuple[dict[str, Reader], list[str]]:
    """{relative path: reader} of the sources and headers in an archive, and
    every regular file's name (for messages)."""
    if path.stat().st_size > MAX_UPLOAD_BYTES:
        raise SubmissionError("unreadable-archive", _("your archive could not be read: %(name)s is "
                                                      "larger than %(mib)d MiB.") % {"name": path.name, "mib": MAX_UPLOAD_BYTES >> 20})
    try:
        if kind == "zip":
            return _zip_files(path, budget)
        return _tar_files(path, kind, budget)
    except SubmissionError:
        raise
    except Exception as exc:  # BadZipFile, TarError, EOFError, zlib/lzma errors, ...
        raise _unreadable(path.name, exc) from None


def _open_regular(path: Path):
    """A regular file opened without following a symbolic link (and without
    blocking on a FIFO), or None."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        return None
    return os.fdopen(fd, "rb")


def _folder_files(path: Path, budget: _Budget) -> tuple[dict[str, Reader], list[str]]:
    """Regular files below a folder (symbolic links neither followed nor read)."""
    files: dict[str, Reader] = {}
    listed: list[str] = []
    count = 0
    for dirpath, dirnames, filenames in os.walk(path):  # does not descend into links
        # Deeper than any project (os.walk recurses: a folder 2000 deep would overflow).
        deep = len(Path(dirpath).relative_to(path).parts) >= MAX_DEPTH
        dirnames[:] = [] if deep else sorted(d for d in dirnames
                                             if d not in SKIPPED_DIRS and not d.startswith("."))
        budget.check_time()
        for filename in sorted(filenames):
            count += 1
            if count > MAX_MEMBERS:
                raise SubmissionError("unreadable-archive", _("the folder %(name)s holds more than "
                                                              "%(count)d files.") % {"name": path.name, "count": MAX_MEMBERS})
            full = Path(dirpath) / filename
            if full.is_symlink() or not full.is_file():
                continue
            name = full.relative_to(path).as_posix()
            listed.append(name)
            if not _wanted(name):
                continue

            def read(full=full, name=name) -> bytes:
                stream = _open_regular(full)
                if stream is None:
                    raise SubmissionError("no-source", _("%(name)s cannot be read.") % {"name": name})
                return _read_member(stream, name, budget)
            files[name] = read
    return files, listed


# ---- choosing the file ------------------------------------------------------------

def _depth_then_name(name: str) -> tuple[int, str]:
    return (name.count("/"), name)


def _holds(listed: list[str]) -> str:
    shown = sorted(listed, key=_depth_then_name)[:10]
    more = _(" and %(count)d more") % {"count": len(listed) - len(shown)} if len(listed) > len(shown) else ""
    return ", ".join(shown) + more


def _choose(files: dict[str, Reader], listed: list[str], where: str) -> tuple[str, list[str]]:
    """The member to grade and the notes that explain the choice."""
    if not listed:
        raise SubmissionError("empty-submission", _("%(where)s is empty: there is nothing to grade. "
                                                    "Expected: %(expected)s.") % {"where": where, "expected": _expected()})
    exact = sorted((n for n in files if n.rsplit("/", 1)[-1] == SOURCE_NAME), key=_depth_then_name)
    if exact:
        notes = []
        if len(exact) > 1:
            same = len({files[n]() for n in exact}) == 1
            notes.append(f"{where} holds {len(exact)} files named {SOURCE_NAME} ({', '.join(exact)}); "
                         f"used {exact[0]}, the one nearest the top (ties: alphabetical order)"
                         + ("; they are identical." if same else "."))
        return exact[0], notes
    other_case = sorted((n for n in files if n.rsplit("/", 1)[-1].lower() == SOURCE_NAME.lower()),
                        key=_depth_then_name)
    if other_case:
        return other_case[0], [f"used {other_case[0]} as {SOURCE_NAME} (the name differs in case)."]

    # A renamed file (e.g. "EnvironmentMap (1).cpp"): the one .cpp that defines fetchColor.
    def defines_fetch_color(name: str) -> bool:
        try:
            return b"EnvironmentMap::fetchColor" in files[name]()
        except SubmissionError as exc:
            if exc.diagnosis_id == "unreadable-archive":
                raise
            return False
    defining = [n for n in sorted(files, key=_depth_then_name)
                if n.endswith(".cpp") and defines_fetch_color(n)]
    if len(defining) == 1:
        return defining[0], [f"no file is named {SOURCE_NAME}; used {defining[0]}, "
                             "the only .cpp file that defines EnvironmentMap::fetchColor."]
    raise SubmissionError("no-source", _("No %(source)s in %(where)s (it holds: %(files)s). "
                                         "Expected: %(expected)s.")
                          % {"source": SOURCE_NAME, "where": where, "files": _holds(listed), "expected": _expected()})


def _header_notes(files: dict[str, Reader], chosen: str, template: Path) -> list[str]:
    """Our headers submitted beside the source: used never, reported when changed."""
    folder = chosen.rsplit("/", 1)[0] + "/" if "/" in chosen else ""
    notes = []
    for ours in sorted(template.glob("*.h")):
        theirs = files.get(folder + ours.name)
        if theirs is None:
            continue

        def normal(text: bytes) -> list[bytes]:
            return [line.rstrip() for line in text.replace(b"\r\n", b"\n").strip().split(b"\n")]
        try:
            differs = normal(theirs()) != normal(ours.read_bytes())
        except SubmissionError:
            differs = True
        if differs:
            notes.append(f"submitted {ours.name} differs from ours: ignored "
                         f"(the grader builds with the template's {ours.name}).")
    return notes


def _checked(chosen: ChosenSource) -> ChosenSource:
    problem = _text_problem(chosen.text, chosen.name)
    if problem:
        raise SubmissionError("unknown-format", problem)
    if not chosen.text.strip():
        raise SubmissionError("empty-submission", _("%(name)s is empty: there is nothing to grade.") % {"name": chosen.name})
    return chosen


def _only_archive(folder: Path, sources: dict[str, Reader]) -> Path | None:
    """The one archive at the top of a folder that holds no source file
    (one level: an archive's own archives are not opened)."""
    if sources:
        return None
    found = [p for p in sorted(folder.iterdir()) if _NAMED_ARCHIVE.search(p.name) and not p.is_symlink() and p.is_file()]
    return found[0] if len(found) == 1 else None


def select_source(path: Path, template: Path) -> ChosenSource:
    """Find the student's EnvironmentMap.cpp in a folder, file or archive.
    `template` is the folder of our headers (to note changed copies)."""
    path = Path(path)
    if path.is_symlink():
        raise SubmissionError("no-source", _("%(name)s is a symbolic link: submit the file itself.") % {"name": path.name})
    if path.is_dir():
        where = _("the folder %(name)s") % {"name": path.name}
        budget = _Budget(where)
        files, listed = _folder_files(path, budget)
        archive = _only_archive(path, files)
        if archive is not None:   # Gradescope and Moodle put an uploaded zip in a folder
            chosen = select_source(archive, template)
            chosen.notes.insert(0, f"graded {archive.name}, the archive in {path.name}.")
            return chosen
        name, notes = _choose(files, listed, where)
        return _checked(ChosenSource(files[name](), name, path / name,
                                     notes + _header_notes(files, name, template)))
    stream = _open_regular(path)
    if stream is None:
        if not path.exists():
            raise SubmissionError("no-source", _("%(name)s does not exist.") % {"name": path.name})
        raise SubmissionError("unknown-format", _("%(name)s is not a regular file. Expected: %(expected)s.")
                              % {"name": path.name, "expected": _expected()})
    with stream:
        head = stream.read(512)
    kind = sniff(head)
    if kind == "empty":
        raise SubmissionError("empty-submission", _("%(name)s is empty (0 bytes): there is nothing "
                                                    "to grade. Expected: %(expected)s.") % {"name": path.name, "expected": _expected()})
    if kind in _ARCHIVES:
        budget = _Budget(path.name)
        files, listed = _archive_files(path, kind, budget)
        name, notes = _choose(files, listed, path.name)
        return _checked(ChosenSource(files[name](), name, None,
                                     notes + _header_notes(files, name, template)))
    if kind != "text" or _NAMED_ARCHIVE.search(path.name):
        what = _a(kind) if kind != "text" else _("text, not an archive")
        raise SubmissionError("unknown-format", _("%(name)s is %(what)s: the grader cannot read it. "
                                                  "Expected: %(expected)s.") % {"name": path.name, "what": what, "expected": _expected()})
    stream = _open_regular(path)
    if stream is None:
        raise SubmissionError("no-source", _("%(name)s cannot be read.") % {"name": path.name})
    text = _read_member(stream, path.name, _Budget(path.name))
    notes = [] if path.name == SOURCE_NAME else [f"graded {path.name} as {SOURCE_NAME}."]
    return _checked(ChosenSource(text, path.name if path.suffix == ".cpp" else SOURCE_NAME, path, notes))


def hash_submission(path: Path) -> str:
    """sha256 over a submission's regular files (names and contents),
    symbolic links and special files skipped, for grade-all's resume key;
    like select_source, bounded in files and never following a link."""
    path = Path(path)
    h = hashlib.sha256()
    if path.is_dir():
        entries = []
        for dirpath, dirnames, filenames in os.walk(path):
            if len(Path(dirpath).relative_to(path).parts) >= MAX_DEPTH:
                dirnames.clear()
            dirnames.sort()
            entries += [Path(dirpath) / f for f in sorted(filenames)]
            if len(entries) > MAX_MEMBERS:
                break
        items = [(f.relative_to(path).as_posix(), f) for f in entries[:MAX_MEMBERS]]
    else:
        items = [("", path)]
    for name, f in items:
        stream = _open_regular(f)
        if stream is None:
            continue
        h.update(name.encode("utf-8", "surrogateescape") + b"\0")
        with stream:
            digest = hashlib.sha256()
            for block in iter(lambda: stream.read(1 << 20), b""):
                digest.update(block)
        h.update(digest.digest())
    return h.hexdigest()


# ---- naming a submission ---------------------------------------------------

# Entries graded as submissions besides folders: archives and sources in any
# format the grader reads or can name (sniff() above tells what a
# file really is; a .rar or .7z gets its own verdict). Longest first, so
# "alice.tar.gz" is alice.
SUFFIXES = (".tar.bz2", ".tar.gz", ".tar.xz", ".tbz2", ".tgz", ".txz", ".zip", ".tar", ".tbz", ".gz", ".bz2",
            ".xz", ".rar", ".7z", ".cpp", ".cc", ".cxx")


def student_name(path: Path) -> str:
    name = path.name
    for suffix in SUFFIXES:
        if name.lower().endswith(suffix):
            return name[: -len(suffix)]
    return name
