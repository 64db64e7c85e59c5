"""The student kit's Python environment (issue 20): what it installs, that the
grader's kit-side code runs in it without the heavy packages, and the
first-use bootstrap (student_template/selfcheck/bootstrap.py).

The bootstrap's fast tests run it as a student would, in a folder laid out
like the kit (selfcheck/bootstrap.py, selfcheck/requirements-kit.txt and a
stand-in `grader.kit.selfcheck` that prints its arguments), with a fake pip
first on its PYTHONPATH (`python -m pip` finds it) that records each install
and answers as a real pip does when it works, is offline, or finds no wheel.
The real install (network, about 10-60 s) is marked slow.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import textwrap
import time
from importlib import metadata
from pathlib import Path

import pytest

from grader import PROJECT_ROOT, i18n
from grader.kit import environment
from test_lock import locked

BOOTSTRAP = PROJECT_ROOT / "student_template" / "selfcheck" / "bootstrap.py"
HEAVY = ("scipy", "skimage", "matplotlib", "babel", "PIL")
SETUP_FAILED = 3
BUDGET_BYTES = 100e6


# ---- requirements-kit.txt ---------------------------------------------------------------------

def pins_of(path: Path) -> dict[str, tuple[str, list[str]]]:
    """{canonical name: (version, hashes)} of a requirements file with hashes."""
    out = {}
    for block in re.split(r"\n(?=\S)", path.read_text()):
        m = re.match(r"([A-Za-z0-9._-]+)==([^\s;\\]+)", block)
        if m:
            out[environment.canonical(m[1])] = (m[2], re.findall(r"--hash=sha256:([0-9a-f]{64})", block))
    return out


def test_the_kit_requirements_are_the_locks_pins_and_hashes_of_what_the_kit_imports(tmp_path):
    path = environment.write_requirements(tmp_path)
    assert path == tmp_path / "requirements-kit.txt"
    pins, lock = pins_of(path), locked()
    # The kit's packages, and what they depend on (cffi needs pycparser, rich pygments and markdown-it-py,
    # jinja2 markupsafe, ...).
    assert set(pins) == {"numpy", "cffi", "pycparser", "openimageio", "flip-evaluator", "markdown-it-py", "mdurl",
                         "rich", "pygments", "jinja2", "markupsafe"}
    for name, (version, hashes) in pins.items():
        assert (version, sorted(hashes)) == (lock[name][0], sorted(lock[name][1])), name
        assert hashes
    assert not set(pins) & {"scipy", "scikit-image", "matplotlib", "babel", "pillow"}
    assert "# requires-python: >=3.11" in path.read_text()
    assert "pycparser==3.12 ; implementation_name != 'PyPy'" in path.read_text()     # markers kept


def test_every_dependency_the_installed_packages_declare_is_in_the_kit(tmp_path):
    """Checked against the packages' own metadata (Requires-Dist), not the lock's annotations."""
    from packaging.requirements import Requirement
    pins = pins_of(environment.write_requirements(tmp_path))
    for name in pins:
        for spec in metadata.requires(name) or []:
            req = Requirement(spec)
            if req.marker is None or req.marker.evaluate({"extra": ""}):
                assert environment.canonical(req.name) in pins, f"{name} needs {req.name}"


def test_a_package_missing_from_the_lock_fails_loudly(tmp_path):
    lock = tmp_path / "requirements.lock"
    text = environment.LOCK.read_text()
    lock.write_text(re.sub(r"^numpy==.*?(?=^\S)", "", text, flags=re.S | re.M))
    with pytest.raises(environment.LockError, match="does not pin numpy"):
        environment.write_requirements(tmp_path / "out", lock=lock)
    unhashed = tmp_path / "unhashed.lock"
    unhashed.write_text(re.sub(r"^(mdurl==\S+) \\\n(?:\s+--hash=\S+(?: \\)?\n)+", r"\1\n", text, flags=re.M))
    with pytest.raises(environment.LockError, match="no hashes for mdurl"):
        environment.write_requirements(tmp_path / "out", lock=unhashed)


# ---- the kit's code without the heavy packages -------------------------------------------------

def kit_site_packages(dest: Path) -> Path:
    """A site-packages of links to the kit's distributions only, as installed
    in this environment: what the kit's environment will hold."""
    dest.mkdir()
    for name in pins_of(environment.write_requirements(dest.parent / "req")):
        for top in {f.parts[0] for f in metadata.distribution(name).files if f.parts[0] != ".."}:
            source = Path(metadata.distribution(name).locate_file(top))
            if source.exists() and not (dest / top).exists():
                (dest / top).symlink_to(source)
    return dest


