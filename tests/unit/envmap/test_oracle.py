"""grader.envmap.oracle: the checks get the reference's answers through one interface,
so answers recorded once (the kit's) grade exactly as the live reference does."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from fake_lookups import FakeLookups
from grader.envmap import geometry, oracle, library
from grader.checks import all_checks, run_checks
from grader.checks.context import CheckContext
from project_paths import PROJECT_ROOT

ROOT = PROJECT_ROOT
CHECKS = all_checks()
# Every check but speed (it times the live reference, and is grader-only).
RECORDABLE = ("read_texture", "fetch_sweep", "diagnosis", "stability", "arrows", "renders")


def _grade(lookups, tmp_path):
    order = [c for c in CHECKS.values() if c.name in RECORDABLE]
    ctx = CheckContext(lookups=lookups, seed=4321, artifacts=tmp_path / "images", quick=True)
    return run_checks(order, ctx, [c.name for c in order]).results


def _verdicts(results):
    return [(r.name, r.status, round(r.fraction, 6), [(d.id, d.face) for d in r.diagnoses], r.output)
            for r in results]


def _refuse_live(monkeypatch):
    """The C reference's lookup refused to all but the fake submission
    (which is built on it): a check must get its answers from the oracle."""
    def refusing(original):
        def call(*args, **kwargs):
            if not sys._getframe(1).f_code.co_filename.endswith("fake_lookups.py"):
                raise AssertionError(f"{original.__qualname__} asked outside the oracle during replay")
            return original(*args, **kwargs)
        return call
    for owner, name in ((library, "direction_to_face"), (library.CubeMap, "fetch"),
                        (library.CubeMap, "fetch_with_faces"), (library.CubeMap, "read_texture"),
                        (library.Scene, "render")):
        monkeypatch.setattr(owner, name, refusing(getattr(owner, name)))


# slow: a kit recording graded per mistake (5-21 s each); the first case stays fast
@pytest.mark.parametrize("mistakes", [
    {},
    pytest.param({"texture": "half-texel", "fetch": {"+X": "u-flipped"}}, marks=pytest.mark.slow),
    pytest.param({"fetch": {"+X": "wrong-face:-X", "-X": "wrong-face:+X"}}, marks=pytest.mark.slow),
])
def test_recorded_answers_grade_as_the_live_reference(tmp_path, monkeypatch, mistakes):
    geometry.face_frames.cache_clear()       # its probes are questions too: ask them in the recording
    recorder = oracle.Recorder(oracle.LiveReference())
    with oracle.using(recorder):
        live = _grade(FakeLookups(**mistakes), tmp_path / "live")
    recorder.save(tmp_path / "answers.npz")
    assert all(r.error_log in (None, "") for r in live), [r.error_log for r in live]

    _refuse_live(monkeypatch)
    geometry.face_frames.cache_clear()
    with oracle.using(oracle.Replay(tmp_path / "answers.npz")):
        replayed = _grade(FakeLookups(**mistakes), tmp_path / "replay")
    assert _verdicts(replayed) == _verdicts(live)


def test_a_question_not_recorded_is_refused_not_guessed(tmp_path):
    recorder = oracle.Recorder(oracle.LiveReference())
    recorder.direction_to_face(np.array([[1.0, 0.2, 0.1]]))
    recorder.save(tmp_path / "answers.npz")
    replay = oracle.Replay(tmp_path / "answers.npz")
    face, uv = replay.direction_to_face(np.array([[1.0, 0.2, 0.1]]))
    assert int(face[0]) == 0 and uv.shape == (1, 2)
    with pytest.raises(oracle.MissingAnswer):
        replay.direction_to_face(np.array([[1.0, 0.2, 0.1000001]]))
    with pytest.raises(oracle.MissingAnswer):
        replay.fetch(np.zeros((6, 2, 2, 3), np.float32), np.array([[1.0, 0.2, 0.1]]))


def test_the_checks_ask_the_oracle_in_use(tmp_path):
    # An empty recording: every check that needs the reference must fail to
    # find its answer (a harness error), none may reach the C library.
    oracle.Recorder(oracle.LiveReference()).save(tmp_path / "empty.npz")
    with oracle.using(oracle.Replay(tmp_path / "empty.npz")):
        results = _grade(FakeLookups(), tmp_path / "empty")
    first = {r.name: r for r in results}["read_texture"]
    assert "MissingAnswer" in (first.error_log or ""), first.error_log


@pytest.fixture(scope="module")
def kit_answers():
    """Recorded once per session for both xdist workers (tests/helpers/session_once.py)."""
    import session_once
    from grader.kit import answers

    def record(folder):
        answers.record(folder / answers.ANSWERS, folder / "images", seed=4321, quick=True)
        return folder / answers.ANSWERS
    return session_once.once("kit-answers-4321-quick", record)


# Mistakes the kit's recording never ran (it runs only a handout-like
# submission and a silent readTexture): their questions must all be there.
# slow: a kit recording graded per mistake (5-21 s each); not-normalized stays fast
@pytest.mark.parametrize("mistakes", [
    pytest.param({"texture": "nearest"}, marks=pytest.mark.slow),
    pytest.param({"texture": "scrambled"}, marks=pytest.mark.slow),    # no model fits: the worked case and the read-back
    pytest.param({"texture": "out-of-bounds", "fetch": {"+X": "u-flipped"}}, marks=pytest.mark.slow),
    {"fetch": "not-normalized"},
    pytest.param({"texture": "half-texel", "fetch": {"+X": "wrong-face:-X", "-X": "wrong-face:+X"}},
                 marks=pytest.mark.slow),
])
def test_the_kits_recording_answers_submissions_it_never_saw(tmp_path, monkeypatch, kit_answers, mistakes):
    live = _grade(FakeLookups(**mistakes), tmp_path / "live")
    _refuse_live(monkeypatch)
    geometry.face_frames.cache_clear()
    with oracle.using(oracle.Replay(kit_answers)):
        replayed = _grade(FakeLookups(**mistakes), tmp_path / "replay")
    assert [r.error_log for r in replayed if r.error_log] == []
    assert _verdicts(replayed) == _verdicts(live)


@pytest.fixture(scope="module")
def kit_seed_answers(student_kit):
    """The answers the kit ships (grader.kit.build records them with the kit's seed)."""
    from grader.kit import answers
    path = student_kit.folder / "selfcheck" / answers.ANSWERS
    assert path.is_file(), sorted(student_kit.files)
    return path


def _grade_cli(submission, out, *flags):
    import subprocess
    subprocess.run([sys.executable, "-m", "grader", "grade", str(submission), "--kit-inputs", "--out", str(out), *flags],
                   check=True, capture_output=True, cwd=ROOT)
    result = json.loads((out / "results.json").read_text())
    return [(t["name"], t.get("score")) for t in result["tests"]], (out / "report.md").read_text()


# Real C++ in the worker: the kit's answers grade as the live reference does
# on the kit's inputs (per-check points and the whole report), in both modes.
@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.parametrize("name, flags", [
    ("wrong/half-texel-offset", ()),
    ("compound/rows-flipped-w1-half-trunc_uv-swapped-neg-y", ()),
    ("compound/unclamped-offset-one_flips", ("--no-sandbox",)),
    ("wrong/crash-null", ("--no-sandbox",)),
])
def test_grading_on_the_kits_answers_equals_the_live_reference(tmp_path, kit_seed_answers, name, flags):
    submission = ROOT / "tests" / "submissions" / f"{name}.cpp"
    live = _grade_cli(submission, tmp_path / "live", *flags)
    replayed = _grade_cli(submission, tmp_path / "replay", "--kit-answers", str(kit_seed_answers), *flags)
    assert replayed == live
