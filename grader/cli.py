"""`python -m grader <command>`: one module per command in grader/commands/.

Each command module defines HELP (one line), add_arguments(parser) and
run(args) -> int (the exit status). Modules are imported only when their
command runs, so `--help` stays fast and one broken command cannot break the
others.
"""
from __future__ import annotations

import argparse
import importlib
import sys

COMMANDS = {
    "grade": "grade one submission and write its reports",
    "grade-all": "grade every submission in a folder (a class) in parallel",
    "lookup": "look up directions read from stdin in a cube map (reference)",
    "render": "render a scene file with the reference renderer",
    "fixtures": "regenerate fixtures/ from the reference",
    "kit": "build the student kit (template, renderer, self-check; no lookup, no secret)",
    "bundle": "the old name of `kit`: build the student kit",
    "gradescope": "build autograder.zip for Gradescope",
    "prairielearn": "grade /grade/student for PrairieLearn's external grader",
    "cubemap": "generate and convert environment maps",
    "study": "speed against accuracy of the lookup methods",
    "audit": "measure the grader: grade mutants of correct solutions and count what escapes",
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m grader",
        description="Autograder for the cube-map environment-mapping assignment.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    argv = sys.argv[1:] if argv is None else argv
    chosen = next((a for a in argv if not a.startswith("-")), None)
    for name, help_text in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        if name == chosen:
            module = importlib.import_module(f"grader.commands.{name.replace('-', '_')}")
            module.add_arguments(p)
            p.set_defaults(run=module.run)
    args = parser.parse_args(argv)
    if not getattr(args, "run", None):
        parser.print_help()
        return 2
    return args.run(args)
