"""The grading checks and their contract.

A check is a function registered with @check, check50 style:

    @check(requires=(read_texture,))
    def fetch_sweep(ctx: CheckContext, result: CheckResult, texture: ReadTextureFinding) -> SweepFinding:
        \"\"\"fetchColor picks the right face and (u, v) for every direction.\"\"\"

- Its name (the rubric key) is the function's name; the first line of its
  docstring is the sentence the student reads. Both are written once.
- The runner (`run_checks`) creates the CheckResult and passes it in; the
  check fills in status, fraction, output, diagnoses, metrics, artifacts.
- `requires` lists prerequisite check *functions*. The runner passes each
  prerequisite's return value (its typed finding, e.g. ReadTextureFinding),
  in the order listed, after (ctx, result). A check that nothing depends on
  may return None.
- When a dependent is skipped (status SKIPPED, zero points, the reason in its
  output) is decided per dependency:
    * a bare function reference (`requires=(read_texture,)`) means "needs the
      prerequisite's finding": the dependent is skipped only when the
      prerequisite did not run to the end (harness error, or itself skipped).
      A prerequisite that ran and FAILED still hands over its finding, e.g.
      fetchColor is judged on its own whatever readTexture does.
    * `Needs(fn, passing=predicate, why="...")` also skips the dependent when
      the predicate on the prerequisite's finding is false ("failed" as far as
      this dependent is concerned), e.g. speed needs fetchColor to be right on
      some of the sweep: timing a lookup that returns black means nothing.
    * `Needs(fn, credit=share)`: the dependent earns `share(finding)` (0..1)
      of what it finds, and its output says why (`share.words(finding)`):
      robustness and speed count in proportion to how much of the sweep is
      right, a line rather than a threshold, so one direction more or less
      never moves many points (issue 30). score.apply multiplies it in.
  There are no default findings: a dependent never runs without its inputs.
- `end_to_end=True` marks a check that looks up whole maps the way a program
  does, after faces of another size (context.set_end_to_end_faces). Before
  the first of them, run_checks asks fetchColor the same directions in that
  state and in a process whose first faces they are
  (instruments.process_state); where any answer differs, each end-to-end
  check runs in both states and the lower score counts, with the
  observation as a diagnosis.
- `public_maps=True` marks a check that looks up the public maps of
  Cubemap/ (arrows, renders). Its runs there are observed on a sample of
  their directions (instruments.map_probe: what fetchColor asks for on
  random faces of the same size, read again on the map); where an answer
  differs, run_checks runs the check again with fetchColor's requests on
  random faces of each map's size, read from the public maps
  (map_probe.RandomFaceRequests), and the lower score counts, with the
  observation as a diagnosis.
- Points, partial credit and visibility live in grader/grading/rubric.toml. The run
  order is the rubric's order (score.load_rubric refuses unknown or missing
  check names, and a check listed before one it requires). MODULES only says
  which modules to import.
"""
from __future__ import annotations

import importlib
import logging
import os
import time
import traceback
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable

from ..i18n import N_, _
from ..grading.results import ERROR, SKIPPED, CheckResult

log = logging.getLogger("grader.checks")

# One OpenMP thread for FLIP (flip_evaluator's own libgomp): the renders are
# small and idle OpenMP threads spin, so more threads only burn CPU another
# grading (or a busy machine) needs. The renders check took 0.8-0.9 s of CPU
# with FLIP's default threads on 2 cores, 0.35-0.47 s with one. One thread is
# also one summation order. Set before flip_evaluator loads (it is imported
# where used); a value the caller set is kept.
os.environ.setdefault("OMP_NUM_THREADS", "1")

# Modules holding checks (import order only: the rubric orders the run).
MODULES = ("read_texture", "fetch_sweep", "fetch_faces", "arrows", "stability", "renders", "speed")

# Shares (of cases passed, of points earned) are printed to 0.01% and used as
# printed: the numbers a student reads are the numbers that scored (issue 30).
SHOWN_DIGITS = 4


