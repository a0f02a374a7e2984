"""The ILD1420 byte stream: 3-byte binary values and ASCII replies on one line.

Each 18-bit value goes out as three bytes, L, M, H, whose top bits say which
byte they are::

    L: 0 0 D5  D4  D3  D2  D1  D0
    M: 0 1 D11 D10 D9  D8  D7  D6
    H: 1 f D17 D16 D15 D14 D13 D12     f = 0 first value of a measurement,
                                       f = 1 further value (counter, time ...)

ASCII replies to commands share the line. ASCII has bit 7 clear, so an ASCII
byte looks exactly like an L byte (0x00-0x3F: digits, space, CR, LF, '-',
'>') or an M byte (0x40-0x7F: letters). What only binary data can contain is
an H byte.

How the parser tells them apart, and why that is unambiguous enough
-------------------------------------------------------------------
A value is accepted only as an L, M, H run with the H last: the two bytes
before every H byte must be an L-class then an M-class byte. Everything else
(bit 7 clear) is text, or garbage when no reply is awaited. On a clean line
this is *exact*, not a guess: the sensor sends the three bytes of a value
together, text only ever sits between values, and text never contains an H
byte, so every H byte on the line is the end of a real value and its own M
and L are right before it. Text is never taken for a value because no text
byte can complete the L, M, H pattern.

Because an L byte (or L, M) at the end of what has arrived may still become a
value, the parser holds up to two trailing bytes until the next byte decides.
The one place that matters is the prompt ``->``: '>' is an L-class byte. On a
busy line the next bytes decide at once; on a quiet line the reader calls
``flush_idle()`` after a read timeout, which closes a reply whose text ends in
``->``.

Garbage (line noise, a partial frame) is counted in ``discarded_bytes`` and
skipped until the next L, M, H run: that is the resynchronisation. Random
bytes can forge a value (about one byte triple in 32 fits the pattern), and
the protocol has no checksum, so no parser can catch every forgery. Two
checks above the byte level keep the damage local: a measurement is only
emitted with exactly its configured number of values, first-flagged value
first, so a forged value mostly turns a measurement into an "incomplete" one
that is dropped and counted; and the counter is unwrapped by nearest steps
(``values.CounterUnwrapper``) so a forged counter cannot shift all later ones.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Iterator

import numpy as np

#: What a measurement can carry, in the order the sensor sends it.
OUTPUT_NAMES = ("distance", "counter", "timestamp")
#: The 18-bit values each output occupies in a measurement.
_SLOTS = {"distance": ("distance",), "counter": ("counter",),
          "timestamp": ("timestamp_lo", "timestamp_hi")}

_L, _M = 0, 1
_PROMPT = b"->"
_FLAG_FURTHER = 0x40
_DATA_BITS = 0x3F


def value_slots(outputs: tuple[str, ...]) -> tuple[str, ...]:
    """The value slots of one measurement in sensor order, e.g.
    ("distance", "counter", "timestamp_lo", "timestamp_hi")."""
    unknown = set(outputs) - set(OUTPUT_NAMES)
    if unknown:
        raise ValueError(f"unknown laser outputs {sorted(unknown)}; known: {OUTPUT_NAMES}")
    if "distance" not in outputs:
        raise ValueError("the distance must be among the laser outputs")
    return tuple(slot for name in OUTPUT_NAMES if name in outputs for slot in _SLOTS[name])


def encode_measurements(words: np.ndarray) -> np.ndarray:
    """Bytes of measurements: ``words`` is (m, n) 18-bit values, one row per
    measurement in slot order; returns (m, 3n) uint8, row by row L, M, H."""
    words = np.atleast_2d(np.asarray(words, dtype=np.int64))
    if words.size and (words.min() < 0 or words.max() >= 1 << 18):
        raise ValueError("laser values must fit in 18 bits")
    m, n = words.shape
    out = np.empty((m, n, 3), dtype=np.uint8)
    out[:, :, 0] = words & _DATA_BITS
    out[:, :, 1] = 0x40 | ((words >> 6) & _DATA_BITS)
    out[:, :, 2] = 0x80 | ((words >> 12) & _DATA_BITS)
    out[:, 1:, 2] |= _FLAG_FURTHER
    return out.reshape(m, 3 * n)


@dataclass(frozen=True, slots=True)
class RawMeasurements:
    """Complete measurements as received: ``words[i, k]`` is slot ``slots[k]``
    of measurement i (18-bit values, not yet decoded)."""

    slots: tuple[str, ...]
    words: np.ndarray

    def __len__(self) -> int:
        return self.words.shape[0]

    def column(self, slot: str) -> np.ndarray | None:
        """One slot's values, or None when that output is not configured."""
        if slot not in self.slots:
            return None
        return self.words[:, self.slots.index(slot)]


