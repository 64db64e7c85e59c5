"""How a worker failed, in words a student can act on.

A SubmissionFailure is what the Worker raises (what happened, without the
input); the runner turns it into a Failure (which input, and a hint). The
messages contain nothing that changes between runs (no addresses, no pids),
so grading the same submission twice gives the same report.
"""
from __future__ import annotations

import signal

from ..i18n import N_, _
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
        return _("face %(face)s") % {"face": FACE_NAMES[where]}
    return _("the six faces' buffer")


def _bytes(n: int) -> str:
    return _("1 byte") if n == 1 else _("%(count)d bytes") % {"count": n}


def _forbidden_message(text: str) -> str:
    name, _sep, argument = text.partition(" ")
    words = {"name": name, "argument": argument}
    if name in _PROCESS_CALLS:
        return _("tried to start a new process (%(name)s: fork, system, popen and exec all start one)") % words
    if name in ("execve", "execveat"):
        return (_("tried to run a program (%(name)s %(argument)s)") % words).replace(" )", ")")
    if name in ("open", "openat", "creat"):
        return _("tried to open '%(argument)s' for writing") % words
    if name in _FILE_CALLS:
        return _("tried to change the file system (%(name)s '%(argument)s')") % words if argument else \
            _("tried to change the file system (%(name)s)") % words
    if name in _NETWORK_CALLS:
        return (_("tried to use the network (%(name)s)") if name in ("socket", "socketpair", "connect", "bind", "listen")
                else _("tried to use shared memory or message queues (%(name)s)")) % words
    if name in _SIGNAL_CALLS:
        return _("tried to send a signal to another process (%(name)s)") % words
    if name in ("fcntl", "ioctl"):
        # The commands that choose which process gets a descriptor's signal.
        return _("tried to have the kernel send signals to a process of its choosing (%(name)s %(argument)s)") % words
    if name in _SYSTEM_CALLS:
        return _("tried to change the machine's settings (%(name)s)") % words
    if name in _MEMORY_CALLS:
        return _("tried to change memory the grader owns (%(name)s): the texture's guard pages and the "
                 "grader's code keep their mappings, and no memory may become executable") % words
    return _("made a system call that submissions may not make (%(name)s)") % words


def from_crash(report: CrashReport, output: str, limits_cpu_s: int | None = None) -> SubmissionFailure:
    """A SubmissionFailure for a crash report sent by the worker's handlers."""
    sig = signal_name(report.signo)
    if report.cause == protocol.CAUSE_FORBIDDEN_SYSCALL:
        return SubmissionFailure(FORBIDDEN_SYSCALL, _forbidden_message(report.text), signal_name=sig,
                                 crash=report, output=output, detail=report.text.partition(" ")[0])
    if report.cause == protocol.CAUSE_GUARD_AFTER:
        words = {"sig": sig, "bytes": _bytes(report.distance), "buffer": _buffer_name(report.where)}
        text = (_("out-of-bounds read (%(sig)s): right after the last texel of %(buffer)s") if report.distance == 0
                else _("out-of-bounds read (%(sig)s): %(bytes)s after the last texel of %(buffer)s"))
        return SubmissionFailure(OUT_OF_BOUNDS_READ, text % words,
                                 signal_name=sig, crash=report, output=output, detail="after")
    if report.cause == protocol.CAUSE_GUARD_BEFORE:
        return SubmissionFailure(OUT_OF_BOUNDS_READ,
                                 _("out-of-bounds read (%(sig)s): %(bytes)s before the first texel of %(buffer)s")
                                 % {"sig": sig, "bytes": _bytes(report.distance), "buffer": _buffer_name(report.where)},
                                 signal_name=sig, crash=report, output=output, detail="before")
    if report.cause == protocol.CAUSE_TEXTURE_WRITE:
        return SubmissionFailure(CRASH, _("wrote into %(buffer)s, which is read-only (%(sig)s)")
                                 % {"buffer": _buffer_name(report.where), "sig": sig},
                                 signal_name=sig, crash=report, output=output, detail="texture-write")
    if report.cause == protocol.CAUSE_STACK_OVERFLOW:
        return SubmissionFailure(CRASH, _("stack overflow (%(sig)s)") % {"sig": sig}, signal_name=sig, crash=report,
                                 output=output, detail="stack-overflow")
    if report.cause == protocol.CAUSE_CPU_LIMIT:
        text = (_("used up its CPU-time limit of %(limit)s s (%(sig)s)") if limits_cpu_s
                else _("used up its CPU-time limit (%(sig)s)")) % {"limit": limits_cpu_s, "sig": sig}
        return SubmissionFailure(TIMEOUT, text, signal_name=sig,
                                 crash=report, output=output, detail="cpu")
    # A plain signal.
    if report.signo == signal.SIGABRT and "terminate called" in output:
        return SubmissionFailure(EXCEPTION, _("an uncaught C++ exception ended the program (SIGABRT)"),
                                 signal_name=sig, crash=report, output=output, detail="terminate")
    if report.signo == signal.SIGSEGV:
        if report.address < 65536:
            return SubmissionFailure(CRASH, _("segmentation fault (%(sig)s): a read or write through a null pointer")
                                     % {"sig": sig},
                                     signal_name=sig, crash=report, output=output, detail="null")
        return SubmissionFailure(CRASH, _("segmentation fault (%(sig)s): an invalid memory access") % {"sig": sig},
                                 signal_name=sig, crash=report, output=output, detail="invalid")
    if report.signo == signal.SIGFPE:
        what = _("integer division by zero") if report.si_code == 1 else _("an arithmetic error")  # FPE_INTDIV
        return SubmissionFailure(CRASH, f"{what} ({sig})", signal_name=sig, crash=report, output=output,
                                 detail="intdiv" if report.si_code == 1 else "arith")
    what = _({signal.SIGABRT: N_("abort() was called"), signal.SIGILL: N_("an illegal instruction"),
              signal.SIGBUS: N_("a bus error (invalid memory access)")}.get(report.signo, N_("the worker was stopped")))
    return SubmissionFailure(CRASH, f"{what} ({sig})", signal_name=sig, crash=report, output=output)


