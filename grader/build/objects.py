"""What a build made, read as hostile bytes: the student's object and the
linked library, by our own bounds-checked ELF reader (no tool parses them),
against the symbols the runtime libraries and our loader define.
"""
from __future__ import annotations

import functools
import os
import re
import struct
import subprocess
from pathlib import Path

from ..i18n import _, ngettext
from ..intake import SOURCE_NAME
from .compiler import CXX, limited

# ---- the libraries a submission may call -----------------------------------------

# Once, for both walls: the symbols a student's object may leave undefined are
# those these define, and the linked library may need (DT_NEEDED) only these.
RUNTIME_LIBRARIES = ("libc.so.6", "libm.so.6", "libmvec.so.1", "libstdc++.so.6", "libgcc_s.so.1",
                     "ld-linux-x86-64.so.2", "ld-linux-aarch64.so.1")
# Sanitized builds (tests): also these, by prefix (the soname carries a version).
SANITIZER_LIBRARIES = ("libasan.so", "libubsan.so")
# Defined by the linker or the C runtime start files rather than a library.
LINKER_SYMBOLS = {"_GLOBAL_OFFSET_TABLE_", "__dso_handle", "_DYNAMIC", "__tls_get_addr",
                   "_ITM_registerTMCloneTable", "_ITM_deregisterTMCloneTable", "__gmon_start__"}


@functools.lru_cache(maxsize=None)
def runtime_library_paths(sanitize: bool) -> tuple[Path, ...]:
    paths = []
    for name in RUNTIME_LIBRARIES + (SANITIZER_LIBRARIES if sanitize else ()):
        out = subprocess.run([CXX, f"-print-file-name={name}"], capture_output=True, text=True,
                             stdin=subprocess.DEVNULL).stdout.strip()
        if out and os.path.isabs(out) and os.path.isfile(out):
            paths.append(Path(os.path.realpath(out)))
    libgcc = subprocess.run([CXX, "-print-libgcc-file-name"], capture_output=True, text=True,
                            stdin=subprocess.DEVNULL).stdout.strip()
    if libgcc and os.path.isfile(libgcc):
        paths.append(Path(os.path.realpath(libgcc)))
    return tuple(paths)


def defined_symbols(paths: tuple[Path, ...]) -> set[str]:
    """Global symbols defined by our trusted runtime libraries (nm)."""
    names: set[str] = set()
    for path in paths:
        dynamic = ["-D"] if ".so" in path.name else []
        out = subprocess.run(["nm", *dynamic, "-g", "--defined-only", str(path)], capture_output=True,
                             text=True, stdin=subprocess.DEVNULL).stdout
        for line in out.splitlines():
            parts = line.split()
            if len(parts) >= 3:
                names.add(parts[-1].split("@")[0])
    return names


# ---- reading the student's object (hostile bytes: bounds-checked, no tool) --------

class _BadObject(Exception):
    pass


def object_symbols(data: bytes) -> tuple[list[str], list[tuple[str, int, bool]], list[int]]:
    """(section names, [(symbol name, binding, defined)], section flags) of
    an ELF64 little-endian relocatable object."""
    sections, symbols, flags, _ = _parse_elf(data, 1)
    return sections, [(name, bind, defined) for name, bind, defined, _ in symbols], flags


def _library_imports(data: bytes) -> tuple[list[str], list[str]]:
    """(DT_NEEDED libraries, undefined dynamic symbols) of an ELF64 shared object."""
    _, symbols, _, needed = _parse_elf(data, 3)
    return needed, sorted({name for name, _, defined, table in symbols if table == 11 and not defined})


