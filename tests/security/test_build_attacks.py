"""The build as a motivated student attacks it: one test per attack class,
asserting the verdict (not built) and its diagnosis id.

The sources are tests/submissions/attacks/*.cpp; each names the diagnosis
it must get on its first line (// EXPECT: <id>). Upload attacks (damaged,
disguised or huge archives, links, special files) are made here. None of
these needs the worker: a refused build never runs.
"""
from __future__ import annotations

import gzip
import io
import os
import struct
import subprocess
import sys
import tarfile
import time
import zipfile
from pathlib import Path

import pytest

from grader import PROJECT_ROOT, build, intake
from grader.build.include_policy import make_rule_files, outside_files, refused_directives
from grader.build import build_submission
from grader.build.objects import inspect_object
from fake_bwrap import write_failing_bwrap
from project_paths import SUBMISSIONS
from cases import cases
from red_team import REDTEAM

ATTACKS = sorted((SUBMISSIONS / "attacks").glob("*.cpp"))
GOOD = (SUBMISSIONS / "correct" / "idiomatic.cpp").read_bytes()


@pytest.fixture(scope="module")
def cache(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("attack-cache")


def expected(path: Path) -> str:
    first = path.read_text().splitlines()[0]
    assert first.startswith("// EXPECT: "), f"{path.name} must say what it expects on line 1"
    return first.split(": ", 1)[1].strip()


# ---- sources ----------------------------------------------------------------------

@pytest.mark.parametrize("source", ATTACKS, ids=lambda p: p.stem)
def test_attack_source_is_refused_with_its_diagnosis(source, cache):
    result = build_submission(source, cache_dir=cache)
    assert not result.ok and result.library is None, result.log
    assert result.diagnosis_id == expected(source), result.log
    assert result.errors and result.errors[0]["file"] == source.name
    # No refusal echoes a file of the grading machine (/etc/hostname's text).
    hostname = Path("/etc/hostname").read_text().strip() if Path("/etc/hostname").exists() else ""
    if len(hostname) > 3:
        assert hostname not in result.log
    assert "stdc-predef" not in result.log  # nor the preprocessor's file list


def test_calling_the_reference_names_the_functions(cache):
    result = build_submission(SUBMISSIONS / "attacks" / "calls_reference.cpp", cache_dir=cache)
    assert "em_fetch" in result.log and "em_read_texture" in result.log
    assert "reference solution" in result.log


def test_refused_include_names_its_line(cache):
    source = SUBMISSIONS / "attacks" / "include_macro.cpp"
    result = build_submission(source, cache_dir=cache)
    line = next(i for i, text in enumerate(source.read_text().splitlines(), 1) if "#include HEADER" in text)
    assert result.errors[0]["line"] == line
    assert f"line {line}: #include HEADER" in result.log


def test_splices_keep_line_numbers():
    text = b'// one\n#inc\\\nlude "/etc/x"\nint a;\n#include "/etc/y"\n'
    assert [line for line, _ in refused_directives(text)] == [2, 5]


@pytest.mark.parametrize("text", [
    b'#include <cmath>\n#include "EnvironmentMap.h"\n#include <bits/stdc++.h>\n',
    b'const char* s = "#include </etc/passwd>";\n',            # in a string: not a directive
    b'const char* r = R"(\n#include "/etc/passwd"\n)";\n',      # in a raw string
    b'/*\n#include "/etc/passwd"\n*/\nint x = 1\'000\'000;\n',  # in a comment; digit separators
    b'#if __has_include(<execution>)\n#endif\n',
    b'#include <cmath>;  // a stray semicolon: GCC warns, nothing more\n',
])
def test_ordinary_sources_are_not_refused(text):
    assert refused_directives(text) == []


def test_the_preprocessor_file_list_is_checked():
    # What -M wrote for a file that included /etc/hostname through a path
    # the text check could not see.
    deps = make_rule_files("EnvironmentMap.o: EnvironmentMap.cpp \\\n /usr/include/c++/12/cmath \\\n"
                         " /etc/host\\ name /tmp/x/include/EnvironmentMap.h\n")
    assert deps == ["EnvironmentMap.cpp", "/usr/include/c++/12/cmath", "/etc/host name",
                    "/tmp/x/include/EnvironmentMap.h"]
    assert outside_files(deps, Path("/tmp/x")) == ["/etc/host name"]


def test_the_template_headers_only(cache, tmp_path):
    # The reference's header is not on the include path any more.
    source = tmp_path / "EnvironmentMap.cpp"
    source.write_bytes(b'#include "envmap.h"\n' + GOOD)
    result = build_submission(source, cache_dir=cache)
    assert not result.ok and result.diagnosis_id == "build-error"
    assert 'includes "envmap.h", which the grader does not have' in result.log


def test_the_library_holds_no_reference_lookup(cache):
    result = build_submission(SUBMISSIONS / "correct" / "idiomatic.cpp", cache_dir=cache)
    assert result.ok, result.log
    names = subprocess.run(["nm", str(result.library)], capture_output=True, text=True).stdout
    for symbol in ("em_fetch", "em_fetch_batch", "em_read_texture", "em_direction_to_face", "em_render"):
        assert f" {symbol}\n" not in names
    assert " em_cubemap_load_cross\n" in names  # the loader's reference code is there
    dynamic = subprocess.run(["nm", "-D", "--defined-only", str(result.library)], capture_output=True,
                             text=True).stdout
    assert all(line.split()[-1].startswith("sub_") for line in dynamic.splitlines() if line.strip())


def test_object_reader_refuses_malformed_objects():
    allowed = {"memcpy"}
    assert inspect_object(b"", allowed)[0] == "forbidden-object"
    assert inspect_object(b"\x7fELF\x02\x01" + b"\0" * 58, allowed)[0] == "forbidden-object"
    header = bytearray(b"\x7fELF\x02\x01\x01" + b"\0" * 57)
    struct.pack_into("<H", header, 16, 1)
    struct.pack_into("<Q", header, 0x28, 1 << 40)          # section headers far past the end
    struct.pack_into("<HHH", header, 0x3A, 64, 3, 1)
    assert "out of bounds" in inspect_object(bytes(header), allowed)[1]


# ---- how the compiler runs -----------------------------------------------------------

def test_compiler_stdin_is_dev_null(tmp_path):
    # The grader's stdin carries data; a compiler reading /dev/stdin must not see it.
    script = ("import sys, time; from pathlib import Path; from grader.build.compiler import Deadline, run_compiler;"
              "step = run_compiler(['/bin/cat', '/dev/stdin'], Path(sys.argv[1]), Deadline.of(20), 'none');"
              "print(repr(step.output))")
    done = subprocess.run([sys.executable, "-c", script, str(tmp_path)], input="GRADER-STDIN-SECRET",
                          capture_output=True, text=True, cwd=PROJECT_ROOT, timeout=60)
    assert done.returncode == 0, done.stderr
    assert "GRADER-STDIN-SECRET" not in done.stdout


def test_link_runs_in_the_sandbox(cache, tmp_path, monkeypatch):
    from grader.worker import sandbox
    if sandbox.sandbox_problem() is not None:
        pytest.skip(f"no sandbox here: {sandbox.sandbox_problem()}")
    wrapped = []
    real = sandbox.compiler_command

    def recording(cmd, read_only, writable):
        wrapped.append(cmd)
        return real(cmd, read_only, writable)
    monkeypatch.setattr(sandbox, "compiler_command", recording)
    source = tmp_path / "EnvironmentMap.cpp"
    source.write_bytes(GOOD + b"\n// sandboxed link\n")
    result = build_submission(source, cache_dir=cache)
    assert result.ok and result.isolation == "bubblewrap", result.log
    assert any("-shared" in cmd for cmd in wrapped)     # the link
    assert any("-S" in cmd for cmd in wrapped)          # the compile
    assert any("-MD" in cmd for cmd in wrapped)         # with the list of files it read


# slow: several real builds each, in more than one isolation mode (12-16 s)
@pytest.mark.slow
@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="privilege drop needs root")
def test_privilege_drop_builds_as_an_unprivileged_uid(cache, tmp_path, monkeypatch):
    monkeypatch.setattr(build, "build_isolation", lambda: "privilege-drop")
    step = build.run_compiler(["/usr/bin/id", "-u"], tmp_path, build.Deadline.of(20), "privilege-drop")
    # Neither root nor nobody (the uid a privilege-dropped worker runs student code as).
    assert step.output.strip() == str(build.BUILD_UID) and build.BUILD_UID not in (0, 65534)
    source = tmp_path / "EnvironmentMap.cpp"
    source.write_bytes(GOOD + b"\n// privilege drop\n")
    result = build_submission(source, cache_dir=cache)
    assert result.ok and result.isolation == "privilege-drop", result.log
    # What reaches the cache belongs to us, not to the uid the compiler ran as.
    assert result.library.stat().st_uid == os.geteuid()
    assert result.library.parent.stat().st_uid == os.geteuid()
    refused = build_submission(SUBMISSIONS / "attacks" / "calls_reference.cpp", cache_dir=cache / "drop")
    assert refused.diagnosis_id == "calls-reference"


