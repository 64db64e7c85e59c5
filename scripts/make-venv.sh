#!/usr/bin/env bash
# Create .venv/ and install the grader's Python packages into it, showing
# progress. Called by `make venv` (and so by every target that needs it).
#
#   scripts/make-venv.sh VENV REQUIREMENTS [PYTHON]
#
# PYTHON (default python3) must be 3.11 or later; when python3 is older
# (Ubuntu 22.04 has 3.10) python3.12 or python3.11 is used if present. When
# the venv module's ensurepip is missing (Debian and Ubuntu ship it as
# pythonX.Y-venv) it is installed as root, or the command to do so is named.
# A requirements file with hashes (requirements.lock) is installed with
# --require-hashes: exactly the versions the fixtures were made with.
set -euo pipefail
venv=$1 requirements=$2 python=${3:-python3}

ok_version() { "$1" -c 'import sys; sys.exit(sys.version_info < (3, 11))' 2>/dev/null; }
if ! ok_version "$python"; then
  for alt in python3.13 python3.12 python3.11; do
    if command -v "$alt" >/dev/null && ok_version "$alt"; then python=$alt; break; fi
  done
fi
if ! ok_version "$python"; then
  echo "error: the grader needs Python 3.11 or later; $python is $("$python" --version 2>&1 || echo missing)." >&2
  echo "       On Ubuntu 22.04: apt-get install python3.11 python3.11-venv, then make PYTHON=python3.11 ..." >&2
  exit 1
fi
if ! "$python" -c 'import ensurepip, venv' 2>/dev/null; then
  pkg="python$("$python" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')-venv"
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    echo "venv: $python has no ensurepip; installing $pkg ..."
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "$pkg" \
      || { apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "$pkg"; }
  else
    echo "error: $python cannot create a virtual environment (no ensurepip): install $pkg (sudo apt-get install $pkg)." >&2
    exit 1
  fi
fi
if [ ! -x "$venv/bin/python" ]; then
  echo "venv: creating $venv with $python ($("$python" --version 2>&1)) ..."
  "$python" -m venv "$venv"
fi
hashes=()
grep -q -- '--hash=' "$requirements" && hashes=(--require-hashes)
echo "venv: installing $requirements into $venv (progress below; about 100 MB on first use) ..."
# No --quiet: pip's "Collecting ..." and download bars are the progress.
# pip itself is left as the venv made it: the lock decides everything else.
set +e
"$venv/bin/python" -m pip install --progress-bar on "${hashes[@]}" -r "$requirements" 2>&1 \
  | grep --line-buffered -v '^Requirement already satisfied'
status=${PIPESTATUS[0]}
set -e
if [ "$status" != 0 ]; then
  echo "error: pip could not install $requirements into $venv (exit status $status, see above)." >&2
  exit "$status"
fi
echo "venv: ready ($("$venv/bin/python" --version))"
