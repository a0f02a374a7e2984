"""The process pool's workers: what the fork server built once (analysis/pool_preload.py), their priority,
and what they raise."""
import os
import sys
from concurrent.futures.process import BrokenProcessPool

import pytest

from analysis.effects import mechanical
from analysis.parallel import BACKGROUND_NICENESS, fit_executor


def _table_entries() -> int:
    return mechanical._x1_excess_table.cache_info().currsize


def test_a_new_worker_has_the_struve_table_already():
    with fit_executor(2) as pool:
        # The table is cached by functools.cache: a worker that built it has one entry before any fit.
        sizes = [pool.submit(_table_entries).result(timeout=300) for _ in range(2)]
    assert sizes == [1, 1]


def test_the_table_built_ahead_is_the_one_a_fit_would_build():
    mechanical._x1_excess_table.cache_clear()
    mechanical.build_tables()
    assert mechanical._x1_excess_table.cache_info().currsize == 1


def _niceness() -> int:
    return os.nice(0)


def test_a_background_pool_runs_below_its_caller_and_a_plain_one_beside_it():
    caller = os.nice(0)
    with fit_executor(2, background=True) as pool:
        background = {pool.submit(_niceness).result(timeout=300) for _ in range(4)}
    with fit_executor(2) as pool:
        plain = {pool.submit(_niceness).result(timeout=300) for _ in range(4)}
    assert background == {min(caller + BACKGROUND_NICENESS, 19)}
    assert plain == {caller}


class NeedsTwo(Exception):
    """An exception pickle cannot rebuild: its args hold the one message, its __init__ wants two arguments."""

    def __init__(self, part: str, why: str):
        super().__init__(f"{part}: {why}")


def _raise_needs_two() -> None:
    raise NeedsTwo("the coil", "too hot")


def test_an_exception_the_caller_cannot_rebuild_arrives_as_one_line_and_the_pool_goes_on():
    """Before: concurrent.futures could not unpickle it, marked the pool broken (BrokenProcessPool) and every
    call still on it failed; the GUI had to start another pool."""
    with fit_executor(2) as pool:
        worker = pool.submit(os.getpid).result(timeout=300)
        with pytest.raises(Exception) as raised:
            pool.submit(_raise_needs_two).result(timeout=300)
        assert not isinstance(raised.value, BrokenProcessPool)
        assert "NeedsTwo: the coil: too hot" in str(raised.value)
        assert pool.submit(_niceness).result(timeout=300) == os.nice(0)       # the pool goes on
        assert pool._processes[worker].is_alive()                             # with the same workers


def _niceness_of_the_preload() -> int | None:
    from analysis import pool_preload
    return pool_preload.niceness


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="a nice value per thread is Linux's")
def test_the_fork_servers_preload_runs_below_its_caller_and_the_workers_it_forks_are_not_niced_twice():
    caller = os.nice(0)
    with fit_executor(2) as pool:
        assert pool.submit(_niceness_of_the_preload).result(timeout=300) == min(caller + BACKGROUND_NICENESS, 19)
        assert pool.submit(_niceness).result(timeout=300) == caller
    with fit_executor(2, background=True) as pool:
        assert pool.submit(_niceness).result(timeout=300) == min(caller + BACKGROUND_NICENESS, 19)