# ---- uploads -------------------------------------------------------------------------

def zip_bytes(members: dict[str, bytes], compression=zipfile.ZIP_DEFLATED) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", compression) as z:
        for name, data in members.items():
            z.writestr(name, data)
    return buffer.getvalue()


def _local_header(data: bytes) -> int:
    return data.index(b"PK\x03\x04")


def _central_header(data: bytes) -> int:
    return data.index(b"PK\x01\x02")


def bad_crc(data: bytes) -> bytes:
    data = bytearray(data)
    for at in (_local_header(data) + 14, _central_header(data) + 16):
        data[at] ^= 0xFF
    return bytes(data)


def encrypted_flag(data: bytes) -> bytes:
    data = bytearray(data)
    data[_local_header(data) + 6] |= 1
    data[_central_header(data) + 8] |= 1
    return bytes(data)


def deflate64(data: bytes) -> bytes:
    data = bytearray(data)
    struct.pack_into("<H", data, _local_header(data) + 8, 9)
    struct.pack_into("<H", data, _central_header(data) + 10, 9)
    return bytes(data)


def corrupt_deflate(data: bytes) -> bytes:
    data = bytearray(data)
    start = _local_header(data) + 30 + len("EnvironmentMap.cpp")
    data[start:start + 40] = b"\xff" * 40
    return bytes(data)


