"""An exception raised on a worker process reaches its caller, whatever it was.

A process pool sends a call's exception back pickled, and pickle rebuilds an exception as its class called
with its args. An effect of a package runs its own code on the workers and may raise anything: a class whose
__init__ wants arguments it did not pass on to Exception.__init__ could not be rebuilt in the caller, and
concurrent.futures then took the whole pool for broken (BrokenProcessPool: every call on it failed, its
workers were killed); one holding what pickle cannot send (a lock) came back as that pickling error, the
original lost. So the worker tries both itself, and what would not make it goes back as a WorkerError: one
line with the original's type and message, and the effect that raised it when an effect did. The traceback is
not lost: the WorkerError is raised from the original, and concurrent.futures sends the traceback of both as
text (the caller's exception's __cause__), which the log and the crash report print.
"""
from __future__ import annotations

import copy
from multiprocessing.reduction import ForkingPickler
from types import TracebackType
from typing import Callable

from analysis.errors import one_line


class WorkerError(Exception):
    """What a worker raised, as one line, when that exception could not have been sent as it was."""


class WorkerValueError(WorkerError, ValueError):
    pass


class WorkerArithmeticError(WorkerError, ArithmeticError):
    pass


# The kinds a caller tells apart, kept by the exception that stands in for one: the diagnosis records a
# candidate whose fit raised one of them as failed and goes on (analysis.diagnosis.jobs.outcome), as it does
# when it fits in its own thread and the original is raised there.
_STAND_INS = ((ValueError, WorkerValueError), (ArithmeticError, WorkerArithmeticError))


def call_sending_errors(fn: Callable, *args, **kwargs):
    """fn(*args, **kwargs) on a worker; what it raises is raised again as a WorkerError when pickle could not
    bring it back to the caller (module doc)."""
    try:
        return fn(*args, **kwargs)
    except Exception as exc:
        if _travels(exc):
            raise
        stand_in = next((s for kind, s in _STAND_INS if isinstance(exc, kind)), WorkerError)
        raise stand_in(_one_line(exc)) from exc


def _travels(exc: Exception) -> bool:
    """Whether the pool can send `exc` and the caller rebuild it. copy.copy rebuilds it as an unpickler does:
    the callable and arguments of its __reduce_ex__, then its state (and no pickle is read: a source file of
    linpar loads none, tests/reliability/test_file_safety.py)."""
    try:
        ForkingPickler.dumps(exc)
        copy.copy(exc)
    except Exception:  # noqa: BLE001 - whatever stops the pickler or the class's __init__
        return False
    return True


def _one_line(exc: Exception) -> str:
    """'the effect creep-log raised NeedsTwo: the spider: torn; correct the effect, or fit without it'."""
    try:
        what = f"{type(exc).__name__}: {one_line(exc)}"
    except Exception:  # noqa: BLE001 - a __str__ of a package's exception that fails in turn
        what = type(exc).__name__
    effect = _raising_effect(exc.__traceback__)
    if effect is None:
        return f"{what} (raised on a worker process)"
    return f"the effect {effect} raised {what}; correct the effect, or fit without it"


def _raising_effect(tb: TracebackType | None) -> str | None:
    """The id of the effect whose method is innermost in the traceback `tb`, if any (a fit calls an effect's
    response through the model, so an effect's own code is named, not the model's that called it)."""
    from analysis.effects.base import Effect    # on a failure only: analysis.parallel needs no numpy to load
    found = None
    while tb is not None:
        owner = tb.tb_frame.f_locals.get("self")
        if isinstance(owner, Effect):
            found = owner.id
        tb = tb.tb_next
    return found
