"""memory.charged: the shell every worker and compiler step starts under,
and the gate a prepared worker waits at (process.Worker.prepare)."""
from __future__ import annotations

import subprocess

from grader.worker import memory
from grader.worker.process import TEXTURE_BYTES_SLOT


def gated(line: bytes | None, *args: str) -> subprocess.CompletedProcess:
    """The gated shell around `echo args`, given `line` at its gate (None: end of file)."""
    cmd = memory.charged(["/bin/echo", *args], slot=TEXTURE_BYTES_SLOT)
    return subprocess.run(cmd, input=line if line is not None else b"", capture_output=True, timeout=10)


def test_the_gate_fills_the_slot_and_keeps_every_other_argument_as_it_was():
    done = gated(b"41472\n", "--texture-bytes", TEXTURE_BYTES_SLOT, "a b", "$HOME", "*", "")
    assert done.returncode == 0
    assert done.stdout == b"--texture-bytes 41472 a b $HOME * \n"


def test_at_the_gates_end_of_file_or_another_line_nothing_runs():
    for line in (None, b"", b"12x\n", b"\n", b"1; echo no\n"):
        done = gated(line, "ran")
        assert done.returncode == 75 and done.stdout == b"", line


def test_without_a_slot_the_shell_runs_the_command_at_once():
    done = subprocess.run(memory.charged(["/bin/echo", "now", TEXTURE_BYTES_SLOT]), stdin=subprocess.DEVNULL,
                          capture_output=True, timeout=10)
    assert done.stdout == f"now {TEXTURE_BYTES_SLOT}\n".encode()