def tar_bytes(members: dict[str, bytes], mode="w:gz") -> bytes:
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode=mode) as t:
        for name, data in members.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            t.addfile(info, io.BytesIO(data))
    return buffer.getvalue()


def huge_member_tar() -> bytes:
    """A tar whose second member declares 1 TiB (the bytes are not there)."""
    head = tar_bytes({"EnvironmentMap.cpp": GOOD}, mode="w")[:-1024]  # drop the end blocks
    info = tarfile.TarInfo("data.bin")
    info.size = 1 << 40
    return head + info.tobuf(format=tarfile.GNU_FORMAT) + b"\0" * (1200 << 10)


UNREADABLE = {
    "bad_crc.zip": lambda: bad_crc(zip_bytes({"EnvironmentMap.cpp": GOOD})),
    "encrypted.zip": lambda: encrypted_flag(zip_bytes({"EnvironmentMap.cpp": GOOD})),
    "deflate64.zip": lambda: deflate64(zip_bytes({"EnvironmentMap.cpp": GOOD})),
    "corrupt_deflate.zip": lambda: corrupt_deflate(zip_bytes({"EnvironmentMap.cpp": GOOD})),
    "truncated.zip": lambda: zip_bytes({"EnvironmentMap.cpp": GOOD})[:200],
    "truncated.tar.gz": lambda: tar_bytes({"EnvironmentMap.cpp": GOOD})[:300],
    "bomb.tar.gz": lambda: gzip_of_zeros(200 << 20),
}


def gzip_of_zeros(size: int) -> bytes:
    """A tar.gz that unpacks to `size` bytes: one header then zeros, as
    gzip members one after another (gzip reads them as one stream), the
    megabyte of zeros compressed once and repeated."""
    header = tarfile.TarInfo("big.bin")
    header.size = size
    megabyte = gzip.compress(b"\0" * (1 << 20), compresslevel=9, mtime=0)
    return gzip.compress(header.tobuf(), mtime=0) + megabyte * (size >> 20)


