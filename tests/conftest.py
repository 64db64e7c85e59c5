"""Shared test set-up: project paths, a seeded rng, the reference library built
once per run, one correct submission built once per run, and markers.

Markers (registered in pytest.ini):
    slow       grades whole submissions or classes (seconds each)
    sandbox    starts sandboxed workers or compiles in bubblewrap
    browser    drives a headless browser
    sanitizer  reruns suites under AddressSanitizer / UBSan
    agreement  the student kit against the grader on every zoo submission
               (many minutes: pytest.ini leaves it out; `make kit-agreement`)
    representative  a slow test `make test` runs all the same (REPRESENTATIVE below)
`make test-all` (CI's gate, .ci/run) runs everything but agreement; `make test`
(about 3 min) runs the fast tests and the representative slow ones: one or two
of each family of gradings, both isolation modes; `make test-fast` (under a
minute) leaves out slow, sanitizer and browser tests. Markers are given per test file below (MODULE_MARKERS) and
per test (TEST_MARKERS), so test files owned by different people need no
edits to be classified; a test file may also mark single tests with
@pytest.mark.<name>.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest

TESTS = Path(__file__).resolve().parent
PROJECT_ROOT = TESTS.parent
SUBMISSIONS = TESTS / "submissions"
CORRECT_SUBMISSION = SUBMISSIONS / "correct"

# One OpenMP thread for FLIP here and in every grader the tests start (they
# inherit it), as grader.checks sets for itself: two xdist workers already
# fill two cores, and idle OpenMP threads spin.
os.environ.setdefault("OMP_NUM_THREADS", "1")

# The helpers (tests/helpers/: assignment_model, fake_lookups, ...) import by
# name, and so do the few test modules another test borrows from (test files'
# names are unique across the folders).
for folder in [TESTS / "helpers", *sorted(p.parent for p in TESTS.glob("*/**/test_*.py")
                                          if "submissions" not in p.parts)]:
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))

# What each test file needs or costs. Files not listed are fast: unit tests,
# the reference through cffi, report writers on hand-made results.
MODULE_MARKERS = {
    "test_grading_zoo": ("slow", "sandbox"),
    "test_grade_all": ("slow", "sandbox"),
    "test_commands": ("slow", "sandbox"),
    "test_gradescope": ("slow", "sandbox"),
    "test_report_words": ("slow", "sandbox"),
    "test_hostile": ("slow", "sandbox"),
    "test_worker": ("sandbox",),
    "test_build_sandbox": ("sandbox",),
    "test_reference_asan": ("sanitizer", "slow"),
    "test_reference_sanitizers": ("sanitizer", "slow"),
    "test_report_html_browser": ("browser", "slow"),
    "test_markers": ("slow",),      # collects three test files in a subprocess, twice
    "test_kit_agreement": ("slow", "sandbox"),   # builds the kit, grades each submission twice
    "test_kit_redteam": ("slow", "sandbox"),     # grades each attack in the kit and in the grader
}
# Single tests in otherwise fast files, by "module::test name" (every
# parametrized case) or "module::test name[case id]" (that case only): what
# would keep `make test-fast` from its 60 s. `make test-all` runs them all; where a
# family of cases is split, the cheapest cases stay in test-fast so that each
# family still runs there. Durations are from one run at load 10-12 on 2 cores
# (about 3x a quiet machine's), those from the kit on quiet ones (2026-12-02).
SLOW = ("slow",)
TEST_MARKERS = {
    # headless Chromium on a graded class
    "test_report_injection_e2e::test_no_name_runs_as_script_in_a_browser": ("browser", "slow"),
    # a whole-class grading (grade-all)
    "test_report_injection_e2e::test_grade_all_with_markup_and_mathtext_names": SLOW,
    # a hypothesis property test of about 76 s
    "test_texture_model::test_one_mistake_in_each_function_is_named_and_neither_is_blamed_for_the_other": SLOW,
    # AddressSanitizer builds and runs (the sanitizer marker's own business)
    "test_build::test_sanitized_build_loads_under_asan": ("sanitizer", "slow"),
    "test_build_attacks::test_the_whole_standard_library_is_allowed[True]": ("sanitizer", "slow"),
    # every standard header compiled (12 s)
    "test_build_attacks::test_the_whole_standard_library_is_allowed[False]": SLOW,
    # several real builds each, in more than one isolation mode (12-16 s)
    "test_build_attacks::test_privilege_drop_builds_as_an_unprivileged_uid": SLOW,
    "test_build_attacks::test_unsandboxed_build_still_checks_everything": SLOW,
    "test_build_attacks::test_no_scratch_folder_outlives_its_build": SLOW,
    "test_build_attacks::test_refusals_stay_short_whatever_the_object_holds": SLOW,
    "test_build::test_untouched_template_builds_black_and_nearest": SLOW,
    "test_template::test_untouched_template_builds_without_warnings_and_renders_black": SLOW,
    "test_template::test_make_run_with_a_solution_renders_the_reference_image": SLOW,
    "test_redteam::test_a_huge_library_is_refused_and_not_cached": SLOW,
    "test_redteam::test_a_flood_of_warnings_stops_the_compiler_and_is_a_build_error": SLOW,
    # waits out wall-clock bounds on purpose (7-10 s)
    "test_redteam::test_a_worker_that_stops_itself_times_out_at_that_input": SLOW,
    "test_redteam::test_a_lookup_asleep_everywhere_uses_up_the_gradings_budget_and_stops": SLOW,
    # truth decided densely for every zoo file (18 s), the quick study (12 s), the whole code scanned (9 s)
    "test_audit::test_truth_of_the_zoo": SLOW,
    # a mutant built and its truth decided per case (5-12 s); crashing0, wrong and not-compiling stay fast
    **{f"test_audit::test_truth_of_hand_reasoned_mutants[{case}]": SLOW
       for case in ("equivalent", "wrong-non-square", "crashing1", "wrong-extreme", "wrong-ties")},
    "test_sweep_and_stability_details::test_reads_past_the_face_at_ties_are_not_blamed_on_the_tie_rule": SLOW,
    "test_study::test_quick_study_writes_its_csv_chart_and_failure_map": SLOW,
    "test_system_deps::test_the_scan_finds_what_the_code_is_known_to_run": SLOW,
    # a crashing submission narrowed down per input (10 s; the sandbox case stays fast)
    "test_crash_localisation::test_a_submission_crashing_only_at_u_or_v_one_loses_only_those_inputs[plain]": SLOW,
    # checks on fake lookups whose readTexture no model fits, or fits only after a long
    # search (6-28 s each); the cheaper cases of each family stay fast
    "test_checks_unit::test_being_hard_to_model_buys_no_fetch_color_points": SLOW,
    "test_checks_unit::test_a_read_texture_answering_the_judge_otherwise_buys_no_fetch_color_points": SLOW,
    "test_checks_unit::test_an_honest_read_texture_differs_alike_on_every_face": SLOW,
    "test_checks_unit::test_an_out_of_bounds_read_is_attributed_to_read_texture": SLOW,
    "test_checks_unit::test_a_read_texture_that_crashes_everywhere_earns_fetch_color_nothing": SLOW,
    "test_checks_unit::test_read_texture_names_its_mistake_and_fetch_color_keeps_its_points[v-flipped-texture-v-flipped]": SLOW,
    "test_checks_unit::test_read_texture_names_its_mistake_and_fetch_color_keeps_its_points[uv-swapped-texture-uv-swapped]": SLOW,
    "test_checks_unit::test_read_texture_names_its_mistake_and_fetch_color_keeps_its_points[size-minus-one-scaled-by-size-minus-one]": SLOW,
    "test_checks_unit::test_read_texture_names_its_mistake_and_fetch_color_keeps_its_points[u-flipped-texture-u-flipped]": SLOW,
    "test_checks_unit::test_fetch_color_is_analysed_when_read_texture_is_almost_right": SLOW,
    "test_sweep_and_stability_details::test_sweep_does_not_credit_fetch_color_where_its_read_texture_reads_past_the_faces": SLOW,
    "test_sweep_and_stability_details::test_honestly_wrong_everywhere_is_not_timed_output_wrong": SLOW,
    "test_sweep_and_stability_details::test_a_fetch_color_mistake_still_shows_through_an_unclamped_read_texture": SLOW,
    "test_texture_model::test_a_fake_lookup_is_fitted_back_to_its_member[unclamped-w-minus-1-offset]": SLOW,
    "test_texture_model::test_a_fake_lookup_is_fitted_back_to_its_member[unclamped-nearest]": SLOW,
    "test_texture_model::test_a_correct_fetch_color_over_a_correct_read_texture_gets_no_diagnosis": SLOW,
    "test_texture_model::test_a_fetch_color_mistake_over_a_wrong_read_texture_costs_fetch_color_points": SLOW,
    # a kit recording graded per mistake (5-21 s each); one case of each family stays fast
    "test_oracle::test_the_kits_recording_answers_submissions_it_never_saw[mistakes0]": SLOW,
    "test_oracle::test_the_kits_recording_answers_submissions_it_never_saw[mistakes1]": SLOW,
    "test_oracle::test_the_kits_recording_answers_submissions_it_never_saw[mistakes2]": SLOW,
    "test_oracle::test_the_kits_recording_answers_submissions_it_never_saw[mistakes4]": SLOW,
    "test_oracle::test_recorded_answers_grade_as_the_live_reference[mistakes1]": SLOW,
    "test_oracle::test_recorded_answers_grade_as_the_live_reference[mistakes2]": SLOW,
    # the 256 x 256 maps generated again (10-16 s); the 128 x 128 ones stay fast
    "test_cubemap::test_committed_map_is_the_generators_output[test_environment_map.hdr]": SLOW,
    "test_cubemap::test_committed_map_is_the_generators_output[interior_cross.hdr]": SLOW,
    # the student kit built, then make selfcheck or a workflow run in it (6-16 s each)
    "test_kit::test_the_students_code_cannot_reach_the_reports": SLOW,
    "test_kit::test_the_workflow_runs_in_a_repository_made_from_the_kit": SLOW,
    "test_kit::test_cmake_build_and_selfcheck": SLOW,
    "test_kit::test_selfcheck_names_a_crash": SLOW,
    "test_kit::test_fail_under_is_a_percentage_of_the_visible_points": SLOW,
    "test_kit::test_the_kit_reports_in_japanese_with_its_compiled_catalogue": SLOW,
    "test_kit::test_selfcheck_html_escapes_what_the_submission_prints": SLOW,
    # the kit unpacked alone and built from nothing (3-4 s), then make run or a
    # self-check in it (2-8 s each); test-fast keeps the kit's contents tests
    "test_kit::test_built_binaries_have_no_lookup_symbols": SLOW,
    "test_kit::test_selfcheck_of_the_template_in_the_kit_alone": SLOW,
    "test_kit::test_make_run_writes_a_compressed_png": SLOW,
    "test_kit::test_a_submission_calling_the_reference_lookup_is_refused_as_the_grader_refuses_it": SLOW,
    "test_kit::test_a_submission_that_does_not_compile_gets_a_report": SLOW,
    # the kit zipped twice (4-5 s)
    "test_kit::test_zip_is_reproducible": SLOW,
    # wait out wall-clock bounds on purpose (4-6 s, a core idle)
    "test_worker_limits::test_a_batch_asleep_past_the_wall_bound_is_tried_once_more_then_narrowed": SLOW,
    "test_build::test_compile_timeout_is_reported_and_not_cached": SLOW,
    # the batched axis judge against each of 6,480 axes, per model (2 s each); one model stays fast
    **{f"test_texture_model::test_the_fits_batched_axis_judge_equals_judging_each_axis[{case}]": SLOW
       for case in ("unclamped-w-1_trunc-1", "nearest-swapped_wrap-1-v", "half-wh_swapped-round")},
}

# Slow tests `make test` runs too (marked representative): each path of the
# grader end to end once, so that a developer's three-minute run meets most
# regressions before CI's full run (`make test-all`) meets the rest: a
# correct and a wrong submission of each kind of mistake, both isolation
# modes, a class, each platform's entry point, the kit's self-check, one
# attack of each red team, one browser check. Keys as in TEST_MARKERS.
REPRESENTATIVE = (
    "test_grading_zoo::test_correct_submissions_get_full_marks_and_no_diagnosis[if_chain]",
    "test_grading_zoo::test_correct_submissions_get_full_marks_and_no_diagnosis[float_math]",
    "test_grading_zoo::test_wrong_submission_is_diagnosed[v-flipped-pos-z]",
    "test_grading_zoo::test_wrong_submission_is_diagnosed[half-texel-offset]",
    "test_grading_zoo::test_wrong_submission_is_diagnosed[crash-null]",
    "test_grading_zoo::test_wrong_submission_is_diagnosed[syntax-error]",
    "test_grading_zoo::test_the_untouched_template_scores_little_and_says_why",
    "test_gradescope::test_correct_submission_scores_full_marks",
    "test_gradescope::test_build_error_gives_valid_results_and_no_check_passes",
    "test_gradescope::test_students_see_no_instructor_notes_and_instructors_get_them_on_stdout",
    "test_prairielearn::test_entrypoint_grades_a_wrong_submission_in_the_documented_layout",
    "test_commands::test_grade_correct_writes_every_report_and_exits_0",
    "test_commands::test_each_subcommand_has_help",
    "test_grade_all::test_class_summary_written",
    "test_grade_all::test_gradebook_columns_and_statuses",
    "test_grade_all::test_unmatched_students_and_canvas_test_student_are_printed",
    "test_kit::test_selfcheck_names_a_crash",
    "test_kit::test_built_binaries_have_no_lookup_symbols",
    "test_kit::test_a_submission_calling_the_reference_lookup_is_refused_as_the_grader_refuses_it",
    "test_hostile::test_hostile_act_in_fetch_color_gets_its_verdict_at_its_input",
    "test_hostile::test_files_outside_the_sandbox_are_not_visible",
    "test_attack_zoo::test_an_attack_gets_its_verdict_and_the_report_is_intact[forged_reply]",
    "test_attack_zoo::test_an_attack_gets_its_verdict_and_the_report_is_intact[timed_black]",
    "test_production_build::test_in_privilege_drop_mode_the_build_uid_reads_nothing_of_ours",
    "test_production_build::test_a_pasted_has_include_finds_no_course_file",
    "test_redteam3::test_one_cheap_pass_echoed_untimed_does_not_buy_speed",
    "test_redteam3::test_the_controls_are_slow[bubblewrap-slow_control]",
    "test_redteam3::test_the_controls_are_slow[privilege-drop-costly_few_control]",
    "test_i18n::test_a_crash_reads_in_japanese_in_privilege_drop_mode",
    "test_report_html_browser::test_every_image_loads_and_shows_where_it_is_placed",
    "test_markers::test_every_named_test_exists_and_test_fast_leaves_it_out",
)


def _keys(module: str, item) -> tuple[str, ...]:
    """The names a test is listed by: every case of it, and this case."""
    name = getattr(item, "originalname", None) or item.name
    return tuple(dict.fromkeys((f"{module}::{name}", f"{module}::{item.name}")))


def _markers(module: str, item) -> tuple[str, ...]:
    return MODULE_MARKERS.get(module, ()) + tuple(m for key in _keys(module, item) for m in TEST_MARKERS.get(key, ()))


def pytest_collection_modifyitems(config, items):
    for item in items:
        module = item.module.__name__.rsplit(".", 1)[-1]
        for name in dict.fromkeys(_markers(module, item)):
            item.add_marker(getattr(pytest.mark, name))
        if any(key in REPRESENTATIVE for key in _keys(module, item)):
            item.add_marker(pytest.mark.representative)


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded generator: random tests repeat exactly."""
    return np.random.default_rng(20261201)


