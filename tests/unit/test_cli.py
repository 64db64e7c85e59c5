"""grader/cli.py lists the commands; each command's help is written once, as
its module's HELP, and `--help` shows that text."""
from __future__ import annotations

import importlib
import re
import subprocess
import sys

from grader import PROJECT_ROOT, cli


def test_every_command_module_is_listed_once():
    # options.py holds the options several commands share, no command.
    modules = sorted(p.stem for p in (PROJECT_ROOT / "grader" / "commands").glob("*.py")
                     if p.stem not in ("__init__", "options"))
    assert sorted(cli.module_name(c) for c in cli.COMMANDS) == modules
    assert len(set(cli.COMMANDS)) == len(cli.COMMANDS)


def test_the_help_shown_is_each_modules_HELP():
    for command in cli.COMMANDS:
        module = importlib.import_module(f"grader.commands.{cli.module_name(command)}")
        assert cli.command_help(command) == module.HELP, command


def test_help_lists_every_command_with_its_HELP():
    done = subprocess.run([sys.executable, "-m", "grader", "--help"], cwd=PROJECT_ROOT, capture_output=True,
                          text=True, env={"COLUMNS": "1000", "PATH": "/usr/bin:/bin"})
    assert done.returncode == 0, done.stderr
    for command in cli.COMMANDS:
        line = rf"^ +{re.escape(command)}\s+{re.escape(cli.command_help(command))}$"   # a long name wraps
        assert re.search(line, done.stdout, re.M), (command, done.stdout)


SHARED = {"grade": ("--quick", "--no-sandbox", "--unsafe-no-sandbox", "--lang", "--allow-stale"),
          "grade-all": ("--quick", "--no-sandbox", "--unsafe-no-sandbox", "--lang", "--allow-stale", "--no-progress"),
          "gradescope": ("--quick", "--unsafe-no-sandbox", "--lang"),
          "prairielearn": ("--quick", "--lang"),
          "audit": ("--quick", "--no-sandbox", "--unsafe-no-sandbox", "--allow-stale", "--no-progress")}


def _actions(command: str) -> dict:
    import argparse
    parser = argparse.ArgumentParser()
    importlib.import_module(f"grader.commands.{cli.module_name(command)}").add_arguments(parser)
    return {a.option_strings[0]: a for a in parser._actions if a.option_strings}


def test_the_shared_options_are_one_definition_in_every_command():
    """grade, grade-all, gradescope, prairielearn and audit take each shared
    option from grader/commands/options.py: the same destination, choices,
    default and help (but for gradescope's "with --grade: ")."""
    seen: dict[str, tuple] = {}
    for command, names in SHARED.items():
        actions = _actions(command)
        for name in names:
            a = actions[name]
            key = (a.dest, a.choices and tuple(a.choices), a.default, a.help.removeprefix("with --grade: "))
            assert seen.setdefault(name, key) == key, (command, name)
    assert seen["--lang"][1] == tuple(__import__("grader.i18n.languages", fromlist=["CODES"]).CODES)