@pytest.mark.parametrize("name", sorted(UNREADABLE))
def test_unreadable_archive_is_a_verdict(name, cache, tmp_path):
    path = tmp_path / name
    path.write_bytes(UNREADABLE[name]())
    started = time.monotonic()
    result = build_submission(path, cache_dir=cache)
    elapsed = time.monotonic() - started
    assert not result.ok
    assert result.diagnosis_id == "unreadable-archive", result.log
    assert result.log.startswith("your archive could not be read:")
    assert "Traceback" not in result.log
    assert elapsed < intake.MAX_UNPACK_SECONDS + 5  # never the hours an unbounded read takes


@pytest.mark.parametrize("source_first", [True, False])
def test_a_tar_declaring_a_terabyte_ends_quickly(source_first, cache, tmp_path):
    # 1.2 MB on disk, 1 TiB declared: read in one pass, never seeking to
    # the declared end. A source before it is graded; a source declaring
    # 1 TiB that is not there is a damaged archive.
    path = tmp_path / "huge.tar"
    if source_first:
        path.write_bytes(huge_member_tar())
    else:
        info = tarfile.TarInfo("EnvironmentMap.cpp")
        info.size = 1 << 40
        path.write_bytes(info.tobuf(format=tarfile.GNU_FORMAT) + b"\0" * (1200 << 10))
    started = time.monotonic()
    result = build_submission(path, cache_dir=cache)
    assert time.monotonic() - started < intake.MAX_UNPACK_SECONDS
    if source_first:
        assert result.ok, result.log
    else:
        assert not result.ok and result.diagnosis_id == "unreadable-archive", result.log
        assert "damaged or incomplete" in result.log


def test_encrypted_and_deflate64_say_why(cache, tmp_path):
    (tmp_path / "e.zip").write_bytes(UNREADABLE["encrypted.zip"]())
    (tmp_path / "d.zip").write_bytes(UNREADABLE["deflate64.zip"]())
    assert "password" in build_submission(tmp_path / "e.zip", cache_dir=cache).log
    assert "Deflate64" in build_submission(tmp_path / "d.zip", cache_dir=cache).log


def test_too_many_members_is_refused_before_reading(cache, tmp_path, monkeypatch):
    monkeypatch.setattr(intake, "MAX_MEMBERS", 5)
    path = tmp_path / "many.zip"
    path.write_bytes(zip_bytes({f"f{i}.txt": b"x" for i in range(10)} | {"EnvironmentMap.cpp": GOOD}))
    result = build_submission(path, cache_dir=cache)
    assert result.diagnosis_id == "unreadable-archive" and "more than 5 files" in result.log


def test_a_zip64_directory_is_counted_before_it_is_parsed(cache, tmp_path, monkeypatch):
    # More than 65535 entries: the count is in the zip64 record; parsing a
    # directory of millions would take seconds and gigabytes.
    path = tmp_path / "many64.zip"
    with zipfile.ZipFile(path, "w") as z:
        for i in range(66000):
            z.writestr(f"{i}", b"")
    monkeypatch.setattr(zipfile.ZipFile, "__init__", None)  # must not be reached
    result = build_submission(path, cache_dir=cache)
    assert result.diagnosis_id == "unreadable-archive" and "more than 20000 files" in result.log


@pytest.mark.parametrize("name, data, words", [
    ("work.rar", b"Rar!\x1a\x07\x01\x00" + os.urandom(200), "RAR archive"),
    ("work.7z", b"7z\xbc\xaf\x27\x1c" + os.urandom(200), "7-Zip archive"),
    ("work.zip", os.urandom(300).replace(b"PK", b"pk") + b"\0", "binary data"),
    ("EnvironmentMap.cpp", b"\x7fELF\x02\x01\x01" + b"\0" * 300, "ELF"),
    ("EnvironmentMap.cpp", "int main() {}\n".encode("utf-16"), "UTF-16"),
])
def test_unknown_format_says_what_was_received(name, data, words, cache, tmp_path):
    path = tmp_path / name
    path.write_bytes(data)
    result = build_submission(path, cache_dir=cache)
    assert not result.ok and result.diagnosis_id == "unknown-format", result.log
    assert words in result.log
    if words != "UTF-16":
        assert ".zip, .tar or .tar.gz" in result.log  # what is expected


