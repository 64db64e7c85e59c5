#!/usr/bin/env bash
# PrairieLearn's entry point (info.json: externalGradingOptions.entrypoint,
# /grade/serverFilesCourse/envmap/grader/platforms/prairielearn/entrypoint.sh):
# grades /grade/student with the project this script sits in, and always
# leaves /grade/results/results.json, whatever fails.
#
# The Python environment is the image's ($ENVMAP_VENV, set by the Dockerfile
# beside this script), else the project's own .venv (a machine where `make
# venv` ran). PL_GRADE_ROOT stands in for /grade in tests.
set -uo pipefail
root="${PL_GRADE_ROOT:-/grade}"
project="$(cd "$(dirname "$0")/../../.." && pwd)"
results="$root/results/results.json"
mkdir -p "$root/results"

# The grader's own failure, in PrairieLearn's format: not gradable, so the
# student is not charged an attempt; the reason goes to the job log.
fail() {
  echo "prairielearn: $1" >&2
  cat > "$results" <<JSON
{"gradable": false, "score": 0, "message": "The autograder failed before it could grade your submission. This is not your fault: please tell your instructor. ($2)", "output": "", "tests": [], "images": []}
JSON
  exit 0
}

venv=""
for candidate in "${ENVMAP_VENV:-}" "$project/.venv"; do
  if [ -n "$candidate" ] && [ -x "$candidate/bin/python" ]; then venv=$candidate; break; fi
done
[ -n "$venv" ] || fail "no Python environment: ENVMAP_VENV is '${ENVMAP_VENV:-}' and $project/.venv/bin/python does not exist; use the image grader/platforms/prairielearn/Dockerfile builds (docs/platforms.md)" \
  "the grading image has no Python environment for the grader"
if [ -f "$venv/requirements.lock" ] && ! cmp -s "$venv/requirements.lock" "$project/requirements.lock"; then
  echo "prairielearn: warning: $venv was made from another requirements.lock than $project's: rebuild and publish the image" >&2
fi

# The grader writes its build folder into the project; a read-only copy is graded from a writable one.
if [ ! -w "$project" ]; then
  copy="$(mktemp -d)/envmap"
  cp -a "$project" "$copy" || fail "cannot copy $project to $copy" "the grader's files could not be copied"
  project=$copy
fi
cd "$project" || fail "cannot enter $project" "the grader's files are missing"
"$venv/bin/python" -m grader prairielearn --root "$root" "$@"
status=$?
[ -s "$results" ] || fail "python -m grader prairielearn exited $status without writing $results" \
  "the grader stopped without a result"
exit 0
