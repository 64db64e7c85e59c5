"""How a worker failed, in words a student can act on.

A SubmissionFailure is what the Worker raises (what happened, without the
input); the runner turns it into a Failure (which input, and a hint). The
messages contain nothing that changes between runs (no addresses, no pids),
so grading the same submission twice gives the same report.
"""
from __future__ import annotations

import signal

from . import protocol
from .protocol import CrashReport

FACE_NAMES = ("+X", "-X", "+Y", "-Y", "+Z", "-Z")

# Failure kinds (Failure.kind).
CRASH = "crash"
TIMEOUT = "timeout"
EXCEPTION = "exception"
FORBIDDEN_SYSCALL = "forbidden-syscall"
OUT_OF_BOUNDS_READ = "out-of-bounds-read"
EXITED = "exited"
PROTOCOL = "protocol"
LOAD_ERROR = "load-error"
KINDS = (CRASH, TIMEOUT, EXCEPTION, FORBIDDEN_SYSCALL, OUT_OF_BOUNDS_READ, EXITED, PROTOCOL, LOAD_ERROR)

_PROCESS_CALLS = {"fork", "vfork", "clone"}
_FILE_CALLS = {"unlink", "unlinkat", "rename", "renameat", "renameat2", "rmdir", "mkdir", "mkdirat",
               "link", "linkat", "symlink", "symlinkat", "chmod", "fchmodat", "chown", "lchown",
               "fchownat", "mknod", "mknodat", "truncate"}
_NETWORK_CALLS = {"socket", "socketpair", "connect", "bind", "listen", "shmget", "msgget", "semget", "mq_open"}
_SIGNAL_CALLS = {"kill", "tkill", "tgkill", "rt_sigqueueinfo", "rt_tgsigqueueinfo", "pidfd_open",
                 "pidfd_send_signal", "pidfd_getfd"}
_SYSTEM_CALLS = {"settimeofday", "clock_settime", "clock_adjtime", "adjtimex", "syslog", "acct", "swapon", "swapoff",
                 "sethostname", "setdomainname", "quotactl", "vhangup", "personality", "sync", "syncfs", "iopl",
                 "ioperm", "reboot", "mount", "umount2", "pivot_root", "chroot", "unshare", "setns"}
_MEMORY_CALLS = {"mprotect", "pkey_mprotect", "munmap", "madvise", "mmap", "mremap", "remap_file_pages", "shmat",
                 "process_madvise", "memfd_create"}


class SubmissionFailure(Exception):
    """Student code made the worker fail. `fatal`: the worker is gone and a
    new one must be started for further work."""

    def __init__(self, kind: str, message: str, *, signal_name: str | None = None,
                 crash: CrashReport | None = None, fatal: bool = True, output: str = "",
                 exit_status: int | None = None, detail: str = "", grader_limit: bool = False):
        super().__init__(message)
        # Stopped by a limit of the grader's that a busy machine can reach
        # too (the wall-clock outer bound, a kill from outside): worth one
        # more try before it is a verdict.
        self.grader_limit = grader_limit
        self.kind, self.message, self.signal_name = kind, message, signal_name
        self.crash, self.fatal, self.output, self.exit_status = crash, fatal, output, exit_status
        self.detail = detail    # e.g. "after" / "before" for out-of-bounds reads, "bad_alloc"


def signal_name(signo: int) -> str:
    try:
        return signal.Signals(signo).name
    except ValueError:
        return f"signal {signo}"


def _buffer_name(where: int) -> str:
    if 0 <= where < 6:
        return f"face {FACE_NAMES[where]}"
    return "the six faces' buffer"


def _bytes(n: int) -> str:
    return "1 byte" if n == 1 else f"{n} bytes"


def _forbidden_message(text: str) -> str:
    name, _, argument = text.partition(" ")
    if name in _PROCESS_CALLS:
        return f"tried to start a new process ({name}: fork, system, popen and exec all start one)"
    if name in ("execve", "execveat"):
        return f"tried to run a program ({name} {argument})".rstrip()
    if name in ("open", "openat", "creat"):
        return f"tried to open '{argument}' for writing"
    if name in _FILE_CALLS:
        return f"tried to change the file system ({name} '{argument}')" if argument else \
            f"tried to change the file system ({name})"
    if name in _NETWORK_CALLS:
        what = "the network" if name in ("socket", "socketpair", "connect", "bind", "listen") else \
            "shared memory or message queues"
        return f"tried to use {what} ({name})"
    if name in _SIGNAL_CALLS:
        return f"tried to send a signal to another process ({name})"
    if name in ("fcntl", "ioctl"):
        # The commands that choose which process gets a descriptor's signal.
        return f"tried to have the kernel send signals to a process of its choosing ({name} {argument})"
    if name in _SYSTEM_CALLS:
        return f"tried to change the machine's settings ({name})"
    if name in _MEMORY_CALLS:
        return (f"tried to change memory the grader owns ({name}): the texture's guard pages and the "
                "grader's code keep their mappings, and no memory may become executable")
    return f"made a system call that submissions may not make ({name})"


