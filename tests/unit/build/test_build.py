"""grader/build/__init__.py: submissions become libraries that expose submission_abi.h.

Student code is never loaded into the pytest process: a small script run in
a subprocess loads the built library with cffi and calls the sub_* entry
points (PROBE below).
"""
from __future__ import annotations

import io
import json
import subprocess
import sys
import tarfile
import zipfile
from pathlib import Path

import numpy as np
import pytest

from grader import PROJECT_ROOT
from grader.build import build_submission
from grader.envmap.library import CubeMap, faces_to_cross, write_hdr
from project_paths import SUBMISSIONS

CORRECT = sorted((SUBMISSIONS / "correct").glob("*.cpp"))
BUILD_CASES = SUBMISSIONS / "build"
TEMPLATE_SOURCE = PROJECT_ROOT / "student_template" / "EnvironmentMap.cpp"
ABI_HEADER = PROJECT_ROOT / "grader" / "build" / "shim" / "submission_abi.h"

# Loads a built submission and calls it; arguments: library, ABI header,
# input .npz, output .npz. Inputs (all optional but texels): texels
# (6, H, W, 3) float32; dirs (n, 3); faces (m,) with uv (m, 2); load (a path
# for sub_load_cross, then dirs are fetched from the loaded map).
PROBE = r"""
import re, sys
import numpy as np
from cffi import FFI

library, header, inputs, outputs = sys.argv[1:5]
text = open(header).read()
text = re.sub(r"#ifdef __cplusplus.*?#endif", "", text, flags=re.S)
text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
lines = [l for l in text.splitlines() if not l.startswith("#") or re.match(r"#define \w+ \d+$", l)]
ffi = FFI()
ffi.cdef("\n".join(lines))
lib = ffi.dlopen(library)
data = dict(np.load(inputs, allow_pickle=False))
out = {"abi_version": np.array(lib.sub_abi_version())}
message = ffi.new("char[512]")
keep = []

def ptr(ctype, array):
    keep.append(array)
    return ffi.cast(ctype, ffi.from_buffer(array))

m = lib.sub_create(message, 512)
assert m != ffi.NULL, ffi.string(message)
if "load" in data:
    out["load_status"] = np.array(lib.sub_load_cross(m, str(data["load"]).encode(), message, 512))
    out["load_message"] = np.array(ffi.string(message).decode())
else:
    texels = np.ascontiguousarray(data["texels"], dtype=np.float32)
    _, h, w, _ = texels.shape
    assert lib.sub_set_faces(m, ptr("float *", texels), w, h, message, 512) == 0
if "dirs" in data:
    dirs = np.ascontiguousarray(data["dirs"], dtype=np.float64)
    rgb = np.zeros((len(dirs), 3))
    out["fetch_status"] = np.array(lib.sub_fetch_batch(m, ptr("double *", dirs), len(dirs),
                                                       ptr("double *", rgb), message, 512))
    out["fetch_message"] = np.array(ffi.string(message).decode())
    out["fetch"] = rgb
if "faces" in data:
    face_size = texels[0].size
    rgb = np.zeros((len(data["uv"]), 3))
    for i, (face, uv) in enumerate(zip(data["faces"], data["uv"])):
        uv = np.ascontiguousarray(uv, dtype=np.float64)
        addr = ffi.cast("float *", ffi.from_buffer(texels)) + int(face) * face_size
        status = lib.sub_read_texture_batch(m, addr, ptr("double *", uv), 1,
                                            ptr("double *", rgb[i]), message, 512)
        assert status == 0, ffi.string(message)
    out["read"] = rgb
lib.sub_destroy(m)
np.savez(outputs, **out)
"""


def probe(library: Path, tmp_path: Path, **inputs) -> dict:
    """Run PROBE on a built library in a fresh Python process."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    src, dst = tmp_path / "probe_in.npz", tmp_path / "probe_out.npz"
    np.savez(src, **{k: np.asarray(v) for k, v in inputs.items()})
    run = subprocess.run([sys.executable, "-c", PROBE, str(library), str(ABI_HEADER), str(src), str(dst)],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    with np.load(dst) as out:
        return {k: out[k] for k in out.files}


@pytest.fixture(scope="module")
def cache(tmp_path_factory) -> Path:
    """A build cache of this test module's own, so builds here are real builds."""
    return tmp_path_factory.mktemp("build-cache")


def random_faces(rng, w=9, h=6) -> np.ndarray:
    # W != H, so a solution that swaps width and height cannot pass.
    return rng.uniform(0.0, 1.0, (6, h, w, 3)).astype(np.float32)


