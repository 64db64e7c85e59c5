"""scripts/install-system-deps.sh picks packages by what apt can install on
Debian 12, Ubuntu 22.04 and Ubuntu 24.04, and says why when it cannot.

apt is replaced by small fakes on PATH (dpkg, dpkg-query, apt-cache,
apt-get, id) that answer as each system's apt does; the fake apt-get
records what it was asked to install.
"""
from __future__ import annotations

import ast
import functools
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from grader import PROJECT_ROOT

SCRIPT = PROJECT_ROOT / "scripts" / "install-system-deps.sh"

# What `apt-cache policy` offers on each system (package -> candidate version).
SYSTEMS = {
    "Debian GNU/Linux 12 (bookworm)": {
        "gcc": "4:12.2.0-3", "g++": "4:12.2.0-3", "make": "4.3-4.1", "python3-venv": "3.11.2-1+b1",
        "bubblewrap": "0.8.0-2+deb12u1", "unzip": "6.0-28", "libstb-dev": "0.0~git20220908.8b5f1f3+ds-1", "chromium": "156.0-1~deb12u1", "clang": "1:14.0-55.7~deb12u1",
        "libclang-rt-14-dev": "1:14.0.6-12", "libclang-common-14-dev": "1:14.0.6-12",
        "fonts-ipafont-gothic": "00303-23", "fonts-noto-cjk": "1:20220127+repack1-1"},
    "Ubuntu 22.04.5 LTS": {
        "gcc": "4:11.2.0-1ubuntu1", "g++": "4:11.2.0-1ubuntu1", "make": "4.3-4.1build1",
        "python3-venv": "3.10.6-1~22.04", "bubblewrap": "0.6.1-1ubuntu0.1", "unzip": "6.0-26ubuntu3.2", "libstb-dev": "0.0~git20210910.af1a5bc+ds-1", "chromium-browser": "1:85.0-0ubuntu2",
        "clang": "1:14.0-55~exp2", "libclang-common-14-dev": "1:14.0.0-1ubuntu1.1",
        "fonts-ipafont-gothic": "00303-21ubuntu1", "fonts-noto-cjk": "1:20220127+repack1-1"},
    "Ubuntu 24.04.1 LTS": {
        "gcc": "4:13.2.0-7ubuntu1", "g++": "4:13.2.0-7ubuntu1", "make": "4.3-4.1build2",
        "python3-venv": "3.12.3-0ubuntu2", "bubblewrap": "0.9.0-1ubuntu0.1", "unzip": "6.0-28ubuntu4", "libstb-dev": "0.0~git20230129.5736b15+ds-1", "chromium-browser": "2:1snap1-0ubuntu2",
        "clang": "1:18.0-59~exp2", "libclang-rt-14-dev": "1:14.0.6-19build4", "libclang-rt-18-dev": "1:18.1.3-1ubuntu1",
        "libclang-common-18-dev": "1:18.1.3-1ubuntu1",
        "fonts-ipafont-gothic": "00303-21ubuntu1", "fonts-noto-cjk": "1:20230817+repack1-3"},
}

FAKES = {
    # dpkg -s NAME: installed when NAME is in $FAKE_INSTALLED
    "dpkg": '[ "$1" = -s ] && case " $FAKE_INSTALLED " in *" $2 "*) echo "Status: install ok installed"; exit 0;; esac; exit 1',
    "dpkg-query": "exit 1",
    # apt-cache policy NAME: its candidate from $FAKE_AVAILABLE ("name=version ...")
    "apt-cache": 'for kv in $FAKE_AVAILABLE; do [ "${kv%%=*}" = "$2" ] && { echo "$2:"; echo "  Installed: (none)";'
                 ' echo "  Candidate: ${kv#*=}"; exit 0; }; done; exit 0',
    "apt-get": 'echo "$*" >> "$FAKE_LOG"',
    "id": "echo 0",
}