def shown(share: float) -> float:
    """A share as reports print it and score.apply uses it."""
    return round(float(share), SHOWN_DIGITS)


# What a student reads when the harness failed on a check. The traceback goes
# to CheckResult.error_log and the "grader.checks" log, for the instructor.
HARNESS_ERROR_OUTPUT = N_("The grader itself failed on this check; this is not your fault. "
                          "Your instructor has been told.")


@dataclass(frozen=True)
class Needs:
    """A prerequisite with a condition: the dependent runs only when
    `passing(finding)` holds; otherwise it is skipped, the output saying `why`
    (a catalogue id, or a function returning the words in the current language)."""
    check: Callable
    passing: Callable[[Any], bool] | None = None
    why: str | Callable[[], str] = ""
    credit: "Credit | None" = None


@dataclass(frozen=True)
class Credit:
    """How much of its points a dependent can earn after its prerequisite's
    finding: `share(finding)` in 0..1, `words(finding)` saying why with the
    numbers used (as shown)."""
    share: Callable[[Any], float]
    words: Callable[[Any], str]


@dataclass(frozen=True)
class Check:
    name: str
    title: str
    run: Callable[..., Any]
    requires: tuple[Needs, ...] = ()
    end_to_end: bool = False
    public_maps: bool = False

    @property
    def prerequisites(self) -> tuple[str, ...]:
        return tuple(check_of(n.check).name for n in self.requires)


REGISTRY: dict[str, Check] = {}


class CheckDefinitionError(Exception):
    """A check is declared wrongly (the grader's own mistake, found at import)."""


def check(requires: Iterable[Callable | Needs] = (), registry: dict[str, Check] | None = None,
          end_to_end: bool = False, public_maps: bool = False):
    """Register a check; see the module docstring for the contract.
    `registry`: where to register (tests use their own; default REGISTRY)."""
    registry = REGISTRY if registry is None else registry
    needs = tuple(r if isinstance(r, Needs) else Needs(r) for r in requires)

    def register(fn):
        name = fn.__name__
        if not fn.__doc__ or not fn.__doc__.strip():
            raise CheckDefinitionError(f"check {name}: its docstring's first line is the title students read")
        for n in needs:
            if not hasattr(n.check, "__check__"):
                raise CheckDefinitionError(f"check {name} requires {getattr(n.check, '__name__', n.check)!r}, "
                                           "which is not a @check function")
        if name in registry and registry[name].run is not fn:
            raise CheckDefinitionError(f"two checks are named {name}")
        c = Check(name, fn.__doc__.strip().splitlines()[0], fn, needs, end_to_end, public_maps)
        fn.__check__ = c
        registry[name] = c
        return fn
    return register


def check_of(fn: Callable) -> Check:
    return fn.__check__


def all_checks() -> dict[str, Check]:
    """Every registered check by name (registration order, not run order)."""
    for module in MODULES:
        importlib.import_module(f"{__name__}.{module}")
    return dict(REGISTRY)


def ordered_checks(rubric: dict) -> list[Check]:
    """The checks in the rubric's order (the run and report order); the
    rubric has been validated against the registry by score.load_rubric."""
    registry = all_checks()
    return [registry[name] for name in rubric.get("checks", {})]


@dataclass
class Ran:
    """What the runner keeps per check: its result and its finding."""
    result: CheckResult
    finding: Any = None
    finished: bool = False      # ran to the end (passed or failed): its finding exists


@dataclass
class CheckRun:
    """The results of the selected checks, in order; `hidden_runs` were run
    only because a selected check needs their finding (not reported)."""
    results: list[CheckResult] = field(default_factory=list)
    hidden_runs: list[str] = field(default_factory=list)


def _closure(checks: list[Check], selected: set[str]) -> list[Check]:
    """The selected checks and everything they require, in `checks`' order."""
    by_name = {c.name: c for c in checks}
    wanted, todo = set(), list(selected)
    while todo:
        name = todo.pop()
        if name in wanted:
            continue
        wanted.add(name)
        todo += by_name[name].prerequisites
    return [c for c in checks if c.name in wanted]


