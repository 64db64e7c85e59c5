"""The student kit (`python -m grader kit`): holds no lookup code, no solution,
no hidden check and no secret; builds on its own (make and CMake); and its
self-check is the grader's own code, copied in (tests/kit/test_kit_agreement.py
holds the agreement with the grader on the zoos)."""
from __future__ import annotations

import base64
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import time
import tomllib
import zipfile
from pathlib import Path

import pytest

from fake_bwrap import write_failing_bwrap
from grader import PROJECT_ROOT
from grader.kit import NOT_IN_KIT
from grader.kit.build import KitError, build_kit, grader_modules, kit_header, lookup_names, visible_rubric
from grader.grading.score import load_rubric

from project_paths import TESTS
CORRECT = sorted((TESTS / "submissions" / "correct").glob("*.cpp"))
WRONG = TESTS / "submissions" / "wrong"
TEMPLATE_SOURCE = PROJECT_ROOT / "student_template" / "EnvironmentMap.cpp"
# Some points, not all: FAIL_UNDER read as a percentage (the template now scores 0, issue 30).
PARTLY_RIGHT = WRONG / "v-flipped-pos-z.cpp"
# The heart of the reference lookup: these must be among the scanned names.
KEY_NAMES = {"em_fetch", "em_read_texture", "em_direction_to_face", "FACE_AXES", "direction_face_uv", "read_bilinear", "u_sign"}
VISIBLE_POINTS = sum(e["points"] for n, e in load_rubric()["checks"].items()
                     if e.get("visibility", "visible") == "visible" and n not in NOT_IN_KIT)


@pytest.fixture(scope="module")
def kit(student_kit):
    """The session's kit (tests/conftest.py): tests copy it before changing it."""
    return student_kit