def run_script(tmp_path: Path, system: str, installed: list[str], *groups: str, root: bool = True):
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir(exist_ok=True)
    for name, body in FAKES.items():
        if name == "id" and not root:
            body = "echo 1000"
        (bin_dir / name).write_text("#!/bin/bash\n" + body + "\n")
        (bin_dir / name).chmod(0o755)
    os_release = tmp_path / "os-release"
    os_release.write_text(f'PRETTY_NAME="{system}"\n')
    log = tmp_path / "apt.log"
    log.write_text("")
    env = {**os.environ, "PATH": f"{bin_dir}:{os.environ['PATH']}", "APT_OS_RELEASE": str(os_release),
           "FAKE_INSTALLED": " ".join(installed), "FAKE_LOG": str(log),
           "FAKE_AVAILABLE": " ".join(f"{k}={v}" for k, v in SYSTEMS[system].items())}
    done = subprocess.run(["bash", str(SCRIPT), *groups], env=env, capture_output=True, text=True, timeout=60)
    installs = [line.split() for line in log.read_text().splitlines() if line.startswith("install")]
    return done, [p for line in installs for p in line if not p.startswith("-") and p != "install"]


def test_nothing_missing_does_nothing(tmp_path):
    everything = list(SYSTEMS["Debian GNU/Linux 12 (bookworm)"])
    done, installed = run_script(tmp_path, "Debian GNU/Linux 12 (bookworm)", everything)
    assert done.returncode == 0 and installed == [] and done.stdout == ""


def test_debian_12_installs_everything(tmp_path):
    done, installed = run_script(tmp_path, "Debian GNU/Linux 12 (bookworm)", [])
    assert done.returncode == 0, done.stderr
    assert installed == ["gcc", "g++", "make", "python3-venv", "libstb-dev", "fonts-ipafont-gothic", "bubblewrap",
                         "unzip", "chromium", "clang", "libclang-rt-14-dev"]
    assert "installing" in done.stdout   # progress, not silence


def test_ubuntu_22_04_uses_the_common_package_and_explains_chromium(tmp_path):
    done, installed = run_script(tmp_path, "Ubuntu 22.04.5 LTS", [])
    assert done.returncode == 0, done.stderr    # chromium is for a test only
    assert installed == ["gcc", "g++", "make", "python3-venv", "libstb-dev", "fonts-ipafont-gothic", "bubblewrap",
                         "unzip", "clang", "libclang-common-14-dev"]
    assert "cannot install chromium" in done.stderr and "Ubuntu 22.04.5 LTS" in done.stderr
    assert "snap" in done.stderr   # what it is for, and why Ubuntu has none


def test_ubuntu_24_04_matches_the_runtime_to_clang_18(tmp_path):
    done, installed = run_script(tmp_path, "Ubuntu 24.04.1 LTS", ["clang"])
    assert done.returncode == 0, done.stderr
    assert "libclang-rt-18-dev" in installed and "libclang-rt-14-dev" not in installed


def test_core_group_alone_is_what_grading_needs(tmp_path):
    done, installed = run_script(tmp_path, "Ubuntu 24.04.1 LTS", ["gcc", "g++", "make"], "core")
    assert done.returncode == 0, done.stderr
    assert installed == ["python3-venv", "fonts-ipafont-gothic", "bubblewrap"]


def test_a_core_package_apt_cannot_install_fails_and_says_why(tmp_path, monkeypatch):
    monkeypatch.setitem(SYSTEMS, "Odd Linux 1", {"gcc": "1", "g++": "1", "make": "1", "python3-venv": "1"})
    done, installed = run_script(tmp_path, "Odd Linux 1", [], "core")
    assert done.returncode == 1
    assert "cannot install bubblewrap" in done.stderr and "worker sandbox" in done.stderr
    assert installed == ["gcc", "g++", "make", "python3-venv"]   # the rest is still installed


def test_without_root_it_only_says_what_to_run(tmp_path):
    done, installed = run_script(tmp_path, "Debian GNU/Linux 12 (bookworm)", [], "core", root=False)
    assert done.returncode == 0 and installed == []
    assert "bubblewrap" in done.stderr and "sudo bash scripts/install-system-deps.sh core" in done.stderr


@pytest.mark.parametrize("line", [line for line in (PROJECT_ROOT / "packages.txt").read_text().splitlines()
                                  if line.strip() and not line.startswith("#")])