def hint(failure: SubmissionFailure, function: str, *, timeout_s: float | None = None,
         memory_mb: int | None = None) -> str:
    """What usually causes this failure, in plain words (the current language, grader.i18n)."""
    words = _hint_id(failure, function, timed=bool(timeout_s), limited=bool(memory_mb))
    return _(words) % {"within": f"{timeout_s:g}" if timeout_s else "", "limit": memory_mb} if words else ""


def _hint_id(failure: SubmissionFailure, function: str, timed: bool, limited: bool) -> str:
    """hint()'s words as a catalogue id (%(within)s: the time limit in s, %(limit)s: the memory limit in MiB)."""
    kind, detail = failure.kind, failure.detail
    if kind == OUT_OF_BOUNDS_READ:
        if function == "readTexture":
            if detail == "after":
                return N_("reading x = W or y = H: clamp the lattice coordinates to W-1 and H-1, "
                          "as the handout's sample code does")
            return N_("reading x = -1 or y = -1: clamp the lattice coordinates to 0 as well as to W-1 and H-1")
        return N_("fetchColor read outside the six faces: check the face index (0..5), that u and v stay in "
                  "[0, 1], and that readTexture clamps its lattice coordinates")
    if kind == CRASH:
        return {
            "stack-overflow": N_("unbounded recursion: a function that calls itself without ever reaching a base case"),
            "null": N_("a null or uninitialised pointer was used: check every pointer before reading through it"),
            "invalid": N_("an index far outside an array, or a pointer to memory that is gone"),
            "intdiv": N_("integer division by zero: check divisors that can be 0 (a component, a size); "
                         "compute u and v in floating point"),
            "arith": N_("an arithmetic error in integer code"),
            "texture-write": N_("the texture is read-only: fetchColor and readTexture must not change texels"),
        }.get(detail, {
            "SIGABRT": N_("abort() or a failed assert() stopped the program; so does the C library on a double free"),
            "SIGILL": N_("an illegal instruction: often a function that does not return a value on every path, "
                         "which the compiler may turn into a trap"),
            "SIGBUS": N_("a misaligned or invalid memory access"),
        }.get(failure.signal_name or "", N_("the program stopped on a signal")))
    if kind == TIMEOUT:
        if timed:
            return N_("did not finish within %(within)s s: usually an infinite loop (a loop whose condition never "
                      "changes) or far too much work per lookup")
        return N_("did not finish: usually an infinite loop (a loop whose condition never changes) "
                  "or far too much work per lookup")
    if kind == EXCEPTION:
        if "bad_alloc" in failure.message or detail == "bad_alloc":
            if limited:
                return N_("ran out of memory (limit %(limit)s MiB): memory allocated without end, e.g. in a loop "
                          "or on every call")
            return N_("ran out of memory: memory allocated without end, e.g. in a loop or on every call")
        return N_("an exception was thrown and not caught: return a colour for every input instead of throwing")
    if kind == FORBIDDEN_SYSCALL:
        return N_("submissions may only compute colours: remove the call (no new processes, no writing files, "
                  "no network, no signals to other processes, no changes to the grader's memory)")
    if kind == EXITED:
        return N_("exit() (or similar) was called: return a colour instead of ending the program")
    if kind == PROTOCOL:
        return N_("the worker's replies were corrupted: the submission wrote to file descriptors it does not own, "
                  "or overwrote memory it does not own")
    if kind == LOAD_ERROR:
        return N_("the built library could not be loaded; this is usually a problem of the build, not of your code")
    return ""