def test_an_archive_is_known_by_its_bytes_not_its_name(cache, tmp_path):
    path = tmp_path / "EnvironmentMap.cpp"          # a zip with a source's name
    path.write_bytes(zip_bytes({"EnvironmentMap.cpp": GOOD}))
    assert build_submission(path, cache_dir=cache).ok
    path = tmp_path / "submission.tar.gz"           # a plain tar named .tar.gz
    path.write_bytes(tar_bytes({"sub/EnvironmentMap.cpp": GOOD}, mode="w"))
    result = build_submission(path, cache_dir=cache)
    assert result.ok and result.source_name == "sub/EnvironmentMap.cpp"


def test_binary_source_inside_an_archive(cache, tmp_path):
    path = tmp_path / "work.zip"
    path.write_bytes(zip_bytes({"EnvironmentMap.cpp": b"\x7fELF" + b"\0" * 100}))
    result = build_submission(path, cache_dir=cache)
    assert result.diagnosis_id == "unknown-format" and "not a C++ source file" in result.log


@pytest.mark.parametrize("make", ["empty file", "empty folder", "empty zip", "blank source"])
def test_empty_submission(make, cache, tmp_path):
    if make == "empty file":
        path = tmp_path / "EnvironmentMap.cpp"
        path.write_bytes(b"")
    elif make == "empty folder":
        path = tmp_path / "alice"
        (path / "sub").mkdir(parents=True)
    elif make == "empty zip":
        path = tmp_path / "alice.zip"
        path.write_bytes(zip_bytes({}))
    else:
        path = tmp_path / "EnvironmentMap.cpp"
        path.write_bytes(b"\n  \n")
    result = build_submission(path, cache_dir=cache)
    assert not result.ok and result.diagnosis_id == "empty-submission", result.log
    assert "nothing to grade" in result.log


def test_no_source_lists_what_the_upload_holds(cache, tmp_path):
    path = tmp_path / "bob.zip"
    path.write_bytes(zip_bytes({"bob/main.cpp": b"int main() {}\n", "bob/README.md": b"hi"}))
    result = build_submission(path, cache_dir=cache)
    assert result.diagnosis_id == "no-source"
    assert "bob/main.cpp" in result.log and "bob/README.md" in result.log


def test_links_and_special_files_in_a_folder_are_never_read(cache, tmp_path):
    folder = tmp_path / "carol"
    folder.mkdir()
    (folder / "EnvironmentMap.cpp").symlink_to("/proc/self/mem")
    os.mkfifo(folder / "Other.cpp")
    (folder / "sub").symlink_to("/etc")
    started = time.monotonic()
    result = build_submission(folder, cache_dir=cache)
    assert time.monotonic() - started < 10  # a FIFO opened for reading would block forever
    assert not result.ok and result.diagnosis_id == "empty-submission", result.log
    assert intake.hash_submission(folder)  # hashing skips them too, without blocking
    link = tmp_path / "link.cpp"
    link.symlink_to(SUBMISSIONS / "correct" / "idiomatic.cpp")
    assert build_submission(link, cache_dir=cache).diagnosis_id == "no-source"


def test_hash_skips_links(tmp_path):
    folder = tmp_path / "dave"
    folder.mkdir()
    (folder / "EnvironmentMap.cpp").write_bytes(GOOD)
    before = intake.hash_submission(folder)
    (folder / "mem").symlink_to("/proc/self/mem")
    assert intake.hash_submission(folder) == before
    (folder / "EnvironmentMap.cpp").write_bytes(GOOD + b"\n")
    assert intake.hash_submission(folder) != before


def test_refusals_are_plain_text_naming_the_upload(cache, tmp_path):
    # A hostile name reaches the message as it is (report writers escape it).
    name = "<img src=x onerror=alert(1)>.rar"
    path = tmp_path / name
    path.write_bytes(b"Rar!\x1a\x07\x00" + b"x" * 100)
    result = build_submission(path, cache_dir=cache)
    assert result.diagnosis_id == "unknown-format" and name in result.log