def test_every_package_says_what_it_is_for(line):
    fields, _, why = line.partition("#")
    assert len(fields.split()) == 2 and fields.split()[1] in ("core", "kit", "test") and len(why.strip()) > 10, line


# ---- scripts/make-venv.sh: which Python, and python3-venv ---------------------------------

MAKE_VENV = PROJECT_ROOT / "scripts" / "make-venv.sh"
FAKE_PYTHON = """#!/bin/bash
# A stand-in interpreter: VERSION is its version, NO_ENSUREPIP says whether `import ensurepip` fails.
VERSION={version}
NO_ENSUREPIP={no_ensurepip}
case "$*" in
  --version) echo "Python $VERSION";;
  *'version_info[0]'*) echo "${VERSION%.*}";;
  *version_info*) [ "${VERSION%.*}" != 3.10 ];;
  *ensurepip*) [ -z "$NO_ENSUREPIP" ];;
  *) exit 0;;
esac
"""


def run_make_venv(tmp_path: Path, pythons: dict[str, tuple[str, bool]], root: bool = False):
    """pythons: command -> (version, has ensurepip). Returns the finished process."""
    bin_dir = tmp_path / "pybin"
    bin_dir.mkdir(exist_ok=True)
    for name, (version, ensurepip) in pythons.items():
        (bin_dir / name).write_text(FAKE_PYTHON.replace("{version}", version)
                                    .replace("{no_ensurepip}", "" if ensurepip else "no"))
        (bin_dir / name).chmod(0o755)
    (bin_dir / "id").write_text(f"#!/bin/bash\necho {0 if root else 1000}\n")
    (bin_dir / "id").chmod(0o755)
    (bin_dir / "apt-get").write_text('#!/bin/bash\necho "apt-get $*" >> "$FAKE_LOG"\n')
    (bin_dir / "apt-get").chmod(0o755)
    for tool in ("grep", "cat"):      # nothing else from the real PATH: no real python3.x can be found
        (bin_dir / tool).symlink_to(shutil.which(tool))
    env = {"PATH": str(bin_dir), "FAKE_LOG": str(tmp_path / "apt.log")}
    return subprocess.run([shutil.which("bash"), str(MAKE_VENV), str(tmp_path / "venv"), str(PROJECT_ROOT / "requirements.lock"),
                           "python3"], env=env, capture_output=True, text=True, timeout=60)


def test_make_venv_refuses_python_3_10_and_says_what_to_install(tmp_path):
    done = run_make_venv(tmp_path, {"python3": ("3.10.12", True)})
    assert done.returncode == 1
    assert "needs Python 3.11 or later; python3 is Python 3.10.12" in done.stderr
    assert "apt-get install python3.11 python3.11-venv" in done.stderr


def test_make_venv_names_the_venv_package_when_ensurepip_is_missing(tmp_path):
    done = run_make_venv(tmp_path, {"python3": ("3.10.12", True), "python3.12": ("3.12.3", False)})
    assert done.returncode == 1       # python3.12 chosen over the old python3, but it cannot make a venv
    assert "python3.12 cannot create a virtual environment" in done.stderr
    assert "sudo apt-get install python3.12-venv" in done.stderr


def test_make_venv_installs_the_venv_package_as_root(tmp_path):
    run_make_venv(tmp_path, {"python3": ("3.11.2", False)}, root=True)
    log = (tmp_path / "apt.log").read_text()
    assert "install -y -q --no-install-recommends python3.11-venv" in log


# ---- packages.txt against what the code runs ----------------------------------------------

