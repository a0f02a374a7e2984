"""The cycle collector runs in the GUI thread only, so a worker thread never frees a Qt object."""
from __future__ import annotations

import gc
import threading

from PySide6.QtWidgets import QMenu

from app.jobs import gui_gc
from tests.pace import wait_ms


def test_a_qt_cycle_made_in_the_gui_thread_is_not_freed_by_a_worker_thread(qapp, qtbot):
    assert gui_gc.installed() and not gc.isenabled()
    freed_in = []

    class Holder:
        pass

    holder = Holder()
    holder.menu = QMenu()
    holder.menu.destroyed.connect(lambda *_: freed_in.append(threading.current_thread().name))
    holder.me = holder          # a cycle: only the cycle collector frees it
    del holder

    kept = []

    def allocate_a_lot():      # far past every threshold (kept alive): automatic collection would run here
        kept.append([[i] for i in range(200_000)])
    worker = threading.Thread(target=allocate_a_lot, name="worker")
    worker.start()
    worker.join()
    assert freed_in == []
    qtbot.waitUntil(lambda: bool(freed_in), timeout=wait_ms(30))   # the GUI thread's timer collects it
    assert freed_in == [threading.main_thread().name]


def test_the_gui_thread_collects_the_young_generation_a_worker_fills(qapp, qtbot):
    """The timer looks every CHECK_INTERVAL_MS (pyqtgraph's collector looked once a second and met ~190,000
    young objects during a diagnosis, a 126 ms collection); what a worker allocates is collected by the GUI
    thread's young-generation collections, none by the worker."""
    collector = gui_gc._collector
    assert collector.timer.interval() == gui_gc.CHECK_INTERVAL_MS

    collected_in = []

    def note(phase, info):
        if phase == "start":
            collected_in.append(threading.current_thread().name)
    gc.callbacks.append(note)
    try:
        kept = []
        done = threading.Event()

        def allocate_in_bursts():
            for _ in range(20):
                kept.append([[i] for i in range(2_000)])      # 2,000 containers a burst, kept alive
                done.wait(0.005)
            done.set()
        worker = threading.Thread(target=allocate_in_bursts, name="worker")
        worker.start()
        qtbot.waitUntil(done.is_set, timeout=wait_ms(30))
        worker.join()
        qtbot.waitUntil(lambda: gc.get_count()[0] <= collector.threshold[0], timeout=wait_ms(30))
    finally:
        gc.callbacks.remove(note)
    assert collected_in and set(collected_in) == {threading.main_thread().name}, collected_in