def random_directions(rng, n=3000) -> np.ndarray:
    return rng.normal(size=(n, 3)) * rng.uniform(0.1, 10.0, (n, 1))


def marked_line(path: Path, marker: str) -> int:
    """The 1-based line of `path` that carries the comment marker."""
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if f"// {marker}" in line)


# ---- the template and correct solutions ---------------------------------------------

# slow: several real builds each, in more than one isolation mode (12-16 s)
@pytest.mark.slow
def test_untouched_template_builds_black_and_nearest(cache, tmp_path):
    result = build_submission(TEMPLATE_SOURCE, cache_dir=cache)
    assert result.ok, result.log
    assert result.errors == [] and result.warnings == []
    rng = np.random.default_rng(1)
    faces = random_faces(rng)
    uv = np.concatenate([rng.uniform(0, 1, (200, 2)), [[0, 0], [1, 1], [1, 0], [0.999999, 0.5]]])
    face_of = rng.integers(0, 6, len(uv))
    out = probe(result.library, tmp_path, texels=faces, dirs=random_directions(rng, 100),
                faces=face_of, uv=uv)
    assert out["abi_version"] == 2
    assert out["fetch_status"] == 0
    assert np.all(out["fetch"] == 0.0)
    # The handout's starting code: x0 = clamp((int)(u W), 0, W-1), likewise y0.
    h, w = faces.shape[1:3]
    x0 = np.clip((uv[:, 0] * w).astype(int), 0, w - 1)
    y0 = np.clip((uv[:, 1] * h).astype(int), 0, h - 1)
    np.testing.assert_array_equal(out["read"], faces[face_of, y0, x0].astype(np.float64))


@pytest.mark.parametrize("solution", CORRECT, ids=lambda p: p.stem)
def test_correct_solution_matches_reference(solution, cache, tmp_path):
    result = build_submission(solution, cache_dir=cache)
    assert result.ok, result.log
    assert result.warnings == [], result.log
    rng = np.random.default_rng(2)
    faces = random_faces(rng)
    dirs = random_directions(rng)
    uv = rng.uniform(0, 1, (300, 2))
    face_of = rng.integers(0, 6, len(uv))
    out = probe(result.library, tmp_path, texels=faces, dirs=dirs, faces=face_of, uv=uv)
    cube = CubeMap(faces)
    expected_fetch = cube.fetch(dirs, filter="bilinear")
    expected_read = cube.read_texture(face_of, uv, filter="bilinear")
    # float arithmetic is exact only to float precision: ~1e-7 in u, v,
    # times the face width, times the texel contrast (at most 1 here).
    atol = 1e-4 if "float" in solution.stem else 1e-12
    np.testing.assert_allclose(out["fetch"], expected_fetch, rtol=1e-6, atol=atol)
    np.testing.assert_allclose(out["read"], expected_read, rtol=1e-6, atol=atol)


def test_exception_in_student_code_becomes_a_message(cache, tmp_path):
    # hostile/throw.cpp throws std::runtime_error near +x.
    result = build_submission(SUBMISSIONS / "hostile" / "throw.cpp", cache_dir=cache)
    out = probe(result.library, tmp_path, texels=random_faces(np.random.default_rng(3)),
                dirs=np.array([[1.0, 0.0, 0.0]]))
    assert out["fetch_status"] == -1  # SUB_ERR_EXCEPTION
    assert str(out["fetch_message"]) == "direction too close to +x"


def test_load_cross_reads_a_vertical_cross(cache, tmp_path):
    faces = random_faces(np.random.default_rng(4), w=8, h=8)
    cross = tmp_path / "cross.hdr"
    write_hdr(cross, faces_to_cross(faces))
    result = build_submission(SUBMISSIONS / "correct" / "if_chain.cpp", cache_dir=cache)
    dirs = random_directions(np.random.default_rng(5), 500)
    out = probe(result.library, tmp_path, load=str(cross), dirs=dirs)
    assert out["load_status"] == 1, out["load_message"]
    expected = CubeMap.load_cross(cross).fetch(dirs, filter="bilinear")
    np.testing.assert_allclose(out["fetch"], expected, rtol=1e-6, atol=1e-12)

    missing = probe(result.library, tmp_path / "missing", load=str(tmp_path / "nope.hdr"))
    assert missing["load_status"] == 0
    assert "nope.hdr" in str(missing["load_message"])


