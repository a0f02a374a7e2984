"""A job's cancellable pool: its futures say when they are done, so the diagnosis takes those first."""
import threading
from concurrent.futures import Future

from app.jobs.background_pool import CancellableExecutor


class _Pool:
    def __init__(self):
        self.futures: list[Future] = []

    def submit(self, fn, *args, **kwargs):
        self.futures.append(Future())
        return self.futures[-1]


def test_a_cancellable_pools_future_is_done_when_its_result_is_back():
    pool = _Pool()
    future = CancellableExecutor(pool, threading.Event()).submit(print, "x")
    assert not future.done()
    pool.futures[0].set_result(42)
    assert future.done() and future.result() == 42
