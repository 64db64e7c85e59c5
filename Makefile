# The front door. `make` builds the reference library; `make test` sets up
# .venv/ from requirements.lock (and the Debian packages in packages.txt) on
# first use and runs the test suite; `make grade` grades the examples. Every
# target README.md names installs what it needs (tests/project/test_front_door.py).
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
BUILD := build

CC ?= cc
CFLAGS_REF := -std=c11 -O2 -fPIC -Wall -Wextra -Werror -D_POSIX_C_SOURCE=200809L
REF_SRC := $(sort $(wildcard reference/src/*.c))
REF_HDR := reference/include/envmap.h $(wildcard reference/src/*.h)

.PHONY: all reference venv test-all test-all-loaded test test-fast test-load test-exhaustive kit-agreement sanitize fuzz selfcheck grade grade-all fixtures student-kit bundle translations gradescope bench study clean system-deps core-deps

all: reference

reference: $(BUILD)/libenvmap.so $(BUILD)/reference_submission.so

$(BUILD)/libenvmap.so: $(REF_SRC) $(REF_HDR) | $(BUILD) core-deps
	$(CC) $(CFLAGS_REF) -Ireference/include -shared -o $@.tmp $(REF_SRC) -lm && mv $@.tmp $@

# The reference built with AddressSanitizer and UBSan (used by `make sanitize`).
$(BUILD)/asan/libenvmap.so: $(REF_SRC) $(REF_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_REF) -O1 -g -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -Ireference/include -shared -o $@ $(REF_SRC) -lm

# The reference behind the submission ABI: the speed check's baseline.
$(BUILD)/reference_submission.so: grader/build/shim/reference_submission.c grader/build/shim/submission_abi.h $(REF_SRC) $(REF_HDR) | $(BUILD) core-deps
	$(CC) $(CFLAGS_REF) -Ireference/include -Igrader/build/shim -shared -o $@.tmp grader/build/shim/reference_submission.c $(REF_SRC) -lm && mv $@.tmp $@

$(BUILD):
	@mkdir -p $@

# Debian/Ubuntu packages (packages.txt), installed only when missing and when
# we may (root): core-deps is what grading needs (compilers, python3-venv,
# bubblewrap), system-deps adds what the tests use (chromium, clang).
system-deps:
	@bash scripts/install-system-deps.sh

core-deps:
	@bash scripts/install-system-deps.sh core

# requirements.lock: the exact versions (with hashes) the fixtures were made
# with; regenerate it from requirements.txt with scripts/lock-requirements.sh.
$(VENV)/.installed: requirements.lock | core-deps
	@bash scripts/make-venv.sh $(VENV) requirements.lock $(PYTHON)
	@touch $@

venv: $(VENV)/.installed

# Every test (CI's gate: .ci/run; about 11 min on 2 cores). The tiers below
# are subsets of it (markers: pytest.ini, tests/conftest.py).
FAST = not slow and not sanitizer and not browser
# Bytecode (and pytest's rewritten test modules) cached under build/, even
# where the environment says PYTHONDONTWRITEBYTECODE to keep the tree clean:
# compiling ~150 test modules in each worker, every run, cost 3 s of each.
PYTEST = env -u PYTHONDONTWRITEBYTECODE PYTHONPYCACHEPREFIX=$(CURDIR)/$(BUILD)/pycache $(PY) -m pytest

test-all: system-deps venv reference
	$(PYTEST) -n 2 -q -m "not agreement and not exhaustive and not wallclock" --durations=15 tests

# A developer's run (about 3 min): the fast tests and the representative slow
# ones (each grading path once, both isolation modes).
test: system-deps venv reference
	$(PYTEST) -n 2 -q -m "$(FAST) or representative" tests

# The suite without the slow, sanitizer and browser tests (under a minute).
test-fast: system-deps venv reference
	$(PYTEST) -n 2 -q -m "$(FAST)" tests

# The timing-sensitive tests (the speed check, the worker's time limits, the
# build's deadline) beside LOAD busy processes (issue 32: verdicts must not
# change with the load; default 30), all in a cgroup capped at LOAD_CPUS cores
# where one can be made (tests/helpers/loaded.py): the tests see load LOAD on
# LOAD_CPUS cores; the machine's other users lose at most LOAD_CPUS cores.
LOAD ?= 30
LOAD_CPUS ?= 1
TIMING_TESTS = tests/security/test_speed_trust.py tests/sandbox/test_worker_limits.py \
	tests/unit/build/test_compiler_deadline.py tests/security/test_resource_bounds.py
test-load: system-deps venv reference
	$(PY) tests/helpers/loaded.py $(LOAD) --cpus $(LOAD_CPUS) -- $(PYTEST) -n 2 -q -m "not agreement" $(TIMING_TESTS)

# The whole of test-all beside LOAD busy processes at nice LOAD_NICE, each in
# an autogroup of its own at that niceness (tests/helpers/loaded.py --nice):
# the load average reads LOAD and more, as on a machine shared with long
# low-priority jobs, and the suite keeps most of the cores (issue 32).
LOAD_NICE ?= 19
test-all-loaded: system-deps venv reference
	$(PY) tests/helpers/loaded.py $(LOAD) --nice $(LOAD_NICE) -- $(MAKE) --no-print-directory test-all

# Every zoo file and five renamed copies of it graded alike (issue 30; about
# an hour on 2 cores): test-all runs the representative set.
test-exhaustive: system-deps venv reference
	$(PYTEST) -n 2 -q -m exhaustive tests/grading/test_same_behaviour.py

# The student kit's self-check against the grader on every zoo submission
# (tests/kit/test_kit_agreement.py; many minutes): `make test-all` runs a subset.
kit-agreement: system-deps venv reference
	$(PYTEST) -n 2 -q -m agreement tests/kit/test_kit_agreement.py

# Regenerate fixtures/ after changing a scene, a map or the reference.
fixtures: venv reference
	$(PY) -m grader fixtures

# The student release: build/student-kit/ and build/student-kit.zip (the
# template, the renderer without the lookup, the self-check and its data).
student-kit: core-deps venv reference
	@bash scripts/install-system-deps.sh kit
	$(PY) -m grader kit --out build/student-kit

bundle: student-kit

# The Japanese catalogue after English words changed (docs/glossary_ja.md):
# new entries come out empty, changed ones fuzzy; translate them, then
# tests/unit/i18n/test_i18n.py passes again. No .mo: grader/i18n/__init__.py compiles the .po.
translations: venv
	PYTHONPATH=. $(VENV)/bin/pybabel extract -F babel.cfg --no-default-keywords -k _ -k N_ -k ngettext:1,2 \
	    --add-location=file --sort-output --project=envmap-grader -o grader/i18n/locale/grader.pot .
	$(VENV)/bin/pybabel update -i grader/i18n/locale/grader.pot -d grader/i18n/locale -D grader --width=100

# `make grade` grades the examples in examples/; `make grade SUBMISSION=path
# [OUT=dir]` grades one submission (reports in out/<submission name>/).
grade: core-deps venv reference
	$(PY) -m grader grade $(if $(SUBMISSION),"$(SUBMISSION)") $(if $(OUT),--out "$(OUT)")

# A class: `make grade-all SUBMISSIONS=dir [OUT=dir] [JOBS=n]` (resumable).
grade-all: core-deps venv reference
	@test -n "$(SUBMISSIONS)" || { echo "usage: make grade-all SUBMISSIONS=dir [OUT=dir] [JOBS=n]" >&2; exit 2; }
	$(PY) -m grader grade-all "$(SUBMISSIONS)" $(if $(OUT),--out "$(OUT)") $(if $(JOBS),--jobs $(JOBS))

# build/autograder.zip for Gradescope.
gradescope: core-deps venv reference
	$(PY) -m grader gradescope

# What a student's `make selfcheck` shows, for the template's EnvironmentMap.cpp.
selfcheck: student-kit
	$(MAKE) -C build/student-kit selfcheck

# Grading speed: one submission cold and warm, and a class of 100 (JOBS=2).
bench: core-deps venv reference
	$(PY) bench/bench_grading.py $(if $(JOBS),--jobs $(JOBS))

# The speed-against-accuracy study into build/study-figures/; UPDATE=1
# rewrites the committed docs/study/ and fixtures/study.csv instead.
study: core-deps venv reference
	$(PY) -m grader study $(if $(UPDATE),--update)

# Mitsuba 3 as a peer renderer (optional extra: requirements-study.txt).
bench-mitsuba: venv reference
	$(VENV)/bin/pip install --progress-bar on -r requirements-study.txt
	$(PY) bench/bench_mitsuba.py --pictures docs/study

# The RGBE reader's fuzz corpus under AddressSanitizer and UBSan (no libFuzzer needed).
sanitize: $(BUILD)/asan/libenvmap.so
	$(MAKE) -C reference/fuzz check

# libFuzzer on the RGBE reader (clang); see reference/fuzz/README.md.
fuzz:
	$(MAKE) -C reference/fuzz fuzz

clean:
	rm -rf $(BUILD) out
