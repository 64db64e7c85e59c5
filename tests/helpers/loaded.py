"""Run a command on a machine loaded with N busy processes (make test-load).

    python tests/helpers/loaded.py N [--cpus C | --nice K] -- command ...

Each busy process spins at normal priority for at most an hour (a safety
net should this script be killed); all of them are ended when the command
ends, however it ends. The exit status is the command's.

With --cpus C, where a cpu cgroup can be made (grader/worker/memory.py says
where), the busy processes and the command run in one cgroup of their own,
of the weight of N + 1 ordinary processes and capped at C cores: inside it
every process of the command competes with the N busy ones for at most C
cores, as on a C-core machine at load N (C=1: harder than load N on 2
cores, and harder still where the machine is busy too), while the machine's
other users lose at most C cores. Without a cgroup it says so and loads the
whole machine.

With --nice K, the busy processes run at niceness K, each in a session of
its own whose autogroup is set to K too (/proc/PID/autogroup, where the
kernel groups sessions): the load average reads N and more, as on a shared
machine whose other users run long jobs at low priority, and the command
keeps a core or more (at K = 19 each busy process weighs 15 against an
ordinary process's 1024; measured at N = 30 on 2 cores: the busy processes
took about one core, as the command's processes share autogroups).

The command gets STRETCH_ENV: about how many times slower than alone a
process of it runs (N + 1 over the cores it competes for). Tests import
`stretch` to scale their own timeouts by it (a subprocess's wall-clock
timeout is the test harness's, not a verdict), and `busy_on` for a wait for
a core of their own, on one core.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from contextlib import contextmanager
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from grader.worker import memory  # noqa: E402

STRETCH_ENV = "ENVMAP_LOAD_STRETCH"
BUSY = "import time\nend = time.monotonic() + 3600\nwhile time.monotonic() < end: pass"
PERIOD_US = 100_000


@contextmanager
def busy_on(core: int, count: int):
    """`count` processes spinning on CPU `core` only, ended on the way out:
    a process pinned there too gets about 1/(count + 1) of it. Each runs in
    a session of its own, as a worker or a compiler does: where the kernel
    groups each session's processes (autogroup), they compete one by one."""
    spinners = [subprocess.Popen(["/bin/sh", "-c", "while :; do :; done"], start_new_session=True)
                for _ in range(count)]
    try:
        for proc in spinners:
            os.sched_setaffinity(proc.pid, {core})
        yield
    finally:
        for proc in spinners:
            proc.kill()
            proc.wait()


def stretch() -> float:
    """How many times slower than alone this process runs under loaded.py (1 elsewhere)."""
    try:
        return max(1.0, float(os.environ.get(STRETCH_ENV, "1")))
    except ValueError:
        return 1.0


def capped_cgroup(cpus: float, processes: int) -> Path | None:
    """A new cpu cgroup under ours, of the weight of `processes` ordinary
    ones, capped at `cpus` cores; None where none can be made."""
    parent, version, why = memory._own_cgroup("cpu")
    if parent is None:
        print(f"loaded.py: no cpu cgroup ({why}): the whole machine is loaded", flush=True)
        return None
    path = parent / f"envmap-loaded-{os.getpid()}"
    path.mkdir()
    quota = str(int(cpus * PERIOD_US))
    if version == 2:
        (path / "cpu.weight").write_text(str(min(10_000, 100 * processes)))
        (path / "cpu.max").write_text(f"{quota} {PERIOD_US}")
    else:
        (path / "cpu.shares").write_text(str(1024 * processes))
        (path / "cpu.cfs_period_us").write_text(str(PERIOD_US))
        (path / "cpu.cfs_quota_us").write_text(quota)
    return path


def joined(cmd: list[str], group: Path | None) -> list[str]:
    if group is None:
        return cmd
    return ["/bin/sh", "-c", 'echo $$ >"$0" && exec "$@"', str(group / "cgroup.procs"), *cmd]


def weight(nice: int) -> float:
    """The scheduler's weight of a process at niceness `nice` (1024 at 0,
    about 1.25 times less for each step: sched_prio_to_weight)."""
    return 1024 / 1.25 ** nice


def niced(nice: int):
    """A preexec_fn: this process and its session's autogroup at `nice`."""
    def run():
        os.nice(nice)
        try:
            Path(f"/proc/{os.getpid()}/autogroup").write_text(str(nice))
        except OSError:       # no autogroups here: the niceness alone
            pass
    return run


def main(argv: list[str]) -> int:
    cpus = nice = None
    if len(argv) > 2 and argv[1] == "--cpus":
        cpus, argv = float(argv[2]), [argv[0], *argv[3:]]
    elif len(argv) > 2 and argv[1] == "--nice":
        nice, argv = int(argv[2]), [argv[0], *argv[3:]]
    if len(argv) < 3 or argv[1] != "--" or not argv[0].isdigit():
        print(__doc__, file=sys.stderr)
        return 2
    count, command = int(argv[0]), argv[2:]
    group = capped_cgroup(cpus, count + 1) if cpus else None
    busy = [subprocess.Popen(joined([sys.executable, "-c", BUSY], group), start_new_session=True,
                             preexec_fn=niced(nice) if nice else None)
            for _ in range(count)]
    where = f"in a cgroup capped at {cpus:g} cores ({group})" if group else "on the whole machine"
    if nice:
        where += f" at nice {nice}"
    time.sleep(1)       # started: the load average begins to count them
    print(f"loaded.py: {count} busy processes {where}; load average now {os.getloadavg()[0]:.1f}", flush=True)
    cores = cpus if group is not None else len(os.sched_getaffinity(0))
    others = count * weight(nice or 0) / 1024
    env = {**os.environ, STRETCH_ENV: f"{(others + cores) / cores:g}"}
    began = time.monotonic()
    try:
        return subprocess.call(joined(command, group), env=env)
    finally:
        for proc in busy:
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            proc.wait()
        print(f"loaded.py: {time.monotonic() - began:.0f} s; load average at the end {os.getloadavg()[0]:.1f}",
              flush=True)
        if group is not None:
            for _ in range(100):
                try:
                    group.rmdir()
                    break
                except OSError:
                    time.sleep(0.05)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
