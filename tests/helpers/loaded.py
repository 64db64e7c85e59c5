"""Run a command on a machine loaded with N busy processes (make test-load).

    python tests/helpers/loaded.py N -- command ...

Each busy process spins on one core, at normal priority, for at most an
hour (a safety net should this script be killed); all of them are ended
when the command ends, however it ends. The exit status is the command's.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys

BUSY = "import time\nend = time.monotonic() + 3600\nwhile time.monotonic() < end: pass"


def main(argv: list[str]) -> int:
    if len(argv) < 3 or argv[1] != "--" or not argv[0].isdigit():
        print(__doc__, file=sys.stderr)
        return 2
    count, command = int(argv[0]), argv[2:]
    busy = [subprocess.Popen([sys.executable, "-c", BUSY], start_new_session=True) for _ in range(count)]
    print(f"loaded.py: {count} busy processes; load average now {os.getloadavg()[0]:.1f}", flush=True)
    try:
        return subprocess.call(command)
    finally:
        for proc in busy:
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            proc.wait()
        print(f"loaded.py: load average at the end {os.getloadavg()[0]:.1f}", flush=True)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
