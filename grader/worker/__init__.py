"""The only place student code runs: an isolated worker process.

    build -> [worker] -> checks

- worker.c (built into build/worker by native.py, with faults.c, seccomp.c
  and privileges.c) sets resource limits, installs crash handlers and a
  seccomp filter, then dlopen()s the
  submission and serves lookups over a private pipe pair (protocol.py).
- sandbox.py picks the isolation: bubblewrap when the machine allows, else
  privilege-drop (root: chroot + nobody), else SandboxUnavailable unless
  unsafe is allowed.
- process.Worker is one such process seen from Python; runner.SubmissionRunner
  runs whole batches and attributes each failure to the input that causes it.

README.md beside this file describes the design and the protocol.
"""
from .failures import KINDS, SubmissionFailure
from .process import Limits, Worker, WorkerHarnessError
from .runner import Failure, Outcome, SubmissionRunner, TimedPasses, describe_fetch, describe_read_texture
from .sandbox import SandboxUnavailable, fallback_warning, privilege_drop_problem, resolve_mode, sandbox_problem

__all__ = ["KINDS", "Failure", "Limits", "Outcome", "SandboxUnavailable", "SubmissionFailure", "SubmissionRunner",
           "TimedPasses", "Worker", "WorkerHarnessError", "describe_fetch", "describe_read_texture",
           "fallback_warning", "privilege_drop_problem", "resolve_mode", "sandbox_problem"]
