"""A bounded hand-over of LaserBlocks from a reader thread to a consumer.

When the consumer falls behind, the oldest block goes and is counted: the
newest data matter most to a live display, and the counter in every block
shows the gap to whoever aligns the stream. When the link dies, the reader
records why; the consumer first gets every block already received, then the
error - nothing received is lost.
"""

from __future__ import annotations

import threading
import time
from collections import deque

from instruments.laser.sensor import LaserBlock, LaserError


class BlockQueue:
    def __init__(self, max_blocks: int) -> None:
        if max_blocks < 1:
            raise ValueError("the block queue needs room for at least one block")
        self._blocks: deque[LaserBlock] = deque()
        self._max = max_blocks
        self._ready = threading.Condition()
        self._overflows = 0
        self._failure: str | None = None  # NB: written by the reader, read by the consumer

    @property
    def overflows(self) -> int:
        return self._overflows

    @property
    def failure(self) -> str | None:
        return self._failure

    def put(self, block: LaserBlock) -> None:
        """Never blocks: a full queue loses its oldest block."""
        with self._ready:
            if len(self._blocks) >= self._max:
                self._blocks.popleft()
                self._overflows += 1
            self._blocks.append(block)
            self._ready.notify_all()

    def fail(self, reason: str) -> None:
        """No more blocks will come, because of ``reason``."""
        with self._ready:
            self._failure = reason
            self._ready.notify_all()

    def clear(self) -> None:
        with self._ready:
            self._blocks.clear()

    def get(self, timeout: float) -> LaserBlock | None:
        deadline = time.monotonic() + max(0.0, timeout)
        with self._ready:
            while not self._blocks:
                if self._failure is not None:
                    raise LaserError(f"laser link lost: {self._failure}")
                left = deadline - time.monotonic()
                if left <= 0:
                    return None
                self._ready.wait(left)
            return self._blocks.popleft()
