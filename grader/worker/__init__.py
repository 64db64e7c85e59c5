"""The only place student code runs: an isolated worker process.

    build -> [worker] -> checks

- worker.c (built into build/worker by native.py) sets resource limits,
  installs crash handlers and a seccomp filter, then dlopen()s the
  submission and serves lookups over a private pipe pair (protocol.py).
- sandbox.py wraps it in bubblewrap when the machine allows, else says why.
- process.Worker is one such process seen from Python; runner.SubmissionRunner
  runs whole batches and attributes each failure to the input that causes it.

README.md beside this file describes the design and the protocol.
"""
from .failures import KINDS, SubmissionFailure
from .process import Limits, Worker, WorkerHarnessError
from .runner import Failure, Outcome, SubmissionRunner, describe_fetch, describe_read_texture
from .sandbox import fallback_warning, sandbox_problem

__all__ = ["KINDS", "Failure", "Limits", "Outcome", "SubmissionFailure", "SubmissionRunner", "Worker",
           "WorkerHarnessError", "describe_fetch", "describe_read_texture", "fallback_warning",
           "sandbox_problem"]
