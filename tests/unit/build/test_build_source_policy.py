"""The source policy (grader/build/source_policy.py) on the compiler's own -E
output, each wall on its own: the text half (source_policy.refused_constructs), the
token half (source_policy.refusals on real g++ -E output, without the text
half in front of it) and the assembly as a second wall (the token half
switched off).
"""
from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from grader import build
from grader.build import source_policy
from grader.build import build_submission
from grader.build.source_policy import refused_constructs
from project_paths import SUBMISSIONS

ATTACKS = SUBMISSIONS / "attacks"
BODY = (SUBMISSIONS / "correct" / "idiomatic.cpp").read_text()


def preprocessed(tmp_path: Path, text: str) -> str:
    """g++ -E of `text` as EnvironmentMap.cpp, as the build runs it."""
    (tmp_path / "EnvironmentMap.cpp").write_text(text)
    done = subprocess.run(["g++", "-std=c++17", "-E", "EnvironmentMap.cpp"], cwd=tmp_path, capture_output=True,
                          text=True)
    return done.stdout


@pytest.mark.parametrize("text, line, word", [
    ('#line 19 "/etc/hostname"\n#pragma GCC warning "x"\nint a;\n', 1, "#line naming another file"),
    ('int a;\n%:line 40 "/etc/hostname"\nint b;\n', 2, "#line naming another file"),
    ('#define F "/etc/hostname"\n#line 7 F\n', 2, "#line naming another file"),
    ('#define GLUE(a, b) a##b\n#define S(x) GLUE(_Pra, gma)(#x)\nS(GCC optimize("O0"))\n', 3, "#pragma GCC optimize"),
    ('#define GLUE(a, b) a##b\nGLUE(__as, m__)("nop");\n', 2, "__asm__"),
    ('void f() { asm volatile goto("" :::: l); l:; }\n', 1, "asm"),
    ('int x <:<:gnu::section(".x"):>:> = 1;\n', 1, "section"),
    ('int y __attribute__((__alias__("x")));\n', 1, "__alias__"),
    ('#ident "text into the assembly"\n', 1, "#ident"),
    ('const char* r = R"(\n)";\nasm("nop");\n', 3, "asm"),   # a raw string across lines keeps the count
])
def test_the_token_half_alone_refuses(tmp_path, text, line, word):
    found = source_policy.refusals(preprocessed(tmp_path, "#include <cmath>\n" + text), "EnvironmentMap.cpp")
    assert found, text
    # A #line is seen where GCC writes its marker: at the line or just before.
    assert found[0][0] in (line, line + 1) and word in found[0][1], found


def test_a_raw_string_holding_a_line_marker_hides_nothing(tmp_path):
    text = 'const char* r = R"x(\n# 1 "/usr/include/stdio.h" 1 3\n)x";\nasm("nop");\n'
    found = source_policy.refusals(preprocessed(tmp_path, text), "EnvironmentMap.cpp")
    assert found and found[0][0] == 4 and "asm" in found[0][1]


def test_a_line_marker_made_by_a_macro_never_compiles(tmp_path):
    # A '#' from a macro at the start of an -E line reads as a line marker
    # (GCC itself takes it for one in the .ii), so the policy cannot see the
    # asm after it: the build compiles the source, where it is a stray '#'.
    text = '#include "EnvironmentMap.h"\n#define H #\nH 1 "/usr/include/stdio.h" 1 3\n'
    text += 'asm(".pushsection .rodata; .string \\"smuggled\\"; .popsection");\n' + BODY.split("\n", 1)[1]
    out = preprocessed(tmp_path, text)
    assert source_policy.refusals(out, "EnvironmentMap.cpp") == []   # hidden from the policy...
    (tmp_path / "EnvironmentMap.cpp").write_text(text)
    result = build_submission(tmp_path / "EnvironmentMap.cpp", cache_dir=tmp_path / "cache")
    assert not result.ok and result.diagnosis_id == "build-error" and "stray" in result.log  # ...never built


def test_system_headers_may_use_asm_and_pragmas(tmp_path):
    # <cmath>, <vector>, <algorithm> hold __asm__ renames and GCC visibility pragmas.
    text = "#include <cmath>\n#include <vector>\n#include <algorithm>\n#include <bits/stdc++.h>\n" + BODY
    out = preprocessed(tmp_path, text.replace('#include "EnvironmentMap.h"', ""))
    assert "__asm__" in out and "#pragma GCC visibility" in out
    assert source_policy.refusals(out, "EnvironmentMap.cpp") == []


@pytest.mark.parametrize("text", [
    '#pragma GCC diagnostic push\n#pragma GCC diagnostic ignored "-Wunused"\n#pragma GCC diagnostic pop\n',
    "void f(float* a) {\n#pragma GCC unroll 4\n for (int i = 0; i < 8; ++i) a[i] = 0;\n}\n",
    "[[maybe_unused]] static int unused_section = 1; int alias = 2, symver = 3;\n",
    'const char* s = "asm(\\"nop\\") #line 3 _Pragma";\n',
])
def test_ordinary_code_passes_both_halves(tmp_path, text):
    assert refused_constructs(text.encode()) == []
    assert source_policy.refusals(preprocessed(tmp_path, text), "EnvironmentMap.cpp") == []


@pytest.mark.parametrize("text, what", [
    (b'#line 3 "x"\n', "#line"), (b"# 3 \"x\" 1 3\n", "#3"), (b"%:  line 3\n", "#line"),
    (b"??=line 3\n", "#line"), (b"#li\\\nne 3\n", "#line"), (b'#ident "x"\n', "#ident"),
    (b"#pragma GCC warning \"x\"\n", "pragma"), (b"#pragma GCC dependency \"/etc/x\"\n", "pragma"),
    (b'_Pragma("GCC diagnostic push")\n', "_Pragma"), (b"#assert machine(x)\n", "#assert"),
    # GCC reads a NUL as a space: both are directives to it.
    (b'\0# 5 "/usr/include/stdio.h" 1 3\n', "#5"), (b'#\0line 5 "/etc/x"\n', "#line"),
])
def test_the_text_half_refuses_directives_off_the_list(text, what):
    found = refused_constructs(text)
    assert found and found[0][0] == 1 and what in found[0][1], found


def test_the_assembly_is_a_second_wall(tmp_path, monkeypatch):
    # With the token half switched off, the '"' quoting trick and a split
    # .incbin still stop at the assembly, read as raw text.
    monkeypatch.setattr(source_policy, "refusals", lambda text, main: [])
    source = (ATTACKS / "asm_incbin_reference.cpp").read_text().replace(
        "/autograder/source/build/libenvmap.so", "/etc/hostname")
    (tmp_path / "EnvironmentMap.cpp").write_text(source)
    result = build_submission(tmp_path / "EnvironmentMap.cpp", cache_dir=tmp_path / "cache")
    assert not result.ok and result.diagnosis_id == "forbidden-object", result.log
    assert ".inc" in result.log.lower() and "hostname" not in result.log


def test_the_refusal_names_the_line(tmp_path):
    result = build_submission(ATTACKS / "asm_volatile_in_function.cpp", cache_dir=tmp_path)
    line = next(i for i, t in enumerate((ATTACKS / "asm_volatile_in_function.cpp").read_text().splitlines(), 1)
                if t.strip().startswith("__asm__"))
    assert result.diagnosis_id == "refused-source" and result.errors[0]["line"] == line
    assert f"line {line}" in result.log

