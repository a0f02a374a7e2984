"""A worker's exception reaches the caller: as itself when pickle can rebuild it, else as one line of text."""
import threading
import traceback

import pytest

from analysis.diagnosis import jobs
from analysis.parallel import fit_executor
from analysis.worker_errors import WorkerError, call_sending_errors


class NeedsTwo(Exception):
    """pickle cannot rebuild it: its args hold the one message, its __init__ wants two arguments."""

    def __init__(self, part: str, why: str):
        super().__init__(f"{part}: {why}")


class HoldsALock(Exception):
    """pickle cannot send it: an attribute of it is a lock."""

    def __init__(self, message: str):
        super().__init__(message)
        self.lock = threading.Lock()


class RefusedValue(ValueError):
    def __init__(self, value: float, why: str):
        super().__init__(f"{value}: {why}")


def _raise(kind: str) -> None:
    if kind == "needs two":
        raise NeedsTwo("the coil", "too hot")
    if kind == "lock":
        raise HoldsALock("the laser is busy")
    if kind == "value":
        raise RefusedValue(-1.0, "a negative mass")
    raise KeyError(kind)


def test_an_exception_pickle_can_rebuild_is_raised_as_itself():
    with pytest.raises(KeyError, match="fs"):
        call_sending_errors(_raise, "fs")


def test_one_pickle_cannot_send_is_a_worker_error_with_the_originals_type_and_message():
    with pytest.raises(WorkerError) as raised:
        call_sending_errors(_raise, "lock")
    assert str(raised.value) == "HoldsALock: the laser is busy (raised on a worker process)"
    assert isinstance(raised.value.__cause__, HoldsALock)


def test_a_value_error_stays_one_so_that_the_diagnosis_records_a_failed_candidate_and_goes_on():
    def fit():
        return call_sending_errors(_raise, "value")
    result, why = jobs.outcome(fit)
    assert result is None and why == "RefusedValue: -1.0: a negative mass (raised on a worker process)"


def test_through_the_pool_the_callers_error_carries_the_workers_traceback():
    """The log and the crash report print the caller's exception with its __cause__: the worker's traceback."""
    with fit_executor(2) as pool:
        with pytest.raises(WorkerError) as raised:
            pool.submit(_raise, "needs two").result(timeout=300)
    assert str(raised.value) == "NeedsTwo: the coil: too hot (raised on a worker process)"
    printed = "".join(traceback.format_exception(raised.value))
    assert 'raise NeedsTwo("the coil", "too hot")' in printed and "in _raise" in printed