@pytest.fixture(scope="session", autouse=True)
def session_folder(tmp_path_factory) -> Path:
    """Where session_once keeps what is done once per session (gradings of
    grading_cache.grade_once, the student kit): one folder for every xdist
    worker (their base folders' parent)."""
    import session_once
    base = tmp_path_factory.getbasetemp()
    session_once.FOLDER = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "once"
    return session_once.FOLDER


@pytest.fixture(scope="session")
def student_kit(session_folder):
    """The student kit (grader.kit.build), built once per session: read it,
    never change it (copy it first)."""
    import session_once
    from grader.kit.build import build_kit
    return session_once.once("student-kit", lambda folder: build_kit(folder / "student-kit"))


@pytest.fixture(scope="session")
def reference_library() -> Path:
    """build/libenvmap.so, built once per test run (make reference)."""
    from grader import reference
    path = reference.ensure_built()
    reference.library()
    return path


@pytest.fixture(scope="session")
def correct_build(reference_library):
    """One correct submission, compiled once per test run (grader.build's cache)."""
    from grader.build import build_submission
    source = sorted(CORRECT_SUBMISSION.glob("*.cpp"))[0]
    build = build_submission(source)
    assert build.ok, build.log
    return build


# ---- what another user (nobody) can reach -------------------------------------------

