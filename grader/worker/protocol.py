"""The byte protocol between the grader and the worker (protocol.h; README.md, "Protocol").

Every message is a 24-byte header (magic u32, op or status u32, count u64,
payload_bytes u64; native byte order: both ends run on the same machine)
followed by payload_bytes of payload. Constants here mirror protocol.h.
Everything the worker sends is untrusted (student code runs in that process):
`check_reply` validates sizes before anything is decoded, and any surprise is
a ProtocolViolation, charged to the submission.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

# submission_abi.h's SUB_ABI_VERSION: READY's count.
ABI_VERSION = 2
REQUEST_MAGIC = 0x4B574D45   # "EMWK"
RESPONSE_MAGIC = 0x524B4D45  # "EMKR"
HEADER = struct.Struct("=IIQQ")

# Requests (op).
SET_FACES, FETCH, READ_TEXTURE, TIME_FETCH, LOAD_CROSS, QUIT = 1, 2, 3, 4, 5, 6
# FETCH and READ_TEXTURE evaluate one input per submission call, noting its
# index in the progress page; FETCH_WHOLE hands the batch over in blocks of
# 4096 per call (timed passes: nothing per input added; a block in which an
# input faults is evaluated again one input per call).
FETCH_WHOLE = 7
# fetchColor with readTexture's calls recorded (submission_abi.h,
# sub_record_fetch_batch): the payload is a u64 (1: answer with the tags, 0:
# with the student's readTexture), RECORDED_CALLS tag colours, then the
# directions; each reply row is rgb, the number of calls, the call whose
# answer was returned (-1: none), then the first RECORDED_CALLS calls as
# (face, offset, u, v).
RECORD_FETCH = 8
RECORDED_CALLS = 4
RECORD_ROW = 5 + 4 * RECORDED_CALLS
# Replies (status).
OK, EXCEPTION, ARGUMENT, CRASH, LOAD_ERROR, READY, BAD_REQUEST = 0, 1, 2, 3, 4, 5, 6
# Sent before the submission is loaded: the only replies the grader trusts.
SANDBOXED, SETUP_ERROR = 7, 8
# Before FETCH's or READ_TEXTURE's own reply: the inputs that faulted, each
# with its crash report; the worker went on with the next input.
FAULTS = 9
# Bits of SANDBOXED's count: what held besides limits and the filter.
SANDBOXED_PID_NAMESPACE = 1
STATUS_NAMES = {OK: "ok", EXCEPTION: "exception", ARGUMENT: "argument", CRASH: "crash",
                LOAD_ERROR: "load-error", READY: "ready", BAD_REQUEST: "bad-request",
                SANDBOXED: "sandboxed", SETUP_ERROR: "setup-error", FAULTS: "faults"}
# Text replies (exception and error messages) longer than this are refused.
MAX_TEXT_BYTES = 64 << 10

# Crash report causes (crash_report.cause in protocol.h).
CAUSE_SIGNAL, CAUSE_GUARD_AFTER, CAUSE_GUARD_BEFORE, CAUSE_STACK_OVERFLOW = 0, 1, 2, 3
CAUSE_CPU_LIMIT, CAUSE_FORBIDDEN_SYSCALL, CAUSE_TEXTURE_WRITE = 4, 5, 6
WHERE_ALL_FACES = -1
CRASH_REPORT = struct.Struct("=iiiiqQ224s")   # 256 bytes
FAULT = struct.Struct("=Q256s")                # one FAULTS entry: the input's index, its crash report

# Texture placements: the texels end where a guard page starts, or start
# where one ends.
PLACEMENTS = {"end": 0, "start": 1}
# Worker exit codes (protocol.h): a crash already reported, a load failure, a
# broken protocol.
EXIT_CRASH, EXIT_LOAD, EXIT_PROTOCOL, EXIT_SETUP = 70, 71, 72, 73


class ProtocolViolation(Exception):
    """The worker sent something the protocol does not allow."""


@dataclass(frozen=True)
class CrashReport:
    signo: int
    si_code: int
    cause: int
    where: int          # a face (0..5), WHERE_ALL_FACES, or the syscall number
    distance: int       # bytes past the end / before the start of the buffer
    address: int
    text: str           # forbidden syscall: its name and path argument


def request(op: int, count: int, payload: bytes | memoryview = b"") -> list:
    """The header and payload of a request, as buffers for writing."""
    return [HEADER.pack(REQUEST_MAGIC, op, count, len(payload)), payload]


def set_faces_payload(faces: np.ndarray) -> bytearray:
    """SET_FACES's payload, the texels copied once (a 256 x 256 map is 4.7 MB)."""
    six, h, w, three = faces.shape
    payload = bytearray(16 + 4 * faces.size)
    struct.pack_into("=iiii", payload, 0, w, h, 0, 0)
    np.frombuffer(payload, np.float32, offset=16).reshape(faces.shape)[...] = faces
    return payload