CLOSURE_SCRIPT = """
import sys
sys.path[:0] = [{tests!r}, {root!r}]
import grader.grading.grade, grader.checks, grader.reports
from grader.grading import score
from grader.checks import all_checks, run_checks
from grader.checks.context import CheckContext
from grader.grading.results import GradeResult
from fake_lookups import FakeLookups
from pathlib import Path
out = Path({out!r})
checks = [c for c in all_checks().values() if c.name != "speed"]
statuses = {{}}
result = GradeResult(submission="kit closure")
# Every check on a fetchColor mistake; the diagnosis again on an inset, which it maps (face_map.py).
for name, lookups, selected in (("u-flipped", FakeLookups(fetch={{"+X": "u-flipped"}}), None),
                                ("inset", FakeLookups(fetch="inset"), ["diagnosis"])):
    ctx = CheckContext(lookups=lookups, seed=1, artifacts=out / name / "images", quick=True)
    ran = run_checks(checks, ctx, selected).results
    statuses[name] = {{r.name: (r.status, r.error_log) for r in ran}}
    if name == "u-flipped":
        result.checks = ran
        arrows = next(r for r in ran if r.name == "arrows")
        statuses["arrows picture"] = {{"drawn": (str(Path(arrows.artifacts["arrows"]).is_file()),
                                                arrows.output)}} if "arrows" in arrows.artifacts else {{}}
    else:
        statuses[name]["ids"] = [d.id for r in ran for d in r.diagnoses]
score.apply(result, score.load_rubric())
grader.reports.write_all(result, out / "reports")
heavy = sorted({{m.split(".")[0] for m in sys.modules}} & set({heavy!r}))
import json
print(json.dumps({{"statuses": statuses, "heavy": heavy, "diagnoses": [d.id for d in result.diagnoses]}}))
"""