NOBODY = ["setpriv", "--reuid", "65534", "--regid", "65534", "--clear-groups"]
# What a copy of the project for another user leaves out (the venv is the
# interpreter's; build outputs are made again).
NOT_COPIED = (".venv", "build", "out", ".git", "__pycache__", ".pytest_cache", ".tmp-*")


def nobody_python() -> tuple[str | None, str]:
    """An interpreter path user nobody can run with the grader's packages
    (this one, or the same venv by its real path when only the way to it is
    closed, e.g. a .venv symlink inside a 0700 checkout), and why not when none."""
    import os
    import subprocess
    why = ""
    real = os.path.join(os.path.realpath(sys.prefix), "bin", "python")
    for python in dict.fromkeys([sys.executable, real]):
        done = subprocess.run([*NOBODY, python, "-c", "import numpy, cffi, rich"], capture_output=True,
                              text=True, timeout=60, cwd="/")
        if done.returncode == 0:
            return python, ""
        why = (done.stderr.strip().splitlines() or [f"exit {done.returncode}"])[-1]
    return None, why


class NobodyCopy(NamedTuple):
    root: Path       # the project, readable by nobody
    python: str      # an interpreter nobody can run with the grader's packages


@pytest.fixture(scope="session")
def nobody_project(tmp_path_factory) -> NobodyCopy:
    """The project as user nobody can read it: PROJECT_ROOT itself when it
    can, else a copy (without .venv/ and build outputs) in a folder open to
    all, as a checkout in /root or any 0700 folder needs. Skips, saying why,
    when nobody cannot run this interpreter with the grader's packages (a
    virtual environment inside such a folder)."""
    import shutil
    import subprocess
    import tempfile
    python, why = nobody_python()
    if python is None:
        pytest.skip(f"user nobody cannot run {sys.executable} with the grader's packages ({why}): "
                    "the virtual environment is in a folder other users cannot read")
    readable = subprocess.run([*NOBODY, "test", "-r", str(PROJECT_ROOT / "grader" / "__init__.py")],
                              timeout=60, cwd="/").returncode == 0
    if readable:
        yield NobodyCopy(PROJECT_ROOT, python)
        return
    folder = Path(tempfile.mkdtemp(prefix="envmap-for-nobody-"))
    try:
        folder.chmod(0o755)
        copy = folder / "project"
        shutil.copytree(PROJECT_ROOT, copy, ignore=shutil.ignore_patterns(*NOT_COPIED), symlinks=True)
        for path in [copy, *copy.rglob("*")]:
            if not path.is_symlink():
                path.chmod(path.stat().st_mode | (0o755 if path.is_dir() else 0o444))
        yield NobodyCopy(copy, python)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