def _emitted_build_ids(tree) -> set[str]:
    """The diagnosis ids a build module's code gives, read from its syntax
    tree: the first argument of SubmissionError(...) and _refusal(...), a
    diagnosis_id= keyword, an assignment to .diagnosis_id, and the first item
    of a returned (id, message) pair."""
    import ast

    def text(node):
        return node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else None

    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            name = getattr(node.func, "id", getattr(node.func, "attr", ""))
            if name in ("SubmissionError", "_refusal") and node.args and text(node.args[0]):
                found.add(text(node.args[0]))
            found |= {text(k.value) for k in node.keywords if k.arg == "diagnosis_id" and text(k.value)}
        elif isinstance(node, ast.Assign) and text(node.value):
            if any(isinstance(t, ast.Attribute) and t.attr == "diagnosis_id" for t in node.targets):
                found.add(text(node.value))
        elif isinstance(node, ast.Return) and isinstance(node.value, ast.Tuple) and len(node.value.elts) == 2 \
                and text(node.value.elts[0]) and "-" in text(node.value.elts[0]):
            found.add(text(node.value.elts[0]))
    return found


def test_every_build_diagnosis_is_declared_and_catalogued():
    import ast
    from grader.grading.catalogue import CATALOGUE
    used = set()
    for path in [*sorted((PROJECT_ROOT / "grader" / "build").glob("*.py")), PROJECT_ROOT / "grader" / "intake.py"]:
        used |= _emitted_build_ids(ast.parse(path.read_text()))
    assert used <= set(build.DIAGNOSIS_IDS), used - set(build.DIAGNOSIS_IDS)
    # Each declared id is given somewhere; "build-error" as BuildResult's default (a failed compilation).
    assert set(build.DIAGNOSIS_IDS) - used == {"build-error"} and build.BuildResult.diagnosis_id == "build-error"
    assert all(i in CATALOGUE and CATALOGUE[i].kind == "build" for i in build.DIAGNOSIS_IDS)


def test_the_id_reader_finds_each_shape_of_emission():
    import ast
    source = """
def a(): raise SubmissionError("no-source", "m")
def b(): return _refusal("refused-source", "m", 3)
def c(r): r.diagnosis_id = "refused-include"
def d(): return "forbidden-object", "message"
def e(): return BuildResult(diagnosis_id="unknown-format")
def f(): return "ok", "not an id"
"""
    assert _emitted_build_ids(ast.parse(source)) == {"no-source", "refused-source", "refused-include",
                                                      "forbidden-object", "unknown-format"}


def test_a_folder_deeper_than_any_project_is_not_walked_to_the_bottom(tmp_path):
    # os.walk recurses once per level: with Python's usual limit a folder
    # ~1000 deep overflowed it (a traceback). The same overflow is made here
    # with 150 levels under a lowered limit, which pytest can still clean up.
    import inspect
    folder = tmp_path / "erin"
    deep = folder
    for _ in range(150):
        deep = deep / "d"
    deep.mkdir(parents=True)
    (folder / "EnvironmentMap.cpp").write_bytes(GOOD)
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(len(inspect.stack()) + 100)
    try:
        chosen = intake.select_source(folder, build.TEMPLATE)
        digest = intake.hash_submission(folder)
    finally:
        sys.setrecursionlimit(limit)
    assert chosen.name == "EnvironmentMap.cpp" and digest


@pytest.fixture
def failing_bwrap(tmp_path, monkeypatch):
    """A bwrap first on PATH that always fails, as in a container without
    user namespaces; the sandbox probe is asked again."""
    from grader.worker import sandbox
    fake = write_failing_bwrap(tmp_path / "fakebin")
    monkeypatch.setenv("PATH", f"{fake}:{os.environ.get('PATH', '/usr/bin:/bin')}")
    sandbox.sandbox_problem.cache_clear()
    yield
    sandbox.sandbox_problem.cache_clear()


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="privilege drop needs root")
def test_without_bubblewrap_root_builds_unprivileged(failing_bwrap, cache, tmp_path):
    assert build.build_isolation() == "privilege-drop"
    source = tmp_path / "EnvironmentMap.cpp"
    source.write_bytes(GOOD + b"\n// no bubblewrap here\n")
    result = build_submission(source, cache_dir=cache)
    assert result.ok and result.isolation == "privilege-drop", result.log
    refused = build_submission(SUBMISSIONS / "attacks" / "include_scratch_file.cpp", cache_dir=cache)
    assert refused.diagnosis_id == "refused-include"


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="privilege drop needs root")
def test_without_bubblewrap_a_private_temporary_folder_is_not_a_compile_error(failing_bwrap, cache, tmp_path,
                                                                                monkeypatch):
    # TMPDIR inside pytest's 0700 folder (or a private one under /root): the
    # build user cannot enter it, so a correct file was told it did not compile.
    import tempfile
    private = tmp_path / "private-tmp"
    private.mkdir(mode=0o700)
    monkeypatch.setattr(tempfile, "tempdir", str(private))
    build._scratch_parent.cache_clear()
    try:
        source = tmp_path / "EnvironmentMap.cpp"
        source.write_bytes(GOOD + b"\n// a private TMPDIR\n")
        result = build_submission(source, cache_dir=cache)
        assert result.ok and result.isolation == "privilege-drop", result.log
    finally:
        build._scratch_parent.cache_clear()