def test_the_kit_side_grader_runs_without_scipy_scikit_image_matplotlib_babel_or_pillow(tmp_path, reference_library):
    """In a Python that sees only the kit's packages (no site-packages but
    links to those requirements-kit.txt names): import the grade, checks
    and reports, run every check but speed on a fake submission (the per-face
    map and SSIM included) and write every report."""
    site = kit_site_packages(tmp_path / "site")
    script = CLOSURE_SCRIPT.format(tests=str(PROJECT_ROOT / "tests" / "helpers"), root=str(PROJECT_ROOT), out=str(tmp_path),
                                   heavy=HEAVY)
    done = subprocess.run([sys.executable, "-S", "-c", script], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": str(site)}, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    found = json.loads(done.stdout.strip().splitlines()[-1])
    assert found["heavy"] == []
    inset_ids = found["statuses"]["inset"].pop("ids")
    drawn, arrows_output = found["statuses"].pop("arrows picture")["drawn"]     # drawn without Pillow
    assert drawn == "True" and "could not be drawn" not in arrows_output
    for name, statuses in found["statuses"].items():
        errors = {check: log for check, (status, log) in statuses.items() if status == "error" or log}
        assert not errors, (name, errors)
    assert set(found["statuses"]["u-flipped"]) == {"read_texture", "fetch_sweep", "diagnosis", "arrows", "stability",
                                                    "renders"}
    assert "u-flipped" in found["diagnoses"] and inset_ids == ["uv-inset"]
    assert {p.name for p in (tmp_path / "reports").iterdir()} >= {"report.md", "report.html", "junit.xml",
                                                                  "results.json"}


def test_the_same_python_without_the_kit_links_cannot_import_the_grader(tmp_path):
    """The closure test above can fail: with no site-packages at all, numpy is missing."""
    done = subprocess.run([sys.executable, "-S", "-c", f"import sys; sys.path.insert(0, {str(PROJECT_ROOT)!r}); "
                           "import grader.checks.instruments.face_map"], capture_output=True, text=True, timeout=60,
                          env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"}, cwd=tmp_path)
    assert done.returncode != 0 and "numpy" in done.stderr


# ---- the catalogue without Babel ---------------------------------------------------------------

def test_a_copy_of_the_grader_reads_its_compiled_catalogue_without_babel(tmp_path):
    copy = tmp_path / "kit" / "grader"
    copy.mkdir(parents=True)
    for name in ("__init__.py", "i18n/__init__.py", "i18n/languages.py"):
        (copy / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(PROJECT_ROOT / "grader" / name, copy / name)
    locale = copy / "i18n" / "locale"
    written = i18n.compile_catalogues(locale)
    assert written == [locale / "ja" / "LC_MESSAGES" / "grader.mo"]
    from grader.grading.catalogue import CATALOGUE
    ids = [e.title_id for e in list(CATALOGUE.values())[:20]]
    babel = [i18n.translations("ja").gettext(i) for i in ids]
    assert sum(b != i for b, i in zip(babel, ids)) >= 15       # really translated
    script = textwrap.dedent(f"""
        import importlib.abc, json, sys
        class NoBabel(importlib.abc.MetaPathFinder):
            def find_spec(self, name, path=None, target=None):
                if name.split(".")[0] == "babel":
                    raise ImportError("no Babel in the kit")
        sys.meta_path.insert(0, NoBabel())
        sys.path.insert(0, {str(copy.parent)!r})
        from grader import i18n
        assert i18n.LOCALE_DIR == __import__("pathlib").Path({str(locale)!r})
        i18n.set_language("ja")
        print(json.dumps([i18n._(i) for i in {ids!r}]))
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == babel


def test_the_grader_never_compiles_into_its_own_catalogue_folder():
    with pytest.raises(ValueError, match="own catalogue"):
        i18n.compile_catalogues(i18n.LOCALE_DIR)
    assert not list(i18n.LOCALE_DIR.rglob("*.mo"))      # so the grader reads its .po (Babel)


# ---- the bootstrap ----------------------------------------------------------------------------

FAKE_PIP = '''
import json, os, sys
args = sys.argv[1:]
if args == ["--version"]:
    print("pip 24.0 from /fake/pip (python 3)")
    sys.exit(0)
with open(os.environ["FAKE_PIP_LOG"], "a") as log:
    log.write(json.dumps(args) + "\\n")
mode = os.environ.get("FAKE_PIP_MODE", "ok")
if mode == "offline":
    print("WARNING: Retrying (Retry(total=4)) after connection broken by 'NewConnectionError(\\"<pip._vendor.urllib3."
          "connection.HTTPSConnection>: Failed to establish a new connection: [Errno -3] Temporary failure in name "
          "resolution\\")': /simple/numpy/")
    print("ERROR: Could not install packages due to an OSError: HTTPSConnectionPool: Max retries exceeded")
    sys.exit(1)
if mode == "no-wheel":
    print("ERROR: Could not find a version that satisfies the requirement numpy==2.4.6 (from versions: none)")
    print("ERROR: No matching distribution found for numpy==2.4.6")
    sys.exit(1)
python = args[args.index("--python") + 1]
site = os.path.join(os.path.dirname(os.path.dirname(python)), "lib",
                    "python%d.%d" % sys.version_info[:2], "site-packages")
os.makedirs(os.path.join(site, "numpy", "_core", "tests"))
with open(os.path.join(site, "installed_by_fake_pip.py"), "w") as f:
    f.write("RUN = %d\\n" % sum(1 for _ in open(os.environ["FAKE_PIP_LOG"])))
'''

STAND_IN_SELFCHECK = '''
import sys
import installed_by_fake_pip
print("selfcheck ran", sys.argv[1:], "after install", installed_by_fake_pip.RUN)
sys.exit(int(sys.argv[sys.argv.index("--exit") + 1]) if "--exit" in sys.argv else 0)
'''


class Kit:
    """A folder laid out like the kit, with a fake pip for its bootstrap."""

    def __init__(self, root: Path):
        self.root = root
        selfcheck = root / "selfcheck"
        (selfcheck / "grader" / "kit").mkdir(parents=True)
        shutil.copy(BOOTSTRAP, selfcheck / "bootstrap.py")
        self.requirements = environment.write_requirements(selfcheck)
        for package in ("grader", "grader/kit"):
            (selfcheck / package / "__init__.py").write_text("")
        (selfcheck / "grader" / "kit" / "selfcheck.py").write_text(STAND_IN_SELFCHECK)
        self.fakes = root.parent / "fakes"
        (self.fakes / "pip").mkdir(parents=True, exist_ok=True)
        (self.fakes / "pip" / "__init__.py").write_text("")
        (self.fakes / "pip" / "__main__.py").write_text(FAKE_PIP)
        self.log = root.parent / "pip.log"
        self.env = root / "build" / "selfcheck-env"

    def run(self, *args: str, mode: str = "ok", python: str = sys.executable, extra_env: dict | None = None):
        # Without the suite's bytecode cache (Makefile PYTEST): the fake pip writes a same-sized module within
        # the same second into a folder renamed into place, which a cached .pyc keyed by path cannot tell apart.
        ours = {k: v for k, v in os.environ.items() if k != "PYTHONPYCACHEPREFIX"}
        env = {**ours, "PYTHONPATH": str(self.fakes), "FAKE_PIP_LOG": str(self.log), "FAKE_PIP_MODE": mode,
               **(extra_env or {})}
        return subprocess.run([python, "selfcheck/bootstrap.py", *args], cwd=self.root, env=env,
                              capture_output=True, text=True, timeout=120)

    def installs(self) -> list[list[str]]:
        return [json.loads(line) for line in self.log.read_text().splitlines()] if self.log.exists() else []

    def leftovers(self) -> list[str]:
        build = self.root / "build"
        return sorted(p.name for p in build.iterdir() if p.name.startswith("selfcheck-env") and p.is_dir()) \
            if build.exists() else []


@pytest.fixture
def kit(tmp_path) -> Kit:
    return Kit(tmp_path / "kit")


def test_first_use_installs_with_hashes_then_runs_the_selfcheck_with_its_arguments_and_status(kit):
    done = kit.run("--out", "build/selfcheck", "--fail-under", "50", "--exit", "5")
    assert done.returncode == 5, done.stdout + done.stderr
    (install,) = kit.installs()
    # Into a folder of its own, renamed into place when complete.
    assert install[0] == "--python" and re.fullmatch(re.escape(str(kit.env)) + r"\.partial-\d+/bin/python", install[1])
    assert {"--require-hashes", "--no-compile"} <= set(install) and install[install.index("--only-binary") + 1] == ":all:"
    assert install[-2:] == ["-r", str(kit.requirements)]
    assert "selfcheck ran ['--out', 'build/selfcheck', '--fail-under', '50', '--exit', '5'] after install 1" in done.stdout
    # One progress line: what, where, how long and how big.
    progress = [line for line in done.stdout.splitlines() if line.startswith("selfcheck: first use")]
    assert len(progress) == 1 and "numpy 2.4.6" in progress[0] and re.search(r"done in \d+ s, \d+ MB\.$", progress[0])
    assert kit.leftovers() == ["selfcheck-env"]


def test_numpys_test_suite_is_pruned(kit):
    assert kit.run().returncode == 0
    site = next((kit.env / "lib").glob("python*/site-packages"))
    assert (site / "numpy" / "_core").is_dir() and not (site / "numpy" / "_core" / "tests").exists()


def test_later_runs_install_nothing_and_touch_nothing(kit):
    assert kit.run().returncode == 0
    stamp = kit.env / "selfcheck-env.json"
    before = stamp.stat().st_mtime_ns
    started = time.monotonic()
    again = kit.run("--exit", "1")
    elapsed = time.monotonic() - started
    assert again.returncode == 1 and "after install 1" in again.stdout
    assert len(kit.installs()) == 1 and stamp.stat().st_mtime_ns == before
    assert "first use" not in again.stdout
    assert elapsed < 10          # generous on a loaded machine; measured in the report


def test_another_requirements_file_rebuilds_the_environment(kit):
    assert kit.run().returncode == 0
    kit.requirements.write_text(kit.requirements.read_text() + "# a newer kit\n")
    done = kit.run()
    assert done.returncode == 0 and "after install 2" in done.stdout and "first use" in done.stdout
    assert len(kit.installs()) == 2 and kit.leftovers() == ["selfcheck-env"]


def test_an_unfinished_environment_is_not_mistaken_for_a_good_one(kit):
    # What a run killed mid-install could leave if it wrote in place: an environment without its stamp.
    import venv
    venv.EnvBuilder(with_pip=False, symlinks=True).create(str(kit.env))
    (kit.root / "build" / "selfcheck-env.partial-999999999").mkdir()      # a dead run's folder
    done = kit.run()
    assert done.returncode == 0 and "after install 1" in done.stdout
    assert kit.leftovers() == ["selfcheck-env"]


@pytest.mark.parametrize("mode, says", [
    ("offline", "could not reach the package index"),
    ("no-wheel", "no ready-made package for this computer"),
])
def test_a_failed_install_says_why_and_leaves_nothing(kit, mode, says):
    done = kit.run(mode=mode)
    assert done.returncode == SETUP_FAILED
    assert says in done.stdout and "selfcheck-env-install.log" in done.stdout, done.stdout
    assert "selfcheck ran" not in done.stdout and kit.leftovers() == []
    then = kit.run()                                   # and then works, once it can install
    assert then.returncode == 0 and "after install 2" in then.stdout


def test_a_python_older_than_the_packages_need_says_what_to_install(kit, tmp_path):
    kit.requirements.write_text(kit.requirements.read_text().replace("requires-python: >=3.11",
                                                                     "requires-python: >=3.99"))
    empty_path = tmp_path / "bin"
    empty_path.mkdir()
    done = kit.run(extra_env={"PATH": str(empty_path)})
    assert done.returncode == SETUP_FAILED and kit.installs() == [] and kit.leftovers() == []
    assert "needs Python 3.99 or later" in done.stdout and "apt-get install python3.99 python3.99-venv" in done.stdout


def test_a_newer_python_on_path_is_used_when_python3_is_too_old(kit, tmp_path):
    minor = sys.version_info[1]
    kit.requirements.write_text(kit.requirements.read_text().replace("requires-python: >=3.11",
                                                                     f"requires-python: >=3.{minor}"))
    candidates = [shutil.which(f"python3.{minor - 1}"),
                  *map(str, Path.home().glob(f".pyenv/versions/3.{minor - 1}.*/bin/python3.{minor - 1}"))]
    old = next((c for c in candidates if c and subprocess.run([c, "-c", "import sys"], capture_output=True,
                                                              timeout=30).returncode == 0), None)
    if old is None:
        pytest.skip(f"no python3.{minor - 1} here to play the old python3")
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    (bin_dir / f"python3.{minor}").symlink_to(sys.executable)
    done = kit.run(python=old, extra_env={"PATH": f"{bin_dir}:/usr/bin:/bin"})
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"using {bin_dir}/python3.{minor}" in done.stdout and "after install 1" in done.stdout


def test_no_venv_module_names_the_debian_package(kit):
    (kit.fakes / "venv.py").write_text("raise ImportError('No module named venv')\n")
    done = kit.run()
    assert done.returncode == SETUP_FAILED and kit.leftovers() == [] and kit.installs() == []
    assert "has no venv module" in done.stdout
    assert f"apt-get install python{sys.version_info[0]}.{sys.version_info[1]}-venv" in done.stdout


def test_no_pip_at_all_says_how_to_get_one(monkeypatch):
    import importlib.util
    spec = importlib.util.spec_from_file_location("kit_bootstrap", BOOTSTRAP)
    bootstrap = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bootstrap)
    monkeypatch.setattr(bootstrap, "host_pip_version", lambda: None)
    monkeypatch.setattr(bootstrap, "PIP_WHEEL_DIRS", ())
    with pytest.raises(bootstrap.SetupError, match="no pip") as e:
        bootstrap.pip_command(Path("/env/bin/python"))
    assert "apt-get install python3-pip" in str(e.value) and "-m ensurepip" in str(e.value)
    # pip too old for --python, but Python's own pip wheel there: the environment's python runs it.
    monkeypatch.setattr(bootstrap, "host_pip_version", lambda: (21, 0))
    monkeypatch.setattr(bootstrap, "bundled_pip_wheel", lambda: Path("/w/pip-23.2.1-py3-none-any.whl"))
    assert bootstrap.pip_command(Path("/env/bin/python")) == ["/env/bin/python", "/w/pip-23.2.1-py3-none-any.whl/pip"]


def test_the_bootstrap_reads_on_old_pythons():
    """It must run far enough to say a Python is too old: no syntax newer than 3.6."""
    import ast
    tree = ast.parse(BOOTSTRAP.read_text(), feature_version=(3, 6))
    assert not any(isinstance(n, ast.NamedExpr) for n in ast.walk(tree))
    assert "from __future__ import annotations" not in BOOTSTRAP.read_text()


# ---- the real install -------------------------------------------------------------------------

@pytest.mark.slow
def test_the_real_first_use_installs_the_locked_packages_within_budget(tmp_path):
    """Network: pip downloads the kit's packages (cache off) into a fresh environment."""
    kit = Kit(tmp_path / "kit")
    (kit.root / "selfcheck" / "grader" / "kit" / "selfcheck.py").write_text(textwrap.dedent("""
        import json, sys
        from importlib import metadata
        import numpy, cffi, OpenImageIO, flip_evaluator, rich.console, markdown_it, jinja2
        names = ["numpy", "cffi", "openimageio", "flip-evaluator", "rich", "markdown-it-py", "jinja2"]
        print(json.dumps({n: metadata.version(n) for n in names}))
    """))
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH",)}
    env["PIP_NO_CACHE_DIR"] = "1"
    done = subprocess.run([sys.executable, "selfcheck/bootstrap.py"], cwd=kit.root, env=env, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    versions = json.loads(done.stdout.strip().splitlines()[-1])
    lock = locked()
    assert versions == {n: lock[n][0] for n in versions}
    size = sum(p.lstat().st_blocks * 512 for p in kit.env.rglob("*") if not p.is_symlink() and p.is_file())
    assert size <= BUDGET_BYTES, f"{size / 1e6:.0f} MB"
