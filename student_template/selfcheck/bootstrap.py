"""Run the self-check in its own Python environment, made on first use.

    python3 selfcheck/bootstrap.py --out build/selfcheck [--fail-under N]

run from the kit's folder (`make selfcheck` does). The self-check is the
grader's own code (selfcheck/grader/, `python -m grader.kit.selfcheck`), which
needs numpy and a few other packages. The first run installs exactly the
versions in selfcheck/requirements-kit.txt (the grader's, with their hashes)
into build/selfcheck-env/; later runs find it and start at once. Every
argument is passed on to the self-check, and its exit status comes back.

Needs Python 3.11 or later (the requirements file says which; a newer
python3.X on PATH is used when python3 is older) and pip (the one that comes
with Python, or Debian/Ubuntu's python3-pip), and the internet the first
time. When something is missing it says what and how to get it, exits with
status 3, and leaves no half-made environment behind.

Standard library only, and readable by old Pythons so that they can say
they are too old.
"""
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

KIT = Path(__file__).resolve().parent.parent
SELFCHECK = KIT / "selfcheck"
REQUIREMENTS = SELFCHECK / "requirements-kit.txt"
ENV = KIT / "build" / "selfcheck-env"
STAMP_NAME = "selfcheck-env.json"     # written last: an environment without it is not finished
LOG = KIT / "build" / "selfcheck-env-install.log"
MODULE = "grader.kit.selfcheck"
SETUP_FAILED = 3
PIP_WITH_PYTHON_OPTION = (22, 3)      # pip's --python (install into another interpreter's environment)
# Where a Python's own copy of pip's wheel may be: its ensurepip, and Debian's python3-pip-whl.
PIP_WHEEL_DIRS = ("{ensurepip}/_bundled", "/usr/share/python-wheels")
# Installed files the self-check never uses, removed to keep the environment small: numpy's own
# test suite (8 MB of numpy 2.4's 31 MB).
PRUNED = ("numpy/**/tests",)


class SetupError(Exception):
    """What is missing, and the command that gets it."""


def say(text, end="\n"):
    print("selfcheck: " + text if text else "", end=end, flush=True)


# ---- what the requirements file asks for ----------------------------------------------------------

def requirements_digest():
    return hashlib.sha256(REQUIREMENTS.read_bytes()).hexdigest()


def minimum_python():
    """(major, minor) from the file's "# requires-python: >=3.11" line."""
    m = re.search(r"^# requires-python: >=(\d+)\.(\d+)", REQUIREMENTS.read_text(encoding="utf-8"), re.M)
    return (int(m.group(1)), int(m.group(2))) if m else (3, 0)


def pinned_packages():
    """["numpy 2.4.6", ...] as the file pins them."""
    found = re.findall(r"^([A-Za-z0-9][A-Za-z0-9._-]*)==([^\s;\\]+)", REQUIREMENTS.read_text(encoding="utf-8"), re.M)
    return ["{} {}".format(name, version) for name, version in found]


# ---- the environment ----------------------------------------------------------------------------

def env_python(env):
    return env / ("Scripts/python.exe" if os.name == "nt" else "bin/python")


def base_python(env):
    """The interpreter an environment runs on: its python's real path (a
    symlink into the Python it was made from; Windows copies it instead). A
    different one (python3 now a newer Python) means the packages no longer fit."""
    return os.path.realpath(str(env_python(env))) if os.name != "nt" else "copy"