@pytest.fixture(scope="module")
def alone(kit, tmp_path_factory) -> Path:
    """The zip unpacked alone in an empty folder (no project beside it), with
    the program built."""
    where = tmp_path_factory.mktemp("alone")
    with zipfile.ZipFile(kit.zip_path) as z:
        z.extractall(where)
    folder = where / "student-kit"
    run = subprocess.run(["make", "-s", "all"], cwd=folder, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "warning" not in run.stdout + run.stderr
    return folder


def kit_environment(**extra: str) -> dict:
    """The caller's environment without PYTHONPATH (the kit has its own copy
    of the grader) and with this Python for the self-check (its packages are
    the kit's locked ones: grader.kit.environment)."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "GRADER_SECRET", "ENVMAP_LIBRARY")}
    return {**env, "SELFCHECK_PYTHON": sys.executable, **extra}


@pytest.fixture(params=["bubblewrap", "no-bwrap"])
def environment(request, tmp_path) -> dict:
    """Both ways the kit runs here: bubblewrap as installed, and a failing
    bwrap first on PATH (the worker is then the only confinement)."""
    if request.param == "bubblewrap":
        return kit_environment()
    fake = write_failing_bwrap(tmp_path / "fakebin")
    return kit_environment(PATH=f"{fake}:{os.environ.get('PATH', '/usr/bin:/bin')}")


def selfcheck(folder: Path, source: Path | None = None, *extra: str, env: dict | None = None
              ) -> tuple[subprocess.CompletedProcess, dict | None]:
    if source is not None:
        shutil.copyfile(source, folder / "EnvironmentMap.cpp")
    run = subprocess.run(["make", "-s", "selfcheck", *extra], cwd=folder, capture_output=True, text=True,
                         timeout=600, env=env or kit_environment())
    summary = folder / "build" / "selfcheck" / "selfcheck.json"
    return run, json.loads(summary.read_text()) if summary.is_file() else None


def ids(summary: dict) -> set[str]:
    return {d["id"] for d in summary["extra_data"]["diagnoses"]}


# ---- what the kit holds --------------------------------------------------------------


def test_lookup_names_cover_the_reference_lookup():
    assert KEY_NAMES <= set(lookup_names())
    # ... and none of them is something the kit's renderer provides.
    assert "em_render" not in lookup_names() and "em_cubemap_load_cross" not in lookup_names()


def kit_files(folder: Path):
    return sorted(p for p in folder.rglob("*") if p.is_file())


# Where the kit's copy of the grader names a lookup.c name without holding
# its code: the cffi bindings, which the kit's header does not declare and
# its library does not define (test_built_binaries_have_no_lookup_symbols);
# two variable names of the face frames probed through the oracle (geometry).
NAMED_NOT_HELD = {
    "selfcheck/grader/envmap/library.py": {"EM_FILTER_NEAREST", "em_cubemap_lookup", "em_cubemap_lookup_fn",
                                      "em_direction_to_face_batch", "em_fetch_batch", "em_filter",
                                      "em_read_texture_batch"},
    "selfcheck/grader/envmap/geometry.py": {"u_axis", "v_axis"},
}


def test_kit_holds_no_lookup_code(kit):
    pattern = re.compile(rb"\b(" + b"|".join(n.encode() for n in lookup_names()) + rb")\b")
    found = {}
    for path in kit_files(kit.folder):
        hits = {h.decode() for h in pattern.findall(path.read_bytes())}
        rel = path.relative_to(kit.folder).as_posix()
        if hits - NAMED_NOT_HELD.get(rel, set()):
            found[rel] = sorted(hits - NAMED_NOT_HELD.get(rel, set()))
    assert not found, f"reference lookup names in the kit: {found}"
    names = {Path(n).name for n in kit.files}
    assert "lookup.c" not in names and "reference_submission.c" not in names
    for header in ("renderer/include/envmap.h", "selfcheck/reference/include/envmap.h"):
        text = (kit.folder / header).read_text()
        assert "em_render" in text and "em_lookup_fn" in text and "em_cubemap_load_cross" in text
        assert "em_fetch" not in text and "em_filter" not in text


# slow: the kit unpacked alone and built from nothing (3-4 s), then make run or a self-check in it (2-8 s each); test-fast keeps the kit's contents tests
@pytest.mark.representative
@pytest.mark.slow
def test_built_binaries_have_no_lookup_symbols(alone):
    run, summary = selfcheck(alone, CORRECT[0])
    assert summary is not None, run.stdout + run.stderr
    built = alone / "selfcheck" / "build"
    binaries = [alone / "envmap", built / "libenvmap.so", built / "worker", *sorted(built.rglob("*.so")),
                *sorted((alone / "build").rglob("*.o")), *sorted(built.rglob("*.o")), *sorted(built.rglob("*.a"))]
    assert (built / "libenvmap.so") in binaries and len([b for b in binaries if b.suffix == ".so"]) >= 2
    names = set(lookup_names())
    for binary in binaries:
        nm = subprocess.run(["nm", "-C", str(binary)], capture_output=True, text=True, check=True).stdout
        symbols = {line.split()[-1] for line in nm.splitlines() if line.strip()}
        assert not symbols & names, f"{binary.relative_to(alone)}: {sorted(symbols & names)}"
    nm = subprocess.run(["nm", "-D", str(built / "libenvmap.so")], capture_output=True, text=True, check=True).stdout
    assert "em_trace" in nm and "em_resolve" in nm


def test_the_kit_ships_the_graders_own_modules_and_nothing_more(kit):
    package = kit.folder / "selfcheck" / "grader"
    shipped = sorted(p.relative_to(package).as_posix() for p in package.rglob("*.py"))
    assert shipped == grader_modules()
    for rel in shipped:     # byte copies: the kit runs the grader's code, not a restatement of it
        assert (package / rel).read_bytes() == (PROJECT_ROOT / "grader" / rel).read_bytes(), rel
    # What the self-check runs is there, what it never runs is not.
    for rel in ("kit/selfcheck.py", "grading/grade.py", "build/__init__.py", "worker/runner.py", "reports/html.py",
                "grading/catalogue.py", "checks/read_texture.py", "checks/renders.py", "envmap/oracle.py"):
        assert rel in shipped, rel
    for rel in ("kit/build.py", "kit/answers.py", "cli.py", "commands/grade.py", "course/grade_all.py",
                "platforms/gradescope.py", "study/chart.py", "kit/data.py"):
        assert rel not in shipped, rel
    assert not (package / "worker" / "null_submission.c").exists()


def test_kit_holds_no_secret_no_hidden_check_and_nothing_from_tests_or_examples(kit):
    rubric = load_rubric()
    secret = str(rubric["grading"]["secret"]).encode()
    ours = {hashlib.sha256(p.read_bytes()).hexdigest(): p for p in
            [*(PROJECT_ROOT / "tests").rglob("*"), *(PROJECT_ROOT / "examples").rglob("*")] if p.is_file() and p.stat().st_size > 64}
    # (examples/ has the untouched template, which the kit starts from too.)
    for path in (PROJECT_ROOT / "student_template").rglob("*"):
        if path.is_file():
            ours.pop(hashlib.sha256(path.read_bytes()).hexdigest(), None)
    for path in kit_files(kit.folder):
        data = path.read_bytes()
        assert secret not in data, path
        assert hashlib.sha256(data).hexdigest() not in ours, f"{path} is a copy of {ours.get(hashlib.sha256(data).hexdigest())}"
    shipped = tomllib.loads((kit.folder / "selfcheck" / "grader" / "grading" / "rubric.toml").read_text())
    assert "secret" not in json.dumps(shipped) and set(shipped) == {"grading", "checks"}
    assert shipped["checks"] == rubric["checks"]      # every check is visible today, with its points and settings
    assert shipped["grading"] == {"language": rubric["grading"]["language"]}


def test_a_rubric_with_a_hidden_check_cannot_make_a_kit():
    rubric = load_rubric()
    rubric["checks"]["stability"]["visibility"] = "after_due_date"
    with pytest.raises(KitError, match="stability is not visible"):
        visible_rubric(rubric)


def test_kit_header_cut_is_exact():
    original = (PROJECT_ROOT / "reference" / "include" / "envmap.h").read_text()
    cut = kit_header(original)
    assert "em_fetch" in original and "em_fetch" not in cut and "em_filter" not in cut
    # Everything else is kept verbatim.
    assert "int em_render(const em_scene *scene, em_lookup_fn lookup" in cut
    assert cut.count("#ifdef __cplusplus") == 2


# slow: the kit zipped twice (4-5 s)
@pytest.mark.slow
def test_zip_is_reproducible(kit, tmp_path):
    time.sleep(2)       # zip members carry times to 2 s: a build in the same second would prove nothing
    again = build_kit(tmp_path / "student-kit")
    assert again.zip_path.read_bytes() == kit.zip_path.read_bytes()
    # 6.4 MB in December 2026: the recorded answers (4.8 MB) and the maps twice
    # (the kit's own and the self-check's pristine copies).
    assert kit.size < 8_000_000


def test_template_is_the_kit_starting_point(kit):
    assert (kit.folder / "EnvironmentMap.cpp").read_bytes() == TEMPLATE_SOURCE.read_bytes()
    for name in ("EnvironmentMap.h", "Vector3.h", "Color.h", "EnvironmentMapLoader.cpp"):
        assert (kit.folder / name).read_bytes() == (PROJECT_ROOT / "student_template" / name).read_bytes()


# ---- the kit alone: make run, make selfcheck ------------------------------------------


# slow: the kit unpacked alone and built from nothing (3-4 s), then make run or a self-check in it (2-8 s each); test-fast keeps the kit's contents tests
@pytest.mark.slow
def test_make_run_writes_a_compressed_png(alone):
    shutil.copyfile(TEMPLATE_SOURCE, alone / "EnvironmentMap.cpp")     # black: other tests leave their file
    run = subprocess.run(["make", "-s", "run"], cwd=alone, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    png = (alone / "out.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")
    assert (width, height) == (512, 512)
    assert len(png) < 50_000        # black: the stored (uncompressed) writer gave 787 KB
    assert (alone / "out.hdr").is_file()


# slow: the kit unpacked alone and built from nothing (3-4 s), then make run or a self-check in it (2-8 s each); test-fast keeps the kit's contents tests
@pytest.mark.slow
def test_selfcheck_of_the_template_in_the_kit_alone(alone, environment):
    run, summary = selfcheck(alone, TEMPLATE_SOURCE, env=environment)
    assert run.returncode == 0, run.stdout + run.stderr
    assert summary["extra_data"]["max_score"] == VISIBLE_POINTS
    assert [t["extra_data"]["check"] for t in summary["tests"]] == [
        n for n, e in load_rubric()["checks"].items() if e.get("visibility", "visible") == "visible" and n not in NOT_IN_KIT]
    # Nothing for the starting code (issue 30): 0 on every check, and why.
    assert summary["score"] == 0 and {t["score"] for t in summary["tests"]} == {0}
    assert {"not-implemented", "nearest-neighbor"} <= ids(summary)
    # The grader's report, and the grader's results.json under the kit's name.
    out = alone / "build" / "selfcheck"
    assert (out / "results.json").read_bytes() == (out / "selfcheck.json").read_bytes()
    md = (out / "report.md").read_text()
    assert f"**Score: {summary['score']:g} / {VISIBLE_POINTS:g}**" in md
    page = (out / "report.html").read_text()
    # Self-contained: no script, nothing fetched from elsewhere.
    assert page.startswith("<!DOCTYPE html>") and "<script" not in page and "default-src 'none'" in page
    assert not re.search(r'(src|href)="(https?:)?//', page)
    assert f"{summary['score']:g} / {VISIBLE_POINTS:g}" in page
    isolation = summary["extra_data"]["isolation"]
    assert isolation == ("bubblewrap" if "SELFCHECK_PYTHON" in environment and "fakebin" not in environment["PATH"]
                         else "privilege-drop" if os.geteuid() == 0 else "own-machine"), isolation


# slow: the student kit built, then make selfcheck or a workflow run in it (6-16 s each)
@pytest.mark.slow
def test_fail_under_is_a_percentage_of_the_visible_points(alone):
    run, summary = selfcheck(alone, CORRECT[0], "FAIL_UNDER=100")
    assert run.returncode == 0, run.stdout + run.stderr
    assert summary["score"] == VISIBLE_POINTS and not summary["extra_data"]["diagnoses"]
    run, summary = selfcheck(alone, PARTLY_RIGHT)
    percent = 100 * summary["score"] / VISIBLE_POINTS       # e.g. 80 points of 95: 84.2 %
    assert summary["score"] < int(percent) + 1 < 100
    # Read as points, FAIL_UNDER=<percent rounded down> would fail: as a percentage it passes.
    assert selfcheck(alone, None, f"FAIL_UNDER={int(percent)}")[0].returncode == 0
    below = selfcheck(alone, None, f"FAIL_UNDER={int(percent) + 1}")[0]
    assert below.returncode != 0 and f"FAIL_UNDER={int(percent) + 1}%" in below.stdout


# slow: the student kit built, then make selfcheck or a workflow run in it (6-16 s each)
@pytest.mark.slow
def test_the_kit_reports_in_japanese_with_its_compiled_catalogue(alone):
    # The kit carries grader.mo, not the .po: its Japanese must be whole without Babel.
    from test_i18n import english_sentences
    assert not list((alone / "selfcheck").rglob("*.po"))
    source = WRONG / "u-flipped-pos-x.cpp"
    run, english = selfcheck(alone, source, "REPORT_LANG=en")
    assert run.returncode == 0, run.stdout + run.stderr
    run, japanese = selfcheck(alone, source, "REPORT_LANG=ja")
    assert run.returncode == 0, run.stdout + run.stderr
    assert japanese["score"] == english["score"] and ids(japanese) == ids(english) == {"u-flipped"}
    md = (alone / "build" / "selfcheck" / "report.md").read_text()
    assert "## まず直すところ" in md     # the heading above the diagnosis, in Japanese (not only a word of it)
    assert english_sentences(md, "EnvironmentMap") == []


# slow: the student kit built, then make selfcheck or a workflow run in it (6-16 s each)
@pytest.mark.representative
@pytest.mark.slow
def test_selfcheck_names_a_crash(alone, tmp_path):
    source = tmp_path / "crash.cpp"
    source.write_text(TEMPLATE_SOURCE.read_text().replace(
        "    (void)direction; // delete this line once you use `direction`\n",
        "    if (direction.x > 0.5) { volatile int* p = nullptr; return Color(*p, 0, 0); }\n"))
    run, summary = selfcheck(alone, source)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "crash" in ids(summary)


# slow: the kit unpacked alone and built from nothing (3-4 s), then make run or a self-check in it (2-8 s each); test-fast keeps the kit's contents tests
@pytest.mark.representative
@pytest.mark.slow
def test_a_submission_calling_the_reference_lookup_is_refused_as_the_grader_refuses_it(alone, tmp_path):
    source = tmp_path / "cheat.cpp"
    source.write_text(TEMPLATE_SOURCE.read_text().replace(
        "    (void)direction; // delete this line once you use `direction`\n",
        "    double rgb[3];\n    em_fetch(nullptr, EM_FILTER_BILINEAR, direction.x, direction.y, direction.z, rgb);\n")
        .replace('#include "EnvironmentMap.h"\n', '#include "EnvironmentMap.h"\n#include "envmap.h"\n'))
    run, summary = selfcheck(alone, source)
    assert run.returncode != 0
    assert summary["score"] == 0 and summary["extra_data"]["status"] == "build-error"
    assert ids(summary) == {"build-error"}      # envmap.h is not there to include, as in the grader
    assert "envmap.h" in (alone / "build" / "selfcheck" / "report.md").read_text()


# slow: the student kit built, then make selfcheck or a workflow run in it (6-16 s each)
@pytest.mark.slow
def test_selfcheck_html_escapes_what_the_submission_prints(alone, tmp_path):
    source = tmp_path / "hostile.cpp"
    source.write_text(TEMPLATE_SOURCE.read_text().replace(
        "    (void)direction; // delete this line once you use `direction`\n",
        '    if (direction.x > 0.9) throw std::runtime_error("<script>alert(1)</script>");\n')
        .replace("#include <algorithm>\n", "#include <algorithm>\n#include <stdexcept>\n"))
    run, summary = selfcheck(alone, source)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "exception" in ids(summary)
    page = (alone / "build" / "selfcheck" / "report.html").read_text()
    assert "<script>" not in page and "&lt;script&gt;" in page


# slow: the kit unpacked alone and built from nothing (3-4 s), then make run or a self-check in it (2-8 s each); test-fast keeps the kit's contents tests
@pytest.mark.slow
def test_a_submission_that_does_not_compile_gets_a_report(alone):
    run, summary = selfcheck(alone, TESTS / "submissions" / "build" / "syntax_error.cpp")
    assert run.returncode != 0
    assert summary["extra_data"]["status"] == "build-error" and summary["score"] == 0
    report = (alone / "build" / "selfcheck" / "report.md").read_text()
    assert "error" in report


# slow: the student kit built, then make selfcheck or a workflow run in it (6-16 s each)
@pytest.mark.slow
@pytest.mark.slow
@pytest.mark.parametrize("compiler", [("gcc", "g++"), ("clang", "clang++")])
def test_cmake_build_and_selfcheck(kit, tmp_path, compiler):
    cc, cxx = compiler
    if not shutil.which(cxx) or not shutil.which("cmake"):
        pytest.skip(f"{cxx} or cmake not installed")
    folder = tmp_path / "kit"
    shutil.copytree(kit.folder, folder)
    shutil.copyfile(CORRECT[0], folder / "EnvironmentMap.cpp")
    env = kit_environment(CC=cc, CXX=cxx)
    for cmd in (["cmake", "-S", ".", "-B", "build-cmake", f"-DSELFCHECK_PYTHON={sys.executable}"],
                ["cmake", "--build", "build-cmake", "-j2"],
                ["cmake", "--build", "build-cmake", "--target", "selfcheck"], ["cmake", "--build", "build-cmake", "--target", "run"]):
        run = subprocess.run(cmd, cwd=folder, capture_output=True, text=True, timeout=600, env=env)
        assert run.returncode == 0, " ".join(cmd) + "\n" + run.stdout[-3000:] + run.stderr[-3000:]
        assert "warning" not in run.stdout.lower() + run.stderr.lower(), run.stdout + run.stderr
    summary = json.loads((folder / "build-cmake" / "selfcheck" / "selfcheck.json").read_text())
    assert summary["score"] == VISIBLE_POINTS
    assert (folder / "out.png").read_bytes()[:4] == b"\x89PNG"


# ---- the report is selfcheck's own -------------------------------------------------------

# A static initialiser in the student's own file (the template, otherwise
# untouched), run when the worker loads it: it tries to open a file in the
# report folder (absolute path, filled in below); where it can, it leaves a
# daemon that has left the worker's session (setsid) and its tree (double
# fork), waits until the self-check has exited, then writes full marks into
# both report files. Where it cannot, the report says why (the worker refuses
# the open, or the initialiser aborts): proof that it ran.
REPORT_REWRITER = r'''
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>
#include <cstdio>
#include <cstdlib>
namespace {
const char* const OUT = "@OUT@";
void rewrite(const char* name, const char* text) {
    char path[4096];
    std::snprintf(path, sizeof path, "%s/%s", OUT, name);
    if (FILE* f = std::fopen(path, "w")) { std::fputs(text, f); std::fclose(f); }
}
struct Rewriter {
    Rewriter() {
        char mark[4096];
        std::snprintf(mark, sizeof mark, "%s/.rewriter", OUT);
        int fd = open(mark, O_CREAT | O_WRONLY, 0644);
        if (fd < 0) std::abort();               // cannot reach the reports: say so by crashing
        close(fd);
        if (fork() != 0) return;                // the worker goes on as usual
        setsid();
        if (fork() != 0) _exit(0);
        int null = open("/dev/null", O_RDWR);
        dup2(null, 0); dup2(null, 1); dup2(null, 2);
        sleep(20);
        rewrite("report.md", "# Self-check\n\n**Score: 95 / 95**\n");
        rewrite("selfcheck.json", "{\"score\": 95, \"tests\": []}\n");
        _exit(0);
    }
} rewriter;
}
'''


# slow: the student kit built, then make selfcheck or a workflow run in it (6-16 s each)
@pytest.mark.slow
@pytest.mark.slow
def test_the_students_code_cannot_reach_the_reports(alone, tmp_path, environment):
    folder = tmp_path / "kit"
    shutil.copytree(alone, folder, symlinks=True)
    out = folder / "build" / "selfcheck"
    out.mkdir(parents=True, exist_ok=True)
    (folder / "EnvironmentMap.cpp").write_text(TEMPLATE_SOURCE.read_text() + REPORT_REWRITER.replace("@OUT@", str(out)))
    run = subprocess.run(["make", "-s", "selfcheck"], cwd=folder, capture_output=True, text=True, timeout=600,
                         env=environment)
    assert run.returncode == 0, run.stdout + run.stderr
    printed = re.search(r"^\S+\s+([\d.]+) / ([\d.]+)\s", run.stdout, re.M)
    assert printed and float(printed[1]) < float(printed[2]), run.stdout
    summary = json.loads((out / "selfcheck.json").read_text())
    assert not (out / ".rewriter").exists(), "the submission wrote into the report folder"
    # It ran, and the worker stopped it (its seccomp filter refuses open(), or it aborted).
    assert summary["score"] == float(printed[1]) and ids(summary) & {"forbidden-syscall", "crash"}, ids(summary)
    assert f"**Score: {printed[1]} / {printed[2]}**" in (out / "report.md").read_text()


# ---- the workflow (GitHub Actions; any CI reads what it leaves) ------------------------------

WORKFLOW = PROJECT_ROOT / "student_template" / ".github" / "workflows" / "grade.yml"
EXPRESSION = re.compile(r"\$\{\{\s*([^}]*?)\s*\}\}")


def workflow() -> dict:
    yaml = pytest.importorskip("yaml", reason="PyYAML reads the workflow (not in requirements.lock yet)")
    return yaml.safe_load(WORKFLOW.read_text())


def test_the_workflow_needs_no_classroom_reporter_and_gives_its_points_as_outputs():
    """Classroom's grading reporter is deprecated (Classroom's autograding is
    sunset): the workflow uses GitHub's own actions only, and its points are
    the job's outputs, from the step that computes them."""
    flow = workflow()
    assert "classroom-resources" not in WORKFLOW.read_text()
    (job,) = flow["jobs"].values()
    assert [s["uses"].split("@")[0] for s in job["steps"] if "uses" in s] == ["actions/checkout", "actions/upload-artifact"]
    assert job["outputs"] == {"points": "${{ steps.points.outputs.points }}",
                              "max_points": "${{ steps.points.outputs.max_points }}"}
    assert any(s.get("id") == "points" for s in job["steps"])
    artifact = [s for s in job["steps"] if s.get("uses", "").startswith("actions/upload-artifact")][0]
    assert "junit.xml" in artifact["with"]["path"] and "report.html" in artifact["with"]["path"]


