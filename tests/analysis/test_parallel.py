"""The process pool's workers start with what the fork server built once (analysis/pool_preload.py)."""
from analysis.effects import mechanical
from analysis.parallel import fit_executor


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
