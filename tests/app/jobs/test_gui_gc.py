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
