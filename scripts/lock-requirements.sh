#!/usr/bin/env bash
# Regenerate requirements.lock (exact versions with their SHA-256 hashes) from
# requirements.txt, with uv from PyPI in a throw-away virtual environment.
#
#   scripts/lock-requirements.sh             # keep the locked versions, add what is new
#   scripts/lock-requirements.sh --upgrade   # move every package to its newest version
#
# The lock is universal (Python 3.11 and later, any platform markers), so
# Gradescope's Ubuntu 24.04 (Python 3.12) installs the same versions as a
# Debian 12 machine (3.11). After an upgrade, run `make fixtures` and the
# test suite: the render thresholds were measured with the locked libraries,
# and fixtures/manifest.json records them.
set -euo pipefail
cd "$(dirname "$0")/.."
tools=$(mktemp -d)
trap 'rm -rf "$tools"' EXIT
python3 -m venv "$tools/venv"
"$tools/venv/bin/python" -m pip install --progress-bar on "uv>=0.5" >&2
"$tools/venv/bin/uv" pip compile requirements.txt --universal --python-version 3.11 --generate-hashes \
  --custom-compile-command "scripts/lock-requirements.sh" --output-file requirements.lock "$@"
echo "wrote requirements.lock; install it with: make venv (pip install --require-hashes -r requirements.lock)"