def _parse_elf(data: bytes, e_type_wanted: int) -> tuple[list[str], list[tuple[str, int, bool, int]],
                                                         list[int], list[str]]:
    """Sections, symbols (name, binding, defined, table type), section flags
    and DT_NEEDED names of an ELF64 little-endian file, every offset checked."""
    try:
        if data[:4] != b"\x7fELF" or data[4] != 2 or data[5] != 1:
            raise _BadObject("not a 64-bit little-endian ELF object")
        e_type, = struct.unpack_from("<H", data, 16)
        if e_type != e_type_wanted:
            raise _BadObject("not a relocatable object" if e_type_wanted == 1 else "not a shared object")
        shoff, = struct.unpack_from("<Q", data, 0x28)
        shentsize, shnum, shstrndx = struct.unpack_from("<HHH", data, 0x3A)
        if shentsize != 64:
            raise _BadObject("unexpected section header size")

        def header(i: int) -> tuple:
            if not 0 <= i or shoff + 64 * (i + 1) > len(data):
                raise _BadObject("section header out of bounds")
            return struct.unpack_from("<IIQQQQIIQQ", data, shoff + 64 * i)
        if shoff and shnum == 0:
            shnum = header(0)[5]
        if shstrndx == 0xFFFF:
            shstrndx = header(0)[6]
        if shnum > 1 << 20:
            raise _BadObject("too many sections")
        headers = [header(i) for i in range(shnum)]

        def body(h: tuple) -> bytes:
            offset, size = h[4], h[5]
            if h[1] == 8:  # SHT_NOBITS
                return b""
            if offset + size > len(data):
                raise _BadObject("section out of bounds")
            return data[offset:offset + size]

        def string(table: bytes, at: int) -> str:
            if at >= len(table):
                raise _BadObject("name out of bounds")
            end = table.find(b"\0", at)
            return table[at:end if end >= 0 else len(table)].decode("utf-8", "surrogateescape")

        def linked(h: tuple) -> bytes:
            return body(headers[h[6]]) if h[6] < shnum else b""

        names_table = body(headers[shstrndx]) if shnum else b""
        sections = [string(names_table, h[0]) for h in headers]
        symbols, needed = [], []
        for h in headers:
            if h[1] in (2, 11):  # SHT_SYMTAB, SHT_DYNSYM
                table, strings = body(h), linked(h)
                for at in range(24, len(table) - 23, 24):  # entry 0 is the null symbol
                    st_name, st_info, _, st_shndx, _, _ = struct.unpack_from("<IBBHQQ", table, at)
                    kind = st_info & 0xF
                    if st_name == 0 or kind in (3, 4):  # STT_SECTION, STT_FILE
                        continue
                    symbols.append((string(strings, st_name), st_info >> 4, st_shndx != 0, h[1]))
            elif h[1] == 6:  # SHT_DYNAMIC: (d_tag, d_val) pairs, DT_NEEDED = 1
                table, strings = body(h), linked(h)
                for at in range(0, len(table) - 15, 16):
                    tag, value = struct.unpack_from("<qQ", table, at)
                    if tag == 0:
                        break
                    if tag == 1:
                        needed.append(string(strings, value))
        return sections, symbols, [h[2] for h in headers], needed
    except (struct.error, IndexError, ValueError) as exc:
        raise _BadObject(f"malformed object ({exc})") from None


def inspect_library(data: bytes, allowed: set[str], sanitize: bool) -> tuple[str, str] | None:
    """The linked library, checked as the worker will load it: it needs only
    the runtime libraries and imports only what they (and the linker) define."""
    try:
        needed, undefined = _library_imports(data)
    except _BadObject as exc:
        return "forbidden-object", _("The library built from %(source)s could not be checked: %(why)s.") % {"source": SOURCE_NAME, "why": exc}
    odd = [n for n in needed if n not in RUNTIME_LIBRARIES and not (sanitize and n.startswith(SANITIZER_LIBRARIES))]
    unknown = [n for n in undefined if n not in allowed]
    if odd or unknown:
        return "forbidden-object", (_("The library built from %(source)s needs %(names)s, "
                                      "which is neither the C/C++ runtime nor the grader's own code.") % {"source": SOURCE_NAME, "names": _listed(odd + unknown)})
    return None


# Sections g++ writes for ordinary C++ (with -g and sanitizers too).
_ORDINARY_SECTION = re.compile(r"""^(
    | \.(text|data|bss|rodata|tdata|tbss|ldata|lbss|lrodata)(\..+)?
    | \.data\.rel\.ro(\..+)? | \.data\.rel(\..+)?
    | \.(init_array|fini_array|preinit_array|ctors|dtors)(\.\d+)?
    | \.eh_frame | \.gcc_except_table(\..+)?
    | \.comment | \.note\.GNU-stack | \.note\.gnu\.property
    | \.group | \.symtab | \.strtab | \.shstrtab | \.symtab_shndx
    | \.debug_\w+ | \.zdebug_\w+
    | \.rela?\.(text|data|bss|rodata|tdata|ldata|lrodata|init_array|fini_array|preinit_array|ctors|dtors
               |eh_frame|gcc_except_table|debug_\w+|data\.rel\.ro|data\.rel)(\..+)?
)$""", re.X)
# Assembler directives that read files or build other directives out of
# text (which would get past any check of the source).
ASSEMBLER_FORBIDDEN = re.compile(r"\.(incbin|include|macro|irpc?|rept|altmacro|purgem|exitm)\b", re.I)


