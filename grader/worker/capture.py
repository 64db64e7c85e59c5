"""What student code prints (fds 1 and 2 of the worker), read by a thread and
kept within a cap: the first `head` bytes and the last `tail` bytes, the
middle dropped and counted. Reading never stops, so a submission that prints
megabytes cannot block on a full pipe."""
from __future__ import annotations

import os
import threading


class CappedOutput:
    def __init__(self, fd: int, head: int = 8192, tail: int = 8192):
        self._fd = fd
        self._head_cap, self._tail_cap = head, tail
        self._head = bytearray()
        self._tail = bytearray()
        self.total = 0
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._drain, name="worker-output", daemon=True)
        self._thread.start()

    def _drain(self) -> None:
        try:
            while True:
                chunk = os.read(self._fd, 65536)
                if not chunk:
                    break
                with self._lock:
                    self.total += len(chunk)
                    room = self._head_cap - len(self._head)
                    if room > 0:
                        self._head += chunk[:room]
                        chunk = chunk[room:]
                    self._tail += chunk
                    if len(self._tail) > self._tail_cap:
                        del self._tail[:len(self._tail) - self._tail_cap]
        finally:
            os.close(self._fd)

    def wait_closed(self, timeout: float) -> None:
        """Wait until every writer has gone (the worker exited) or `timeout`."""
        self._thread.join(timeout)

    def text(self) -> str:
        with self._lock:
            elided = self.total - len(self._head) - len(self._tail)
            head = self._head.decode("utf-8", "replace")
            tail = self._tail.decode("utf-8", "replace")
        if elided > 0:
            return f"{head}\n[... {elided} bytes of output elided ...]\n{tail}"
        return head + tail

    def tail_text(self, limit: int = 2000) -> str:
        """The last `limit` characters (what a failure message quotes)."""
        text = self.text()
        return text if len(text) <= limit else "[...]" + text[-limit:]
