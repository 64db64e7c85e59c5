"""The worker protocol's constants exist twice, in protocol.h and protocol.py
(C and Python cannot share a header): they must agree, name by name."""
from __future__ import annotations

import re

from grader import PROJECT_ROOT
from grader.worker import protocol

WORKER_C = PROJECT_ROOT / "grader" / "worker" / "protocol.h"


def c_constants() -> dict[str, int]:
    """Every `NAME = value` inside an enum, and the magic #defines, of protocol.h."""
    text = WORKER_C.read_text()
    found = {name: int(value, 16) for name, value in
             re.findall(r"^#define (\w+_MAGIC) (0x[0-9a-fA-F]+)u", text, re.M)}
    for body in re.findall(r"enum\s*\{([^}]*)\}", text):
        for name, value in re.findall(r"(\w+)\s*=\s*(-?\d+)", body):
            found[name] = int(value)
    return found


def python_name(c_name: str) -> str | None:
    """The protocol.py name of a protocol.h constant (None: not part of the protocol)."""
    for prefix in ("OP_", "ST_"):
        if c_name.startswith(prefix):
            return c_name[len(prefix):]
    if c_name.startswith(("CAUSE_", "EXIT_", "WHERE_")) or c_name.endswith("_MAGIC"):
        return c_name
    return None


def test_every_protocol_constant_of_worker_c_has_the_same_value_in_protocol_py():
    constants = c_constants()
    compared = 0
    for c_name, value in constants.items():
        name = python_name(c_name)
        if name is None:
            continue
        assert hasattr(protocol, name), f"protocol.h's {c_name} has no {name} in protocol.py"
        assert getattr(protocol, name) == value, f"{c_name} = {value} in protocol.h, {getattr(protocol, name)} in protocol.py"
        compared += 1
    # The parse itself must have found the protocol (a rename would otherwise pass silently).
    assert {"REQUEST_MAGIC", "RESPONSE_MAGIC", "OP_FETCH", "ST_CRASH", "CAUSE_GUARD_AFTER", "EXIT_CRASH"} <= set(constants)
    assert compared >= 25


def test_placements_agree():
    constants = c_constants()
    assert protocol.PLACEMENTS == {"end": constants["PLACE_END"], "start": constants["PLACE_START"]}


def test_crash_report_size_matches_the_c_struct():
    text = WORKER_C.read_text()
    assert protocol.CRASH_REPORT.size == 256
    assert re.search(r"char\s+text\[224\]", text), "protocol.h's crash report text field changed size"
