"""requirements.lock: exact versions with hashes, agreeing with
requirements.txt, with the fixture manifest and with the running venv.

`make venv`, Gradescope's setup.sh and the student kit install it with
`pip install --require-hashes -r requirements.lock`.
"""
from __future__ import annotations

import json
import re
from importlib import metadata

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

from grader import PROJECT_ROOT
from grader.grading import fixtures

LOCK = PROJECT_ROOT / "requirements.lock"


def locked() -> dict[str, tuple[str, list[str]]]:
    """{canonical name: (version, hashes)} from the lock."""
    text = LOCK.read_text()
    out = {}
    for block in re.split(r"\n(?=\S)", text):
        m = re.match(r"([A-Za-z0-9._-]+)==([^\s;\\]+)", block)
        if m:
            out[canonicalize_name(m[1])] = (m[2], re.findall(r"--hash=sha256:([0-9a-f]{64})", block))
    return out


def requirements() -> list[Requirement]:
    lines = (PROJECT_ROOT / "requirements.txt").read_text().splitlines()
    return [Requirement(line.split("#")[0]) for line in lines if line.split("#")[0].strip()]


def test_every_requirement_is_locked_within_its_bounds_with_hashes():
    pins = locked()
    assert len(pins) > len(requirements())          # dependencies are locked too
    for req in requirements():
        version, hashes = pins[canonicalize_name(req.name)]
        assert req.specifier.contains(version, prereleases=True), (req, version)
    assert all(hashes for _, hashes in pins.values()), [n for n, (_, h) in pins.items() if not h]


def test_lock_pins_the_libraries_the_fixtures_were_made_with():
    recorded = json.loads(fixtures.MANIFEST.read_text())["environment"]["libraries"]
    pins = locked()
    for name, version in recorded.items():
        assert pins[canonicalize_name(name)][0] == version, name


def test_this_venv_runs_the_locked_versions():
    pins = locked()
    for name in (canonicalize_name(r.name) for r in requirements()):
        assert metadata.version(name) == pins[name][0], name


def test_every_installer_uses_the_lock_with_hashes():
    from grader.platforms.gradescope import INCLUDE, SETUP_SH
    make_venv = (PROJECT_ROOT / "scripts" / "make-venv.sh").read_text()
    assert "--require-hashes" in make_venv
    assert "make-venv.sh $(VENV) requirements.lock" in (PROJECT_ROOT / "Makefile").read_text()
    grading_env = (PROJECT_ROOT / "scripts" / "install-grading-env.sh").read_text()
    assert 'scripts/make-venv.sh "$venv" requirements.lock' in grading_env and "requirements.lock" in INCLUDE
    assert "scripts/install-grading-env.sh .venv" in SETUP_SH       # Gradescope
    dockerfile = (PROJECT_ROOT / "grader" / "platforms" / "prairielearn" / "Dockerfile").read_text()
    assert "scripts/install-grading-env.sh" in dockerfile             # PrairieLearn's image
