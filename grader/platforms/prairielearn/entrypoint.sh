#!/usr/bin/env bash
# PrairieLearn's entrypoint (info.json: externalGradingOptions.entrypoint):
# grades /grade/student with the project this script sits in.
cd "$(dirname "$0")/../../.."
exec .venv/bin/python -m grader prairielearn --root "${PL_GRADE_ROOT:-/grade}"