def test_without_bubblewrap_and_not_root_builds_as_ourselves(failing_bwrap, monkeypatch):
    monkeypatch.setattr(os, "geteuid", lambda: 1000)
    assert build.build_isolation() == "none"


# slow: several real builds each, in more than one isolation mode (12-16 s)
@pytest.mark.slow
def test_unsandboxed_build_still_checks_everything(cache, tmp_path, monkeypatch):
    # Non-root without bubblewrap: the compilers run as ourselves, and every
    # refusal still happens (they do not depend on the sandbox).
    monkeypatch.setattr(build, "build_isolation", lambda: "none")
    source = tmp_path / "EnvironmentMap.cpp"
    source.write_bytes(GOOD + b"\n// no isolation\n")
    result = build_submission(source, cache_dir=cache / "none")
    assert result.ok and result.isolation == "none", result.log
    for attack, expected_id in [("include_scratch_file.cpp", "refused-include"),
                                ("incbin_split.cpp", "refused-source"),
                                ("calls_reference.cpp", "calls-reference")]:
        refused = build_submission(SUBMISSIONS / "attacks" / attack, cache_dir=cache / "none")
        assert refused.diagnosis_id == expected_id, refused.log


# slow: every standard header compiled (12 s), and again under AddressSanitizer
@pytest.mark.parametrize("sanitize", cases([False, True], slow={"False", "True"}, sanitizer={"True"}))
def test_the_whole_standard_library_is_allowed(sanitize, cache):
    # No false refusals: threads, regex, filesystem, exceptions, RTTI,
    # thread_local, guarded statics, <random>, <complex> ... all link.
    result = build_submission(SUBMISSIONS / "build" / "uses_standard_library.cpp", cache_dir=cache,
                              sanitize=sanitize)
    assert result.ok, result.log


# slow: several real builds each, in more than one isolation mode (12-16 s)
@pytest.mark.slow
def test_refusals_stay_short_whatever_the_object_holds(tmp_path, monkeypatch):
    # 91 undefined symbols of 190 characters: the message names a few, shortened.
    # (Their asm labels are refused first by the source policy, switched off
    # here: the object check is the second wall.)
    from grader.build import source_policy
    monkeypatch.setattr(source_policy, "refusals", lambda text, main: [])
    result = build_submission(SUBMISSIONS / "attacks" / "long_symbol_names.cpp", cache_dir=tmp_path)
    assert result.diagnosis_id == "forbidden-object"
    assert "and 86 more" in result.log and len(result.log) < 1000


def test_the_linked_library_is_checked_too(cache):
    # Whatever got past the object checks, the library the worker loads
    # may need only the C/C++ runtime: a library that needs zlib is refused.
    from grader.build.objects import inspect_library
    built = build_submission(SUBMISSIONS / "correct" / "idiomatic.cpp", cache_dir=cache)
    allowed = set((next(cache.glob("common-*")) / "allowed-symbols.txt").read_text().split())
    assert inspect_library(built.library.read_bytes(), allowed, sanitize=False) is None
    other = Path("/usr/lib/x86_64-linux-gnu/libpng16.so.16")
    if not other.is_file():
        pytest.skip("no libpng16 here to stand for a library with other needs")
    verdict = inspect_library(other.read_bytes(), allowed, sanitize=False)
    assert verdict[0] == "forbidden-object" and "libz.so.1" in verdict[1]
    assert inspect_library(b"not an ELF file", allowed, sanitize=False)[0] == "forbidden-object"