def _blocked(c: Check, done: dict[str, Ran]) -> str | None:
    """Why `c` cannot run, or None."""
    for need in c.requires:
        pre = check_of(need.check)
        ran = done.get(pre.name)
        if ran is None or not ran.finished:
            if ran is None:
                text = N_("Not run: it needs the check \u201c%(check)s\u201d, which did not run.")
            elif ran.result.status == SKIPPED:
                text = N_("Not run: it needs the check \u201c%(check)s\u201d, which could not run.")
            else:
                text = N_("Not run: it needs the check \u201c%(check)s\u201d, which stopped with a grader error.")
            return _(text) % {"check": _(pre.title)}
        if need.passing is not None and not need.passing(ran.finding):
            if need.why:   # a catalogue id, or a function giving the words (with numbers)
                why = need.why() if callable(need.why) else _(need.why)
                return _("Not run: %(why)s") % {"why": why}
            return _("Not run: it needs the check \u201c%(check)s\u201d to pass first.") % {"check": _(pre.title)}
    return None


def _refuse_unknown_ids(c: Check, result: CheckResult) -> None:
    """A diagnosis id missing from grader/grading/catalogue.py is the grader's bug:
    the check becomes a harness error (ungradable, not the student's zero)."""
    from ..grading.catalogue import CATALOGUE
    unknown = sorted({d.id for d in result.diagnoses if d.id not in CATALOGUE})
    if unknown:
        result.status, result.fraction, result.output, result.diagnoses = ERROR, 0.0, _(HARNESS_ERROR_OUTPUT), []
        result.error_log += f"check {c.name} emitted diagnosis ids missing from grader/grading/catalogue.py: {', '.join(unknown)}\n"
        log.error(result.error_log)


def _apply_credit(c: Check, result: CheckResult, done: dict[str, Ran]) -> None:
    """The share of its points a check can earn after its prerequisites'
    findings (Needs.credit), and why, before what it found."""
    for need in c.requires:
        if need.credit is not None:
            finding = done[check_of(need.check).name].finding
            share = need.credit.share(finding)
            if share < 1.0:
                result.credit *= share
                result.output = need.credit.words(finding) + ("\n\n" + result.output if result.output else "")


def _run_one(c: Check, ctx, inputs: list) -> Ran:
    """One run of a check: its result, and its finding when it ran to the end."""
    result = CheckResult(c.name, _(c.title))   # the title is the docstring's first line, a catalogue id
    ran = Ran(result)
    # Each check narrows failures down on its own budget: how many an
    # earlier check's random inputs hit decides nothing here.
    # (In-process stand-ins, which never fail a run, have no budget; tests
    # of this runner pass no context.)
    reset = getattr(getattr(ctx, "lookups", None), "reset_failure_budget", None)
    if reset is not None:
        reset()
    try:
        ran.finding = c.run(ctx, result, *inputs)
        ran.finished = True
    except Exception:  # the harness failed, not the student: no traceback for the student
        result.status, result.fraction = ERROR, 0.0
        result.output = _(HARNESS_ERROR_OUTPUT)
        result.diagnoses = []
        result.error_log = traceback.format_exc()
        log.error("check %s failed:\n%s", c.name, result.error_log)
    return ran


@dataclass(frozen=True)
class OtherState:
    """A state a check is run again in when a probe observes that fetchColor
    behaves otherwise there; the lower score counts."""
    probe: str                      # the CheckContext method giving the observation (.depends, .diagnosis())
    folder: str                     # its pictures' folder: the run not kept must not replace the kept run's
    applies: Callable[[Check], bool]
    kept: str                       # what the check's output says first when this run is kept (a catalogue id)
    flag: str | None = None         # a CheckContext attribute set while it runs
    lookups: str | None = None      # the CheckContext method giving the lookups the check sees while it runs