# slow: AddressSanitizer builds and runs (the sanitizer marker's own business)
@pytest.mark.sanitizer
@pytest.mark.slow
def test_sanitized_build_loads_under_asan(cache, tmp_path):
    result = build_submission(SUBMISSIONS / "correct" / "idiomatic.cpp", cache_dir=cache, sanitize=True)
    assert result.ok, result.log
    libasan = subprocess.run(["gcc", "-print-file-name=libasan.so"], capture_output=True,
                             text=True).stdout.strip()
    src, dst = tmp_path / "in.npz", tmp_path / "out.npz"
    faces = random_faces(np.random.default_rng(6))
    dirs = random_directions(np.random.default_rng(7), 200)
    np.savez(src, texels=faces, dirs=dirs)
    env = {"LD_PRELOAD": libasan, "ASAN_OPTIONS": "detect_leaks=0", "PATH": "/usr/bin:/bin"}
    run = subprocess.run([sys.executable, "-c", PROBE, str(result.library), str(ABI_HEADER), str(src),
                          str(dst)], capture_output=True, text=True, env=env, timeout=120)
    assert run.returncode == 0, run.stderr
    with np.load(dst) as out:
        np.testing.assert_allclose(out["fetch"], CubeMap(faces).fetch(dirs), rtol=1e-6, atol=1e-12)


# ---- failures the student reads -----------------------------------------------------

def test_syntax_error_names_its_line(cache):
    source = BUILD_CASES / "syntax_error.cpp"
    result = build_submission(source, cache_dir=cache)
    line = marked_line(source, "ERROR")
    assert not result.ok and result.library is None
    assert result.errors[0]["line"] == line
    first_error = next(l for l in result.log.splitlines() if "error:" in l)
    assert first_error.startswith(f"syntax_error.cpp:{line}:")


@pytest.mark.parametrize("case, sentence", [
    ("redefines_load.cpp", "must not define loadFromCrossHDR: it is provided"),
    ("redefines_face_address.cpp", "must not define faceAddress: it is provided"),
    ("missing_fetch_color.cpp", "must define fetchColor"),
    ("member_helper.cpp", "EnvironmentMap::clampU is not declared in EnvironmentMap.h"),
    ("includes_old_header.cpp", 'includes "hdr.h", which the grader does not have'),
    # The refusal names the line (the file's 4th) before anything is compiled.
    ("includes_absolute_path.cpp", 'Refused: line 4: #include "/etc/hostname"'),
])
def test_common_mistakes_get_a_clear_sentence(case, sentence, cache):
    result = build_submission(BUILD_CASES / case, cache_dir=cache)
    assert not result.ok
    assert sentence in result.errors[0]["message"]
    assert result.log.startswith(result.errors[0]["message"])


def test_extra_symbols_build_and_warnings_are_reported(cache):
    source = BUILD_CASES / "extra_symbols.cpp"
    result = build_submission(source, cache_dir=cache)
    assert result.ok, result.log
    assert [w["line"] for w in result.warnings] == [marked_line(source, "WARNING")]
    assert "unused variable" in result.log
    exported = subprocess.run(["nm", "-D", "--defined-only", str(result.library)],
                              capture_output=True, text=True, check=True).stdout
    names = {line.split()[-1] for line in exported.splitlines() if line.strip()}
    assert names == {"sub_abi_version", "sub_create", "sub_destroy", "sub_set_faces",
                     "sub_fetch_batch", "sub_read_texture_batch", "sub_load_cross",
                     "sub_record_fetch_batch"}


# slow: wait out wall-clock bounds on purpose (4-6 s, a core idle)
@pytest.mark.slow
def test_compile_timeout_is_reported_and_not_cached(cache, tmp_path):
    source = BUILD_CASES / "slow_compile.cpp"
    result = build_submission(source, cache_dir=cache, timeout_s=2)
    assert not result.ok and result.timed_out and result.stopped_by == "cpu"
    assert "more than 2 s of processor time" in result.log
    again = build_submission(source, cache_dir=cache, timeout_s=2)
    assert not again.cached


# ---- inputs: folders, files, archives, the cache -------------------------------------

def _zip(path: Path, members: dict[str, bytes]) -> Path:
    with zipfile.ZipFile(path, "w") as z:
        for name, data in members.items():
            z.writestr(name, data)
    return path


