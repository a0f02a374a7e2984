"""Effects' responses remembered between evaluations of one model at one set of lines.

A least-squares fit evaluates its model thousands of times, and most evaluations move one parameter: the
Jacobian's forward differences step each varying parameter in turn. An effect whose own inputs did not
move gives the same response as in the evaluation before, so it is not worked out again. A start
value's screen (analysis.diagnosis.candidates) varies one effect's parameters alone, and a site's
correction holds every catalogue effect at a site: there every other effect is remembered throughout.

What an effect depends on is not declared; it is seen. The first evaluation reads the parameters through a
mapping that notes every name read (the effect's own, and e.g. CMES and LCES for fs, Bl for a term in
kg/s). A later evaluation whose values of exactly those names are equal reruns the same arithmetic on the
same numbers, so the remembered response is the one it would compute, to the bit: an effect's response
is a function of the lines and the parameters it reads (every effect's contract: Effect.response).
Parameters that are not plain numbers (arrays) are never remembered.

One model and one set of lines per thread: a fit evaluates one model on one set of lines from its start to
its end, and a pool's worker runs one fit at a time.
"""
from __future__ import annotations

import threading
from collections.abc import Mapping
from operator import itemgetter
from typing import Callable

import numpy as np

_PLAIN_NUMBERS = (float, int, np.float64)
_local = threading.local()


class _ReadNames(Mapping):
    """The parameters as an effect sees them, noting each name it reads."""

    __slots__ = ("values", "read")

    def __init__(self, values: Mapping[str, float]):
        self.values = values
        self.read: dict[str, object] = {}

    def __getitem__(self, name: str):
        value = self.values[name]
        self.read[name] = value
        return value

    def __iter__(self):
        return iter(self.values)

    def __len__(self) -> int:
        return len(self.values)


class _Remembered:
    """What an effect read (a getter of those names, their values) and what it gave."""

    __slots__ = ("getter", "values", "response")

    def __init__(self, read: dict[str, object], response):
        names = tuple(read)
        self.getter: Callable | None = itemgetter(*names) if names else None
        self.values = self.getter(read) if names else None
        self.response = response

    def still(self, p: Mapping[str, float]) -> bool:
        return self.getter is None or self.getter(p) == self.values


class ResponseMemo:
    """The responses of one model's effects at one set of lines `s` (use `for_model`)."""

    __slots__ = ("model", "s", "s_bytes", "remembered")

    def __init__(self, model: object, s: np.ndarray):
        self.model, self.s, self.s_bytes = model, s, _lines_key(s)
        self.remembered: dict[int, _Remembered] = {}

    def holds(self, model: object, s: np.ndarray) -> bool:
        return model is self.model and (s is self.s or _lines_key(s) == self.s_bytes)

    def response(self, effect, s: np.ndarray, p: Mapping[str, float]):
        """effect.response(s, p), or the one given last time the values it reads were the same."""
        key = id(effect)
        kept = self.remembered.get(key)
        if kept is not None and kept.still(p):
            return kept.response
        reading = _ReadNames(p)
        response = effect.response(s, reading)
        if all(type(v) in _PLAIN_NUMBERS for v in reading.read.values()):
            if isinstance(response, np.ndarray):
                response.flags.writeable = False      # shared by later evaluations: no one may change it
            self.remembered[key] = _Remembered(reading.read, response)
        else:
            self.remembered.pop(key, None)
        return response


def _lines_key(s) -> bytes:
    s = np.asarray(s)
    return s.dtype.str.encode() + str(s.shape).encode() + s.tobytes()


def for_model(model: object, s: np.ndarray) -> ResponseMemo:
    """This thread's memo for `model` at `s` (a fresh one when the thread last evaluated another model or
    other lines)."""
    memo = getattr(_local, "memo", None)
    if memo is None or not memo.holds(model, s):
        memo = ResponseMemo(model, s)
        _local.memo = memo
    return memo