# Who provides each program the Python code and tests run: a package of
# packages.txt, or "base:" and why it is there without one (Debian's and
# Ubuntu's essential packages, or the clone itself).
PROVIDED_BY = {
    "cc": "gcc", "gcc": "gcc", "g++": "g++", "make": "make", "bwrap": "bubblewrap",
    "chromium": "chromium", "unzip": "unzip", "clang": "clang",
    "nm": "base: binutils, which gcc depends on",
    "bash": "base: essential", "true": "base: coreutils (essential)", "sleep": "base: coreutils (essential)",
    "mktemp": "base: coreutils (essential)", "tar": "base: essential",
    "setpriv": "base: util-linux (essential)", "find": "base: findutils (essential)",
    "git": "base: the clone itself (bench/bench_compare.py archives a commit)",
    "cmake": "optional: tests/kit/test_kit.py skips its CMake build without it",
    "hadolint": "optional: tests/platforms/test_prairielearn.py lints the Dockerfile with it when installed",
    "dpkg": "optional: tests/unit/i18n/test_languages.py asks which package the font found came from, and skips without it",
}
CALLS = ("run", "Popen", "check_output", "check_call", "call")


def _programs_run_by(path: Path) -> set[str]:
    """Programs a Python file runs: the first word of every subprocess call
    and every shutil.which() name, resolving module-level string constants
    and list prefixes (CXX = "g++"; NOBODY = ["setpriv", ...]; [*NOBODY, ...])."""
    tree = ast.parse(path.read_text(), str(path))
    constants: dict[str, ast.expr] = {}
    for node in tree.body:
        if isinstance(node, ast.Assign):
            for target, value in _pairs(node.targets, node.value):
                if isinstance(value, (ast.Constant, ast.List)):
                    constants[target] = value

    def first_word(node) -> str | None:
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            return node.value
        if isinstance(node, ast.Name) and node.id in constants:
            return first_word(constants[node.id])
        if isinstance(node, ast.List) and node.elts:
            head = node.elts[0]
            return first_word(head.value if isinstance(head, ast.Starred) else head)
        return None

    found = set()
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call) or not node.args or not isinstance(node.func, ast.Attribute):
            continue
        owner = node.func.value.id if isinstance(node.func.value, ast.Name) else ""
        if (owner, node.func.attr) == ("shutil", "which") or (owner == "subprocess" and node.func.attr in CALLS):
            word = first_word(node.args[0])
            if word and "/" not in word and not word.startswith("-"):
                found.add(word)
    return found


def _pairs(targets, value):
    """(name, value) of an assignment, tuples unpacked: CXX, CC = "g++", "gcc"."""
    for target in targets:
        if isinstance(target, ast.Name):
            yield target.id, value
        elif isinstance(target, ast.Tuple) and isinstance(value, ast.Tuple):
            for t, v in zip(target.elts, value.elts):
                if isinstance(t, ast.Name):
                    yield t.id, v


@functools.lru_cache(maxsize=None)
def programs_run() -> dict[str, list[str]]:
    """Program -> the files that run it, over the grader, tests, bench and the kit."""
    where: dict[str, list[str]] = {}
    for folder in ("grader", "tests", "bench", "student_template", "scripts"):
        for path in sorted((PROJECT_ROOT / folder).rglob("*.py")):
            for program in _programs_run_by(path):
                where.setdefault(program, []).append(str(path.relative_to(PROJECT_ROOT)))
    return where


def listed_packages() -> set[str]:
    names = set()
    for line in (PROJECT_ROOT / "packages.txt").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            names |= set(line.split()[0].split("|"))
    return names


# slow: a mutant built and its truth decided per case (5-12 s); crashing0, wrong and not-compiling stay fast
@pytest.mark.slow
def test_the_scan_finds_what_the_code_is_known_to_run():
    """Not vacuous: the compilers, the sandbox, the browser and unzip are all found."""
    found = programs_run()
    assert {"g++", "gcc", "cc", "bwrap", "chromium", "unzip", "nm", "setpriv", "make"} <= set(found), sorted(found)


def test_every_program_the_code_runs_comes_from_packages_txt_or_the_base_system():
    listed = listed_packages()
    unknown = {p: files for p, files in programs_run().items() if p not in PROVIDED_BY}
    assert not unknown, f"programs run with no known provider (add them to PROVIDED_BY and packages.txt): {unknown}"
    missing = {p: pkg for p, pkg in PROVIDED_BY.items() if ":" not in pkg and pkg not in listed}
    assert not missing, f"programs whose package is not in packages.txt: {missing}"
