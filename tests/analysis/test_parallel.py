"""The process pool's workers: what the fork server built once (analysis/pool_preload.py), their priority."""
import os

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