_ERROR_LINE = re.compile(r"^E\d{3}\b")
_WARNING_LINE = re.compile(r"^W\d{3}\b")


@dataclass(frozen=True, slots=True)
class Reply:
    """One complete ASCII reply: command echo, lines, the ``->`` prompt."""

    text: str

    @property
    def lines(self) -> tuple[str, ...]:
        """Non-empty lines, the closing prompt left out."""
        text = self.text[:-len(_PROMPT)] if self.text.endswith("->") else self.text
        return tuple(s for s in (line.strip() for line in text.splitlines()) if s)

    @property
    def body(self) -> tuple[str, ...]:
        """The lines after the echo."""
        return self.lines[1:]

    @property
    def errors(self) -> tuple[str, ...]:
        return tuple(line for line in self.lines if _ERROR_LINE.match(line))

    @property
    def warnings(self) -> tuple[str, ...]:
        return tuple(line for line in self.lines if _WARNING_LINE.match(line))

    def from_echo(self, command: str) -> tuple[int, Reply] | None:
        """(characters before the echo, the reply from the echo on), or None
        when this is not the reply to ``command``. What comes before the echo
        is garbage that looked like text."""
        wanted = command.strip().upper()
        offset = 0
        for line in self.text.splitlines(keepends=True):
            bare = line.rstrip("\r\n").rstrip()
            if wanted and bare.upper().endswith(wanted):
                start = offset + len(bare) - len(wanted)
                return start, Reply(self.text[start:])
            offset += len(line)
        return None


@dataclass(frozen=True, slots=True)
class ParserStats:
    values: int = 0
    measurements: int = 0
    discarded_bytes: int = 0
    incomplete_measurements: int = 0
    orphan_values: int = 0
    replies: int = 0