OTHER_STATES = (
    # In a process whose first faces they are (instruments.process_state).
    OtherState("states", "first-faces", lambda c: c.end_to_end,
               N_("What follows (numbers and pictures) is this check's run with each map looked up in a fresh "
                  "process whose first faces it is: it scored lower than the run after faces of another size "
                  "(fetch-depends-on-earlier-faces)."), flag="first_faces"),
    # fetchColor's requests on random faces of each map's size, read from the
    # public maps (instruments.map_probe).
    OtherState("map_probe", "random-face-requests", lambda c: c.public_maps,
               N_("What follows (numbers and pictures) is this check's run on what your fetchColor asks for on "
                  "random faces of each map's size, read from the public maps as the handout's readTexture reads: "
                  "it scored lower than your lookup on the maps themselves (fetch-depends-on-the-map)."),
               lookups="random_face_requests"),
)


def _observed(ctx, state: OtherState, result: CheckResult):
    """The probe's observation when it shows fetchColor behaving otherwise,
    else None. A probe the harness could not run leaves the check's one run
    standing, the traceback in its error log."""
    probe = getattr(ctx, state.probe, None)
    if probe is None:
        return None
    try:
        observed = probe()
        return observed if observed.depends else None
    except Exception:
        result.error_log += f"the probe {state.probe} failed:\n" + traceback.format_exc()
        log.error("the probe %s failed:\n%s", state.probe, traceback.format_exc())
        return None


def _run_in_other_states(c: Check, ctx, inputs: list, ran: Ran) -> Ran:
    """The check again in each other state whose probe observed fetchColor
    behaving otherwise; the lowest score kept, with its observations."""
    said = []
    for state in OTHER_STATES:
        if not state.applies(c):
            continue
        observed = _observed(ctx, state, ran.result)
        if observed is None:
            continue
        artifacts, lookups = ctx.artifacts, ctx.lookups
        ctx.artifacts = artifacts / state.folder
        if state.flag:
            setattr(ctx, state.flag, True)
        if state.lookups:
            ctx.lookups = getattr(ctx, state.lookups)()
        try:
            other = _run_one(c, ctx, inputs)
        finally:
            ctx.artifacts, ctx.lookups = artifacts, lookups
            if state.flag:
                setattr(ctx, state.flag, False)
        if other.finished and other.result.fraction < ran.result.fraction:
            said.append(observed.diagnosis())
            other.result.error_log = ran.result.error_log + other.result.error_log
            other.result.output = _(state.kept) + ("\n\n" + other.result.output if other.result.output else "")
            ran = other
    ran.result.diagnoses += said
    return ran


def run_checks(checks: list[Check], ctx, selected: Iterable[str] | None = None) -> CheckRun:
    """Run `checks` in order, handing findings to dependents. `selected`
    (default: all) are reported; prerequisites they need run too, unreported."""
    names = [c.name for c in checks]
    chosen = set(names if selected is None else selected)
    out = CheckRun()
    done: dict[str, Ran] = {}
    for c in _closure(checks, chosen):
        reason = _blocked(c, done)
        if reason:
            ran = Ran(CheckResult(c.name, _(c.title)))   # the title is the docstring's first line, a catalogue id
            ran.result.status, ran.result.fraction, ran.result.output = SKIPPED, 0.0, reason
        else:
            inputs = [done[check_of(n.check).name].finding for n in c.requires]
            t0 = time.monotonic()
            ran = _run_one(c, ctx, inputs)
            if ran.finished:
                ran = _run_in_other_states(c, ctx, inputs, ran)
            result = ran.result
            result.duration_s = time.monotonic() - t0
            _refuse_unknown_ids(c, result)
            if ran.finished:
                _apply_credit(c, result, done)
        result = ran.result
        done[c.name] = ran
        if c.name in chosen:
            out.results.append(result)
        else:
            out.hidden_runs.append(c.name)
    return out
