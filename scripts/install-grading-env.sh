#!/usr/bin/env bash
# What grading needs on a fresh Debian or Ubuntu (as root): the "core"
# packages of packages.txt, Python 3.11 or later, and a virtual environment
# with exactly the versions of requirements.lock (pip install
# --require-hashes). Gradescope's setup.sh and PrairieLearn's image
# (grader/platforms/prairielearn/Dockerfile) both run it.
#
#   bash scripts/install-grading-env.sh VENV
#
# Run from anywhere: it works in the project this script sits in.
set -euo pipefail
venv=${1:?usage: install-grading-env.sh VENV}
cd "$(dirname "$0")/.."
export DEBIAN_FRONTEND=noninteractive
apt-get update -q
apt-get install -y -q --no-install-recommends python3 make
bash scripts/install-system-deps.sh core
python=python3
# Ubuntu 24.04 and Debian 12 have 3.12 and 3.11; on 22.04 python3.11 is
# installed beside the system's 3.10.
if ! python3 -c 'import sys; sys.exit(sys.version_info < (3, 11))'; then
  apt-get install -y -q --no-install-recommends python3.11 python3.11-venv
  python=python3.11
fi
bash scripts/make-venv.sh "$venv" requirements.lock "$python"
# What the venv was made from: the entry points compare it with the
# project's lock and warn the instructor when they differ.
cp requirements.lock "$venv/requirements.lock"
touch "$venv/.installed"
