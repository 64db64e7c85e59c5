"""`python -m grader <command>`: one module per command in grader/commands/.

Each command module defines HELP (one line), add_arguments(parser) and
run(args) -> int (the exit status). Modules are imported only when their
command runs, so `--help` stays fast and one broken command cannot break the
others.
"""
from __future__ import annotations

import argparse
import ast
import importlib
import sys
from pathlib import Path

# In the order `--help` lists them; each one's help is its module's HELP.
COMMANDS = ("grade", "grade-all", "lookup", "render", "fixtures", "kit", "bundle", "gradescope", "prairielearn",
            "cubemap", "study", "audit")


def module_name(command: str) -> str:
    return command.replace("-", "_")


def command_help(command: str) -> str:
    """The command module's HELP, read from its source rather than imported:
    `--help` stays fast and cannot be broken by one command's imports."""
    path = Path(__file__).with_name("commands") / f"{module_name(command)}.py"
    try:
        for node in ast.parse(path.read_text(), str(path)).body:
            if isinstance(node, ast.Assign) and [getattr(t, "id", None) for t in node.targets] == ["HELP"]:
                return ast.literal_eval(node.value)
    except (OSError, SyntaxError, ValueError) as e:
        return f"(its help cannot be read: {e})"
    return "(no help)"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m grader",
        description="Autograder for the cube-map environment-mapping assignment.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    argv = sys.argv[1:] if argv is None else argv
    chosen = next((a for a in argv if not a.startswith("-")), None)
    for name in COMMANDS:
        help_text = command_help(name)
        p = sub.add_parser(name, help=help_text, description=help_text)
        if name == chosen:
            module = importlib.import_module(f"grader.commands.{module_name(name)}")
            module.add_arguments(p)
            p.set_defaults(run=module.run)
    args = parser.parse_args(argv)
    if not getattr(args, "run", None):
        parser.print_help()
        return 2
    return args.run(args)