def is_ready(env):
    """The environment exists, was finished, was made from this requirements
    file, and still runs on the Python it was made with."""
    try:
        stamp = json.loads((env / STAMP_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return (env_python(env).exists() and stamp.get("requirements_sha256") == requirements_digest()
            and stamp.get("python") == base_python(env))


def size_on_disk(folder):
    total = 0
    for root, _, files in os.walk(str(folder)):
        for name in files:
            try:
                st = os.lstat(os.path.join(root, name))
            except OSError:
                continue
            total += getattr(st, "st_blocks", 0) * 512 or st.st_size
    return total


# ---- what is needed to make it ---------------------------------------------------------------------

def newer_python(minimum):
    """A python3.X on PATH at least `minimum`, newest first, or None."""
    for minor in range(20, minimum[1] - 1, -1):
        found = shutil.which("python{}.{}".format(minimum[0], minor))
        if not found:
            continue
        probe = subprocess.run([found, "-c", "import sys; print(sys.version_info[:2] >= {!r})".format(minimum)],
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, universal_newlines=True)
        if probe.returncode == 0 and probe.stdout.strip() == "True":
            return found
    return None


def versioned(name):
    """"python3.11-venv" for this interpreter: Debian's and Ubuntu's package names."""
    return name.replace("python3", "python{}.{}".format(*sys.version_info[:2]))


def check_python(minimum):
    if sys.version_info[:2] >= minimum:
        return
    want = "{}.{}".format(*minimum)
    raise SetupError(
        "the self-check needs Python {} or later; {} is Python {}, and no python{} or newer is on PATH.\n"
        "  Debian/Ubuntu: sudo apt-get install python{} python{}-venv\n"
        "  macOS: brew install python@{} (or the installer from python.org)\n"
        "  then run make selfcheck again (or make selfcheck PYTHON=python{}).".format(
            want, sys.executable, ".".join(map(str, sys.version_info[:3])), want, want, want, want, want))


def check_venv():
    try:
        import venv  # noqa: F401
    except ImportError:
        raise SetupError("this Python ({}) has no venv module, which makes the self-check's environment.\n"
                         "  Debian/Ubuntu: sudo apt-get install {}".format(sys.executable, versioned("python3-venv")))


def host_pip_version():
    """The version of `python3 -m pip` beside this Python, or None."""
    try:
        done = subprocess.run([sys.executable, "-m", "pip", "--version"], stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, universal_newlines=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return None
    m = re.match(r"pip (\d+)\.(\d+)", done.stdout)
    return (int(m.group(1)), int(m.group(2))) if done.returncode == 0 and m else None


def bundled_pip_wheel():
    """pip's wheel as this Python ships it (ensurepip), or Debian's copy, or None."""
    try:
        import ensurepip
        ensurepip_dir = os.path.dirname(ensurepip.__file__)
    except ImportError:
        ensurepip_dir = None
    for pattern in PIP_WHEEL_DIRS:
        if "{ensurepip}" in pattern and ensurepip_dir is None:
            continue
        folder = Path(pattern.format(ensurepip=ensurepip_dir))
        wheels = sorted(folder.glob("pip-*.whl")) if folder.is_dir() else []
        if wheels:
            return wheels[-1]
    return None


def pip_command(python):
    """How to run pip so that it installs into the environment of `python`:
    this Python's pip with --python (pip 22.3 or later), else pip's own wheel
    run by `python` itself (pip can run from its wheel)."""
    version = host_pip_version()
    if version is not None and version >= PIP_WITH_PYTHON_OPTION:
        return [sys.executable, "-m", "pip", "--python", str(python)]
    wheel = bundled_pip_wheel()
    if wheel is not None:
        return [str(python), str(wheel / "pip")]
    old = " (its pip {}.{} is older than 22.3)".format(*version) if version else ""
    raise SetupError("no pip to install the self-check's packages with{}.\n"
                     "  Debian/Ubuntu: sudo apt-get install python3-pip {}\n"
                     "  elsewhere: {} -m ensurepip --upgrade".format(old, versioned("python3-venv"), sys.executable))


# ---- making it ------------------------------------------------------------------------------------

def explain_pip_failure(status, output):
    """The reason in a student's words, from what pip printed."""
    tail = "\n".join("    " + (line if len(line) <= 200 else line[:197] + "...")
                     for line in output.strip().splitlines()[-6:])
    if re.search(r"NewConnectionError|Failed to establish|Temporary failure in name resolution|"
                 r"Network is unreachable|getaddrinfo failed|ConnectTimeout|ReadTimeout|ProxyError|SSLError", output):
        why = ("could not reach the package index to download them: connect to the internet and run "
               "make selfcheck again (or set PIP_INDEX_URL to a mirror you can reach).")
    elif re.search(r"No matching distribution|Could not find a version that satisfies", output):
        why = ("there is no ready-made package for this computer (Python {}, {}): use Python 3.11 to 3.13 on "
               "Linux (x86-64 or ARM), macOS or Windows.".format(".".join(map(str, sys.version_info[:3])),
                                                                 sys.platform))
    elif re.search(r"DO NOT MATCH THE HASHES|Hashes are required", output):
        why = ("a downloaded file is not the one the grader uses (its hash differs): a proxy or mirror changed "
               "it; try another network, or ask your instructor.")
    elif re.search(r"No space left on device", output):
        why = "the disk is full (the environment needs about 100 MB)."
    else:
        why = "pip failed (exit status {}).".format(status)
    return "could not install the self-check's packages: {}\n  pip said (all of it is in {}):\n{}".format(
        why, LOG.relative_to(KIT), tail)


def remove_leftovers():
    """Half-made environments of runs that were stopped (their process is gone)."""
    for path in ENV.parent.glob(ENV.name + ".partial-*"):
        try:
            os.kill(int(path.name.rsplit("-", 1)[1]), 0)
            continue                                   # still being made by another run
        except (ValueError, ProcessLookupError):
            pass
        except OSError:
            continue
        shutil.rmtree(str(path), ignore_errors=True)


def prune(site):
    for pattern in PRUNED:
        for folder in sorted(site.glob(pattern), reverse=True):
            if folder.is_dir():
                shutil.rmtree(str(folder), ignore_errors=True)


def create():
    """Make ENV from REQUIREMENTS: in a folder of its own, renamed into place
    only when complete, stamp written last."""
    check_python(minimum_python())
    check_venv()
    import venv
    ENV.parent.mkdir(parents=True, exist_ok=True)
    remove_leftovers()
    partial = ENV.with_name("{}.partial-{}".format(ENV.name, os.getpid()))
    shutil.rmtree(str(partial), ignore_errors=True)
    try:
        venv.EnvBuilder(with_pip=False, symlinks=os.name != "nt").create(str(partial))
        python = env_python(partial)
        pip = pip_command(python)
        packages = pinned_packages()
        say("first use: installing {} packages into {}/ ({}) ...".format(
            len(packages), ENV.relative_to(KIT).as_posix(), ", ".join(packages)), end="")
        start = time.monotonic()
        with LOG.open("w", encoding="utf-8") as log:
            done = subprocess.run(pip + ["install", "--require-hashes", "--only-binary", ":all:", "--no-compile",
                                         "--no-input", "--disable-pip-version-check", "--progress-bar", "off",
                                         "--no-warn-script-location", "-r", str(REQUIREMENTS)],
                                  stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
        if done.returncode != 0:
            print(flush=True)
            raise SetupError(explain_pip_failure(done.returncode, LOG.read_text(encoding="utf-8", errors="replace")))
        for site in partial.glob("lib/python*/site-packages"):
            prune(site)
        (partial / STAMP_NAME).write_text(json.dumps({"requirements_sha256": requirements_digest(),
                                                      "python": base_python(partial)}, indent=1), encoding="utf-8")
        shutil.rmtree(str(ENV), ignore_errors=True)
        os.replace(str(partial), str(ENV))
        print(" done in {:.0f} s, {:.0f} MB.".format(time.monotonic() - start, size_on_disk(ENV) / 1e6), flush=True)
    finally:
        shutil.rmtree(str(partial), ignore_errors=True)


def run_selfcheck(args):
    """Hand over to the self-check in ENV: its exit status is ours."""
    environ = dict(os.environ, PYTHONPATH=str(SELFCHECK))
    command = [str(env_python(ENV)), "-m", MODULE] + list(args)
    if os.name == "nt":
        return subprocess.call(command, env=environ)
    os.execve(command[0], command, environ)


def main(args):
    if not REQUIREMENTS.is_file():
        say("error: {} is missing: this kit is incomplete (unpack it again).".format(REQUIREMENTS))
        return SETUP_FAILED
    if not is_ready(ENV):
        minimum = minimum_python()
        if sys.version_info[:2] < minimum and os.environ.get("SELFCHECK_REEXEC") != "1":
            newer = newer_python(minimum)
            if newer:
                say("{} is Python {}.{}; using {}".format(sys.executable, *sys.version_info[:2], newer))
                os.environ["SELFCHECK_REEXEC"] = "1"
                os.execv(newer, [newer, str(Path(__file__).resolve())] + list(args))
        try:
            create()
        except SetupError as e:
            say("error: " + str(e))
            return SETUP_FAILED
        except KeyboardInterrupt:
            print(flush=True)
            say("stopped; nothing was kept (run it again to install).")
            return 130
    return run_selfcheck(args)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
