"""A stand-in for app.jobs.background_pool that notes what is handed to the pool (tests of the jobs using it)."""
from __future__ import annotations

import contextlib


def noting_background_pool(real, handed: list[str]):
    """`real` (a background_pool), each submitted function's name appended to `handed` before it is handed over."""
    class Noting:
        def __init__(self, executor):
            self.executor = executor

        def submit(self, fn, *args):
            handed.append(fn.__name__)
            return self.executor.submit(fn, *args)

    @contextlib.contextmanager
    def pool(cancel):
        with real(cancel) as executor:
            yield Noting(executor)
    return pool