def run_workflow(repo: Path) -> dict:
    """The workflow's steps as GitHub runs them, in `repo`: each `run` in bash
    (-e, as GitHub's default shell), ${{ }} filled in (step outputs, no
    repository variables), GITHUB_OUTPUT and GITHUB_STEP_SUMMARY as files;
    after a step fails, only the steps whose `if` says always() run."""
    outputs: dict[str, dict[str, str]] = {}
    printed: dict[str, str] = {}
    failed = []
    summary = repo.parent / f"{repo.name}-summary.md"
    (job,) = workflow()["jobs"].values()

    def fill(text: str) -> str:
        def value(m):
            expr = m.group(1)
            found = re.fullmatch(r"steps\.([\w-]+)\.outputs\.(\w+)", expr)
            if found:
                return outputs.get(found[1], {}).get(found[2], "")
            assert expr.startswith("vars."), f"an expression this test cannot fill: {expr}"
            return ""
        return EXPRESSION.sub(value, str(text))

    for step in job["steps"]:
        if "run" not in step or (failed and "always()" not in str(step.get("if", ""))):
            continue
        output = repo.parent / f"{repo.name}-output-{len(outputs)}"
        output.write_text("")
        cwd = repo / fill(step.get("working-directory", "."))
        env = {k: fill(v) for k, v in step.get("env", {}).items()}
        run = subprocess.run(["bash", "--noprofile", "--norc", "-eo", "pipefail", "-c", fill(step["run"])], cwd=cwd,
                             capture_output=True, text=True, timeout=300,
                             env=kit_environment(GITHUB_OUTPUT=str(output), GITHUB_STEP_SUMMARY=str(summary), **env))
        name = step.get("id", step["name"])
        if run.returncode != 0:
            failed.append(name)
        printed[name] = run.stdout
        outputs[name] = dict(line.split("=", 1) for line in output.read_text().splitlines() if "=" in line)
    return {"outputs": outputs, "printed": printed, "failed": failed, "summary": summary.read_text()}