def decode_header(data: bytes) -> tuple[int, int, int]:
    """(status, count, payload_bytes) of a reply header."""
    magic, status, count, size = HEADER.unpack(data)
    if magic != RESPONSE_MAGIC:
        raise ProtocolViolation(f"reply header has magic {magic:#010x}, expected {RESPONSE_MAGIC:#010x}")
    if status not in STATUS_NAMES:
        raise ProtocolViolation(f"reply status {status} is not one the protocol defines")
    return status, count, size


def check_reply_size(status: int, count: int, size: int, expected_count: int | None,
                     expected_bytes: int | None) -> None:
    """Refuse a reply whose size does not follow from the request, before
    reading its payload (so a lying header cannot make us allocate)."""
    if status == CRASH:
        if size != CRASH_REPORT.size:
            raise ProtocolViolation(f"crash report of {size} bytes, expected {CRASH_REPORT.size}")
    elif status in (EXCEPTION, ARGUMENT, LOAD_ERROR, BAD_REQUEST, SETUP_ERROR):
        if size > MAX_TEXT_BYTES:
            raise ProtocolViolation(f"{STATUS_NAMES[status]} message of {size} bytes")
    elif status == FAULTS:
        if not 0 < count <= (expected_count if expected_count is not None else 0) or size != count * FAULT.size:
            raise ProtocolViolation(f"faults reply for {count} inputs in {size} bytes")
    elif status in (READY, SANDBOXED):
        if size != 0:
            raise ProtocolViolation(f"ready reply with a {size}-byte payload")
    elif status == OK:
        if expected_count is not None and count != expected_count:
            raise ProtocolViolation(f"reply for {count} items, expected {expected_count}")
        if expected_bytes is not None and size != expected_bytes:
            raise ProtocolViolation(f"reply payload of {size} bytes, expected {expected_bytes}")
        if expected_bytes is None and size > MAX_TEXT_BYTES:
            raise ProtocolViolation(f"reply payload of {size} bytes")


def decode_text(payload: bytes) -> str:
    return payload.decode("utf-8", "replace").rstrip("\0")


def decode_crash(payload: bytes) -> CrashReport:
    signo, code, cause, where, distance, address, text = CRASH_REPORT.unpack(payload)
    if cause not in range(7) or not 0 < signo < 128:
        raise ProtocolViolation(f"crash report with cause {cause}, signal {signo}")
    return CrashReport(signo, code, cause, where, distance, address,
                       text.split(b"\0", 1)[0].decode("utf-8", "replace"))


def decode_faults(payload: bytes, count: int, rows: int) -> list[tuple[int, CrashReport]]:
    """(index, crash report) of each input that faulted, indices increasing
    and below `rows` (what the worker was asked to evaluate)."""
    out, last = [], -1
    for k in range(count):
        index, report = FAULT.unpack_from(payload, k * FAULT.size)
        if not last < index < rows:
            raise ProtocolViolation(f"fault at input {index} of {rows} (after {last})")
        out.append((index, decode_crash(report)))
        last = index
    return out


def record_payload(tags: np.ndarray | None, dirs: np.ndarray) -> bytes:
    """RECORD_FETCH's payload; tags None: answer with the student's readTexture."""
    sent = np.zeros((RECORDED_CALLS, 3)) if tags is None else np.ascontiguousarray(tags, np.float64)
    if sent.shape != (RECORDED_CALLS, 3):
        raise ValueError(f"tags must have shape ({RECORDED_CALLS}, 3), not {sent.shape}")
    return struct.pack("=Q", tags is not None) + sent.tobytes() + np.ascontiguousarray(dirs, np.float64).tobytes()


def decode_doubles(payload: bytes, rows: int, width: int = 3) -> np.ndarray:
    """(rows, 3) float64. NaN and infinities are the student's answers, not
    protocol errors: the checks judge them."""
    values = np.frombuffer(payload, dtype=np.float64).reshape(rows, width)
    # A reply read into its own buffer (process.Worker._read_exact) is used as it is.
    return values if values.flags.writeable else values.copy()