def from_crash(report: CrashReport, output: str, limits_cpu_s: int | None = None) -> SubmissionFailure:
    """A SubmissionFailure for a crash report sent by the worker's handlers."""
    sig = signal_name(report.signo)
    if report.cause == protocol.CAUSE_FORBIDDEN_SYSCALL:
        return SubmissionFailure(FORBIDDEN_SYSCALL, _forbidden_message(report.text), signal_name=sig,
                                 crash=report, output=output, detail=report.text.partition(" ")[0])
    if report.cause == protocol.CAUSE_GUARD_AFTER:
        at = "right after" if report.distance == 0 else f"{_bytes(report.distance)} after"
        return SubmissionFailure(OUT_OF_BOUNDS_READ,
                                 f"out-of-bounds read ({sig}): {at} the last texel of {_buffer_name(report.where)}",
                                 signal_name=sig, crash=report, output=output, detail="after")
    if report.cause == protocol.CAUSE_GUARD_BEFORE:
        return SubmissionFailure(OUT_OF_BOUNDS_READ,
                                 f"out-of-bounds read ({sig}): {_bytes(report.distance)} before the first "
                                 f"texel of {_buffer_name(report.where)}",
                                 signal_name=sig, crash=report, output=output, detail="before")
    if report.cause == protocol.CAUSE_TEXTURE_WRITE:
        return SubmissionFailure(CRASH, f"wrote into {_buffer_name(report.where)}, which is read-only ({sig})",
                                 signal_name=sig, crash=report, output=output, detail="texture-write")
    if report.cause == protocol.CAUSE_STACK_OVERFLOW:
        return SubmissionFailure(CRASH, f"stack overflow ({sig})", signal_name=sig, crash=report,
                                 output=output, detail="stack-overflow")
    if report.cause == protocol.CAUSE_CPU_LIMIT:
        limit = f" of {limits_cpu_s} s" if limits_cpu_s else ""
        return SubmissionFailure(TIMEOUT, f"used up its CPU-time limit{limit} ({sig})", signal_name=sig,
                                 crash=report, output=output, detail="cpu")
    # A plain signal.
    if report.signo == signal.SIGABRT and "terminate called" in output:
        return SubmissionFailure(EXCEPTION, "an uncaught C++ exception ended the program (SIGABRT)",
                                 signal_name=sig, crash=report, output=output, detail="terminate")
    if report.signo == signal.SIGSEGV:
        if report.address < 65536:
            return SubmissionFailure(CRASH, f"segmentation fault ({sig}): a read or write through a null pointer",
                                     signal_name=sig, crash=report, output=output, detail="null")
        return SubmissionFailure(CRASH, f"segmentation fault ({sig}): an invalid memory access",
                                 signal_name=sig, crash=report, output=output, detail="invalid")
    if report.signo == signal.SIGFPE:
        what = "integer division by zero" if report.si_code == 1 else "an arithmetic error"  # FPE_INTDIV
        return SubmissionFailure(CRASH, f"{what} ({sig})", signal_name=sig, crash=report, output=output,
                                 detail="intdiv" if report.si_code == 1 else "arith")
    what = {signal.SIGABRT: "abort() was called", signal.SIGILL: "an illegal instruction",
            signal.SIGBUS: "a bus error (invalid memory access)"}.get(report.signo, "the worker was stopped")
    return SubmissionFailure(CRASH, f"{what} ({sig})", signal_name=sig, crash=report, output=output)


def hint(failure: SubmissionFailure, function: str, *, timeout_s: float | None = None,
         memory_mb: int | None = None) -> str:
    """What usually causes this failure, in plain words."""
    kind, detail = failure.kind, failure.detail
    if kind == OUT_OF_BOUNDS_READ:
        if function == "readTexture":
            if detail == "after":
                return ("reading x = W or y = H: clamp the lattice coordinates to W-1 and H-1, "
                        "as the handout's sample code does")
            return "reading x = -1 or y = -1: clamp the lattice coordinates to 0 as well as to W-1 and H-1"
        return ("fetchColor read outside the six faces: check the face index (0..5), that u and v stay in "
                "[0, 1], and that readTexture clamps its lattice coordinates")
    if kind == CRASH:
        return {
            "stack-overflow": "unbounded recursion: a function that calls itself without ever reaching a base case",
            "null": "a null or uninitialised pointer was used: check every pointer before reading through it",
            "invalid": "an index far outside an array, or a pointer to memory that is gone",
            "intdiv": ("integer division by zero: check divisors that can be 0 (a component, a size); "
                       "compute u and v in floating point"),
            "arith": "an arithmetic error in integer code",
            "texture-write": "the texture is read-only: fetchColor and readTexture must not change texels",
        }.get(detail, {
            "SIGABRT": "abort() or a failed assert() stopped the program; so does the C library on a double free",
            "SIGILL": ("an illegal instruction: often a function that does not return a value on every path, "
                       "which the compiler may turn into a trap"),
            "SIGBUS": "a misaligned or invalid memory access",
        }.get(failure.signal_name or "", "the program stopped on a signal"))
    if kind == TIMEOUT:
        within = f" within {timeout_s:g} s" if timeout_s else ""
        return (f"did not finish{within}: usually an infinite loop (a loop whose condition never changes) "
                "or far too much work per lookup")
    if kind == EXCEPTION:
        if "bad_alloc" in failure.message or detail == "bad_alloc":
            limit = f" (limit {memory_mb} MiB)" if memory_mb else ""
            return f"ran out of memory{limit}: memory allocated without end, e.g. in a loop or on every call"
        return "an exception was thrown and not caught: return a colour for every input instead of throwing"
    if kind == FORBIDDEN_SYSCALL:
        return ("submissions may only compute colours: remove the call (no new processes, no writing files, "
                "no network, no signals to other processes, no changes to the grader's memory)")
    if kind == EXITED:
        return "exit() (or similar) was called: return a colour instead of ending the program"
    if kind == PROTOCOL:
        return ("the worker's replies were corrupted: the submission wrote to file descriptors it does not own, "
                "or overwrote memory it does not own")
    if kind == LOAD_ERROR:
        return "the built library could not be loaded; this is usually a problem of the build, not of your code"
    return ""
