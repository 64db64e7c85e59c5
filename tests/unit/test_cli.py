"""grader/cli.py lists the commands; each command's help is written once, as
its module's HELP, and `--help` shows that text."""
from __future__ import annotations

import importlib
import re
import subprocess
import sys

from grader import PROJECT_ROOT, cli


def test_every_command_module_is_listed_once():
    modules = sorted(p.stem for p in (PROJECT_ROOT / "grader" / "commands").glob("*.py") if p.stem != "__init__")
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