def _tar(path: Path, members: dict[str, bytes], symlinks: dict[str, str] = {}) -> Path:
    with tarfile.open(path, "w:gz") as t:
        for name, data in members.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            t.addfile(info, io.BytesIO(data))
        for name, target in symlinks.items():
            info = tarfile.TarInfo(name)
            info.type, info.linkname = tarfile.SYMTYPE, target
            t.addfile(info)
    return path


def test_archives_build_the_same_cached_library(cache, tmp_path):
    source = SUBMISSIONS / "correct" / "switch_on_face.cpp"
    loose = build_submission(source, cache_dir=cache)
    members = {"alice/src/EnvironmentMap.cpp": source.read_bytes(), "alice/README.txt": b"hi"}
    for archive in (_zip(tmp_path / "alice.zip", members), _tar(tmp_path / "alice.tar.gz", members)):
        packed = build_submission(archive, cache_dir=cache)
        assert packed.ok and packed.cached
        assert packed.library == loose.library
        assert packed.sha256 == loose.sha256
        assert packed.source_name == "alice/src/EnvironmentMap.cpp"
        assert packed.source.read_bytes() == source.read_bytes()


def test_messages_name_the_file_inside_the_archive(cache, tmp_path):
    source = BUILD_CASES / "syntax_error.cpp"
    archive = _zip(tmp_path / "bob.zip", {"bob/EnvironmentMap.cpp": source.read_bytes()})
    result = build_submission(archive, cache_dir=cache)
    line = marked_line(source, "ERROR")
    assert result.errors[0]["file"] == "bob/EnvironmentMap.cpp"
    assert f"bob/EnvironmentMap.cpp:{line}:" in result.log


def test_folder_with_several_sources_picks_the_shallowest(cache, tmp_path):
    good = (SUBMISSIONS / "correct" / "if_chain.cpp").read_bytes()
    for name, data in {"work/EnvironmentMap.cpp": good,
                       "work/old/EnvironmentMap.cpp": b"this does not compile",
                       "work/EnvironmentMap.h": b"// my own header\n"}.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_bytes(data)
    result = build_submission(tmp_path / "work", cache_dir=cache)
    assert result.ok, result.log
    assert result.source == tmp_path / "work" / "EnvironmentMap.cpp"
    assert any("used EnvironmentMap.cpp, the one nearest the top" in n for n in result.notes)
    assert "submitted EnvironmentMap.h differs from ours: ignored" in " ".join(result.notes)


def test_unsafe_archive_members_are_never_used(cache, tmp_path):
    good = (SUBMISSIONS / "correct" / "if_chain.cpp").read_bytes()
    archive = _tar(tmp_path / "evil.tar.gz",
                   {"../EnvironmentMap.cpp": b"outside", "/abs/EnvironmentMap.cpp": b"absolute",
                    "deep/down/EnvironmentMap.cpp": good},
                   symlinks={"EnvironmentMap.cpp": "/etc/passwd"})
    result = build_submission(archive, cache_dir=cache)
    assert result.ok, result.log
    assert result.source_name == "deep/down/EnvironmentMap.cpp"
    assert not (tmp_path.parent / "EnvironmentMap.cpp").exists()

    only_link = _tar(tmp_path / "link.tar.gz", {}, symlinks={"EnvironmentMap.cpp": "/etc/passwd"})
    refused = build_submission(only_link, cache_dir=cache)
    assert not refused.ok and refused.diagnosis_id == "empty-submission"


def test_nothing_to_build_is_a_failure_not_an_exception(cache, tmp_path):
    (tmp_path / "notes.txt").write_text("I ran out of time")
    nothing = build_submission(tmp_path, cache_dir=cache)
    assert "No EnvironmentMap.cpp" in nothing.log and "notes.txt" in nothing.log
    assert nothing.diagnosis_id == "no-source"
    # What a file is comes from its bytes: text named .zip is no archive.
    (tmp_path / "broken.zip").write_bytes(b"not a zip")
    broken = build_submission(tmp_path / "broken.zip", cache_dir=cache)
    assert "broken.zip is text, not an archive" in broken.log and ".zip, .tar or .tar.gz" in broken.log
    assert broken.diagnosis_id == "unknown-format"


def test_rebuilding_an_unchanged_source_uses_the_cache(cache):
    first = build_submission(SUBMISSIONS / "correct" / "axis_table.cpp", cache_dir=cache)
    second = build_submission(SUBMISSIONS / "correct" / "axis_table.cpp", cache_dir=cache)
    assert second.cached and second.library == first.library
    record = json.loads((first.library.parent / "build.json").read_text())
    assert record["ok"] is True