# slow: the student kit built, then make selfcheck or a workflow run in it (6-16 s each)
@pytest.mark.slow
@pytest.mark.parametrize("layout", ["kit-is-the-root", pytest.param("kit-in-a-folder", marks=pytest.mark.slow)])
def test_the_workflow_runs_in_a_repository_made_from_the_kit(alone, tmp_path, layout):
    workflow()   # skips here, not half-way, without PyYAML
    repo = tmp_path / "repo"
    kit = repo if layout == "kit-is-the-root" else repo / "student-kit"
    shutil.copytree(alone, kit, symlinks=True)
    shutil.rmtree(kit / "build" / "selfcheck", ignore_errors=True)
    (kit / "EnvironmentMap.cpp").write_text(PARTLY_RIGHT.read_text())   # partial credit
    assert (kit / ".github" / "workflows" / "grade.yml").read_text() == WORKFLOW.read_text()   # the kit's own
    ran = run_workflow(repo)
    assert ran["failed"] == []
    assert ran["outputs"]["kit"]["dir"] == ("." if layout == "kit-is-the-root" else "./student-kit")
    summary = json.loads((kit / "build" / "selfcheck" / "selfcheck.json").read_text())
    # The job's outputs hold the score the self-check printed, partial credit included.
    points = ran["outputs"]["points"]
    assert (float(points["points"]), float(points["max_points"])) == (pytest.approx(summary["score"]), VISIBLE_POINTS)
    assert 0 < summary["score"] < VISIBLE_POINTS
    assert ran["summary"].startswith(f"**Points: {summary['score']:g} / {VISIBLE_POINTS:g}**")
    assert "::error" not in ran["printed"]["points"]       # no diagnosis names a line here
    assert f"**Score: {summary['score']:g} / {VISIBLE_POINTS:g}**" in ran["summary"]


def test_a_compile_error_is_annotated_on_the_students_line(alone, tmp_path):
    """The compiler's line (22 in the zoo's syntax error, as the build-error
    diagnosis names it) becomes a GitHub annotation on EnvironmentMap.cpp;
    the points say 0 of the visible."""
    workflow()
    repo = tmp_path / "repo"
    shutil.copytree(alone, repo, symlinks=True)
    shutil.rmtree(repo / "build" / "selfcheck", ignore_errors=True)
    shutil.copy(PROJECT_ROOT / "tests" / "submissions" / "build" / "syntax_error.cpp", repo / "EnvironmentMap.cpp")
    ran = run_workflow(repo)
    assert ran["failed"] == ["Visible checks"]                 # make selfcheck exits 1: the run is red
    annotations = [line for line in ran["printed"]["points"].splitlines() if line.startswith("::error ")]
    assert len(annotations) == 1, ran["printed"]["points"]
    assert annotations[0].startswith("::error file=EnvironmentMap.cpp,line=22,title=build-error::")
    assert "expected primary-expression" in annotations[0]
    assert ran["outputs"]["points"] == {"points": "0", "max_points": f"{VISIBLE_POINTS:g}"}