class FrameParser:
    """Streaming parser: feed it chunks split anywhere, it yields
    ``RawMeasurements`` and ``Reply`` objects in stream order.

    ``feed`` is a generator and must be iterated to the end; it is lazy on
    purpose, so that the consumer can act on a reply (e.g. ``set_outputs``
    after an output-selection command) before the values behind it are
    grouped. Not thread-safe except ``expect_reply``, which the command
    thread calls before it writes a command (see ild1420.py).

    Text is only collected while a reply is awaited (``expect_reply``), or
    always with ``always_collect_text``; otherwise ASCII-looking bytes are
    garbage. That keeps noise from piling up into the next reply.
    """

    def __init__(self, outputs: tuple[str, ...] = OUTPUT_NAMES, *,
                 always_collect_text: bool = False, max_text_bytes: int = 16384) -> None:
        self._slots = value_slots(outputs)
        self._always_text = always_collect_text
        self._expecting = False  # NB: set by the command thread, cleared here
        self._max_text = max_text_bytes
        self._held = b""
        self._text = bytearray()
        self._group: list[int] = []
        self._values = self._measurements = self._discarded = 0
        self._incomplete = self._orphans = self._replies = 0

    # -- configuration -------------------------------------------------------
    @property
    def slots(self) -> tuple[str, ...]:
        return self._slots

    def set_outputs(self, outputs: tuple[str, ...]) -> None:
        """Change the measurement layout; a half-received measurement is
        dropped (it belongs to the old layout)."""
        self._slots = value_slots(outputs)
        self._drop_group()

    def reset_grouping(self) -> None:
        self._drop_group()

    def expect_reply(self) -> None:
        """Collect text from now until the next ``->``."""
        self._expecting = True

    @property
    def expecting_reply(self) -> bool:
        return self._expecting

    @property
    def stats(self) -> ParserStats:
        return ParserStats(self._values, self._measurements, self._discarded,
                           self._incomplete, self._orphans, self._replies)

    @property
    def held_bytes(self) -> int:
        """Trailing bytes kept back until the next byte says what they are."""
        return len(self._held)

    # -- parsing -------------------------------------------------------------
    def feed(self, chunk: bytes) -> Iterator[RawMeasurements | Reply]:
        buf = self._held + bytes(chunk)
        self._held = b""
        if not buf:
            return
        a = np.frombuffer(buf, dtype=np.uint8)
        kind = a >> 6  # 0 = L, 1 = M, 2 or 3 = H
        if len(a) >= 3:
            ends = np.flatnonzero((kind[2:] >= 2) & (kind[1:-1] == _M) & (kind[:-2] == _L)) + 2
        else:
            ends = np.empty(0, dtype=np.intp)
        hold = 0
        if kind[-1] == _L:
            hold = 1
        elif kind[-1] == _M and len(a) >= 2 and kind[-2] == _L:
            hold = 2
        limit = len(a) - hold

        starts = ends - 2
        previous_end = np.concatenate(([-1], ends[:-1]))
        has_gap = starts > previous_end + 1
        pos, i = 0, 0
        while i < len(ends):
            if has_gap[i]:
                yield from self._loose(buf[pos:starts[i]])
            j = i + 1
            while j < len(ends) and not has_gap[j]:
                j += 1
            yield from self._group_values(a, ends[i:j])
            pos = int(ends[j - 1]) + 1
            i = j
        if pos < limit:
            yield from self._loose(buf[pos:limit])
        self._held = buf[limit:]

    def flush_idle(self) -> list[Reply]:
        """The line went quiet: close a reply whose prompt is being held back
        (the '>' of ``->`` could have been the L byte of a value)."""
        if self._held and self._collecting() and (bytes(self._text) + self._held).endswith(_PROMPT):
            held, self._held = self._held, b""
            return [r for r in self._loose(held) if isinstance(r, Reply)]
        return []

    # -- internals -------------------------------------------------------------
    def _collecting(self) -> bool:
        return self._always_text or self._expecting

    def _loose(self, segment: bytes) -> Iterator[Reply]:
        """Bytes that are not part of a value: text or garbage."""
        for index, byte in enumerate(segment):
            if not self._collecting():
                self._discarded += len(segment) - index
                return
            if byte & 0x80:
                self._discarded += 1
                continue
            self._text.append(byte)
            if byte == 0x3E and self._text.endswith(_PROMPT):
                reply = Reply(self._text.decode("ascii"))
                self._text.clear()
                self._expecting = False
                self._replies += 1
                yield reply
        excess = len(self._text) - self._max_text
        if excess > 0:
            del self._text[:excess]
            self._discarded += excess

    def _group_values(self, a: np.ndarray, ends: np.ndarray) -> Iterator[RawMeasurements]:
        words = ((a[ends - 2] & _DATA_BITS).astype(np.int64)
                 | (a[ends - 1] & _DATA_BITS).astype(np.int64) << 6
                 | (a[ends] & _DATA_BITS).astype(np.int64) << 12)
        first = (a[ends] & _FLAG_FURTHER) == 0
        self._values += len(words)
        n = len(self._slots)
        rows: list[np.ndarray] = []

        k = 0
        while self._group and k < len(words):  # finish a measurement begun earlier
            self._take(int(words[k]), bool(first[k]), rows)
            k += 1
        whole = (len(words) - k) // n * n
        pattern = np.tile(np.arange(n) == 0, whole // n)
        if whole and np.array_equal(first[k:k + whole], pattern):
            rows.append(words[k:k + whole].reshape(-1, n))  # the usual case: clean rows
            k += whole
        for w, f in zip(words[k:].tolist(), first[k:].tolist()):
            self._take(w, f, rows)

        if rows:
            block = np.concatenate([np.atleast_2d(r) for r in rows], axis=0)
            self._measurements += len(block)
            yield RawMeasurements(self._slots, block)

    def _take(self, word: int, first: bool, rows: list[np.ndarray]) -> None:
        if first:
            self._drop_group()
            self._group = [word]
        elif self._group:
            self._group.append(word)
        else:
            self._orphans += 1  # a further value whose first value was lost
            return
        if len(self._group) == len(self._slots):
            rows.append(np.array([self._group], dtype=np.int64))
            self._group = []

    def _drop_group(self) -> None:
        if self._group:
            self._incomplete += 1
        self._group = []
