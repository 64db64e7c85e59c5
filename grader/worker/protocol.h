/*
 * protocol.h - the byte protocol between the grader and the worker (README.md
 * beside this file, "Protocol"), shared by worker.c and faults.c. Keep in step
 * with protocol.py, which tests/test_protocol_constants.py holds to this file.
 */
#ifndef WORKER_PROTOCOL_H
#define WORKER_PROTOCOL_H

#include <stdint.h>

#define REQUEST_MAGIC 0x4b574d45u  /* "EMWK" */
#define RESPONSE_MAGIC 0x524b4d45u /* "EMKR" */

enum { OP_SET_FACES = 1, OP_FETCH = 2, OP_READ_TEXTURE = 3, OP_TIME_FETCH = 4,
       OP_LOAD_CROSS = 5, OP_QUIT = 6, OP_FETCH_WHOLE = 7, OP_RECORD_FETCH = 8 };
enum { ST_OK = 0, ST_EXCEPTION = 1, ST_ARGUMENT = 2, ST_CRASH = 3, ST_LOAD_ERROR = 4,
       ST_READY = 5, ST_BAD_REQUEST = 6, ST_SANDBOXED = 7, ST_SETUP_ERROR = 8, ST_FAULTS = 9 };
enum { CAUSE_SIGNAL = 0, CAUSE_GUARD_AFTER = 1, CAUSE_GUARD_BEFORE = 2,
       CAUSE_STACK_OVERFLOW = 3, CAUSE_CPU_LIMIT = 4, CAUSE_FORBIDDEN_SYSCALL = 5,
       CAUSE_TEXTURE_WRITE = 6 };
enum { PLACE_END = 0, PLACE_START = 1 };
/* Bits of the SANDBOXED message's count: what held besides the filter. */
enum { SANDBOXED_PID_NAMESPACE = 1 };
enum { WHERE_ALL_FACES = -1 };

/* Exit codes, for when the grader sees the status but not the report. */
enum { EXIT_CRASH = 70, EXIT_LOAD = 71, EXIT_PROTOCOL = 72, EXIT_SETUP = 73 };

struct header {
    uint32_t magic, op;
    uint64_t count, payload_bytes;
};

struct crash_report {      /* the ST_CRASH payload, exactly 256 bytes */
    int32_t signo, si_code, cause, where; /* where: face, WHERE_ALL_FACES or syscall nr */
    int64_t distance;      /* bytes past the end / before the start of the buffer */
    uint64_t address;      /* faulting address (si_addr) */
    char text[224];        /* syscall name and argument, NUL padded */
};

/* Write one reply on the response pipe (worker.c); async-signal-safe. */
void reply(uint32_t status, uint64_t count, const void *payload, uint64_t size);
void reply_text(uint32_t status, const char *text);

#endif
