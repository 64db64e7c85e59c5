"""The options several commands share (grade, grade-all, gradescope,
prairielearn, audit), each written once: its name, where it lands in args,
and its help. A command adds the ones it takes; `when` prefixes the help
where an option applies to one mode only (gradescope's "with --grade: ")."""
from __future__ import annotations

import argparse

from ..i18n.languages import CODES


def quick(p: argparse.ArgumentParser, when: str = "") -> None:
    p.add_argument("--quick", action="store_true", help=f"{when}smaller direction sets (for trying the grader out)")


def language(p: argparse.ArgumentParser) -> None:
    p.add_argument("--lang", choices=CODES,
                   help="language of what students read (default: the rubric's grading.language)")


def isolation(p: argparse.ArgumentParser, when: str = "", no_sandbox: bool = True) -> None:
    """--no-sandbox (privilege-drop mode) and --unsafe-no-sandbox (no isolation at all)."""
    if no_sandbox:
        p.add_argument("--no-sandbox", dest="sandbox", action="store_false", default=None,
                       help=f"{when}do not use bubblewrap (privilege-drop mode as root; otherwise needs "
                            "--unsafe-no-sandbox)")
    p.add_argument("--unsafe-no-sandbox", dest="allow_unsafe", action="store_true",
                   help=f"{when}grade even where student code cannot be isolated (no bubblewrap, not root): a "
                        "submission could then read the grader's environment and write its files")


def allow_stale(p: argparse.ArgumentParser) -> None:
    p.add_argument("--allow-stale", action="store_true", help="grade even when fixtures/ is stale")


def progress(p: argparse.ArgumentParser) -> None:
    p.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bars")