# slow: several real builds each, in more than one isolation mode (12-16 s)
@pytest.mark.slow
def test_no_scratch_folder_outlives_its_build(cache, tmp_path, monkeypatch):
    # Also when the compile is killed at the deadline, and on a refusal.
    import shutil
    import tempfile
    # Not under tmp_path: in privilege-drop mode the compiler runs as another
    # uid, which cannot enter pytest's 0700 temporary folder.
    scratch = Path(tempfile.mkdtemp(prefix="envmap-scratch-"))
    scratch.chmod(0o755)
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    try:
        slow = build_submission(SUBMISSIONS / "build" / "slow_compile.cpp", cache_dir=cache, timeout_s=2)
        assert slow.timed_out
        refused = build_submission(SUBMISSIONS / "attacks" / "incbin_split.cpp", cache_dir=cache / "again")
        assert refused.diagnosis_id == "refused-source"
        assert list(scratch.iterdir()) == []
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def test_a_refused_submission_is_not_reported_as_a_compile_error(tmp_path):
    """A refusal (here: calling the reference) compiled fine: every report says it was
    refused and names the cause, not "did not compile" (which sends the student to
    look for a syntax error that is not there)."""
    import json
    import xml.etree.ElementTree as ET
    from grader.grading.grade import GradeOptions, grade
    result = grade(SUBMISSIONS / "attacks" / "calls_reference.cpp", tmp_path / "out", GradeOptions(quick=True))
    assert [d.id for d in result.diagnoses][:1] == ["calls-reference"]
    md = (tmp_path / "out" / "report.md").read_text()
    html = (tmp_path / "out" / "report.html").read_text()
    output = json.loads((tmp_path / "out" / "results.json").read_text())["output"]
    for text in (md, html, output):
        assert "did not compile" not in text
        assert "refused before it could be built or run" in text
    junit = ET.parse(tmp_path / "out" / "junit.xml").getroot()
    assert junit.findall(".//failure") and "did not compile" not in ET.tostring(junit, encoding="unicode")


# ---- the first red-team round (tests/submissions/redteam/) ------------------------
# - warning_flood: a macro repeating `#pragma GCC warning` made the compiler
#   print gigabytes, all held in the grader's memory (4.8 GB RSS for 1 GB) and
#   written to the build cache, and the submission still scored 100. Now the
#   compiler is stopped at 4 MiB of messages.
# - ballast: 240 MiB of zeros in .data (a 4 KiB source) made a 240 MiB
#   library, stored in the build cache and copied into every worker's folder;
#   it scored 100. Now a library over 64 MiB is refused (forbidden-object).

RED_TEAM = {"redteam": {"warning_flood", "ballast"}}
CAP_BYTES = 4 << 20    # grader.build.messages.MAX_COMPILER_OUTPUT_BYTES

# slow: several real builds each, in more than one isolation mode (12-16 s)
@pytest.mark.slow
@pytest.mark.sandbox
def test_a_flood_of_warnings_stops_the_compiler_and_is_a_build_error(tmp_path):
    result = build_submission(REDTEAM / "warning_flood.cpp", cache_dir=tmp_path)
    assert not result.ok and result.diagnosis_id == "build-error"
    assert result.log.splitlines()[0].startswith(
        f"The compiler printed more than {CAP_BYTES >> 20} MiB of messages")
    assert len(result.log) < 10_000
    # The cache holds at most the cap, not what the compiler would have printed.
    records = list(tmp_path.glob("*/build.json"))
    assert records and all(r.stat().st_size < CAP_BYTES * 1.5 for r in records)


# slow: several real builds each, in more than one isolation mode (12-16 s)
@pytest.mark.slow
@pytest.mark.sandbox
def test_a_huge_library_is_refused_and_not_cached(tmp_path):
    result = build_submission(REDTEAM / "ballast.cpp", cache_dir=tmp_path)
    assert not result.ok and result.diagnosis_id == "forbidden-object"
    assert "more than 64 MiB" in result.log
    # Our own objects (common-*, with a 28 MB precompiled header) are in the cache whatever was built.
    stored = sum(f.stat().st_size for f in tmp_path.rglob("*")
                 if f.is_file() and not f.relative_to(tmp_path).parts[0].startswith("common-"))
    assert stored < 16 << 20