def _listed(names, limit: int = 5) -> str:
    """Names from the object (the student's: any length, any characters),
    shortened for a message."""
    names = list(names)
    shown = [repr(n[:80] + "...") if len(n) > 80 else (n if n.isprintable() else repr(n)) for n in names[:limit]]
    return ", ".join(shown) + (_(" and %(count)d more") % {"count": len(names) - limit} if len(names) > limit else "")


def _demangle(names: list[str]) -> list[str]:
    """C++ names as the source spells them; only short printable ones are
    given to c++filt (a hostile mangled name could make a demangler recurse
    for long), in a limited process."""
    if not all(len(n) <= 200 and n.isprintable() for n in names):
        return names
    try:
        done = subprocess.run(limited(["c++filt"], 5), input="\n".join(names), capture_output=True,
                              text=True, timeout=5)
        shown = done.stdout.splitlines()
        return shown if len(shown) == len(names) and done.returncode == 0 else names
    except (OSError, subprocess.SubprocessError):
        return names


def inspect_object(data: bytes, allowed: set[str], loader_names: frozenset[str] = frozenset()
                   ) -> tuple[str, str] | None:
    """(diagnosis id, message) when the student's object is refused, else None.
    `allowed`: what it may leave undefined; `loader_names`: global names of
    the reference code linked for the loader, which it may not define."""
    name = SOURCE_NAME
    try:
        sections, symbols, flags = object_symbols(data)
    except _BadObject as exc:
        return "forbidden-object", _("The compiled %(source)s could not be checked: %(why)s.") % {"source": name, "why": exc}
    # SHF_WRITE | SHF_EXECINSTR: code that can be rewritten while it runs; no compiler makes it.
    writable_code = sorted({n for n, f in zip(sections, flags) if f & 0x1 and f & 0x4})
    if writable_code:
        return "forbidden-object", (
            _("%(source)s makes sections that are both writable and executable "
              "(%(sections)s): remove the asm or attributes that "
              "create them.") % {"source": name, "sections": _listed(writable_code, 3)})
    lto = [s for s in sections if "lto" in s.lower()]
    if lto:
        return "forbidden-object", (
            _("%(source)s carries link-time-optimisation sections (%(sections)s): "
              "code the grader cannot see in your source. The grader builds without LTO; "
              "remove the asm or attributes that create these sections.") % {"source": name, "sections": _listed(sorted(set(lto)), 3)})
    odd = sorted({s for s in sections if not _ORDINARY_SECTION.match(s)})
    if odd:
        return "forbidden-object", (
            _("%(source)s puts code or data in sections a C++ compiler does not make "
              "(%(sections)s). Remove the section attributes or asm "
              "that create them.") % {"source": name, "sections": _listed(odd)})
    undefined = sorted({s for s, _, defined in symbols if not defined})
    reference = [s for s in undefined if s.startswith("em_")]
    if reference:
        return "calls-reference", (
            ngettext("%(source)s calls %(names)s: this is a function of the grader's "
                     "reference solution, which is not part of your program. fetchColor and readTexture must "
                     "compute their answers with your own code.",
                     "%(source)s calls %(names)s: these are functions of the grader's "
                     "reference solution, which is not part of your program. fetchColor and readTexture must "
                     "compute their answers with your own code.", len(reference)) % {"source": name, "names": _listed(reference)})
    replaced = sorted({s for s, bind, defined in symbols if defined and bind == 1 and s in loader_names})
    if replaced:
        return "forbidden-object", (
            _("%(source)s defines %(names)s, which the grader's own loader code defines: "
              "yours would replace it. Rename your function or make it static.") % {"source": name, "names": _listed(replaced)})
    unknown = [s for s in undefined if s not in allowed]
    if unknown:
        shown = _demangle(unknown[:5])
        return "forbidden-object", (
            ngettext("%(source)s uses %(names)s, which is neither in the C/C++ standard library nor in "
                     "EnvironmentMap.h: define it in your file, or use only the standard library.",
                     "%(source)s uses %(names)s, which are neither in the C/C++ standard library nor in "
                     "EnvironmentMap.h: define it in your file, or use only the standard library.",
                     len(unknown)) % {"source": name, "names": _listed(shown + unknown[5:])})
    return None
