"""Python's cycle collector runs in the GUI thread only.

A reference cycle that holds a Qt object (a widget, a menu, an action) is
freed by whichever thread happens to allocate when the collector's threshold
is reached. When that is a worker thread (a measurement, a fit), the C++
destructor runs there: it takes Qt's locks and then wants the GIL, while the
GUI thread, holding the GIL, waits for the same lock. Both wait forever. The
suite met it: a level check's pool thread collected a QMenu while the GUI
thread deleted a QAction.

pyqtgraph's GarbageCollector turns the automatic collector off and collects
on a timer in the GUI thread; worker threads then never collect. Code that
pauses the collector for a while (the measurement's capture, a bulk read)
asks gc.isenabled() first and leaves it off.
"""
from __future__ import annotations

import gc

COLLECT_INTERVAL_S = 1.0
_collector = None


def collect_in_gui_thread() -> None:
    """Call once, in the GUI thread, after the QApplication exists."""
    global _collector
    if _collector is None:
        from pyqtgraph.util.garbage_collector import GarbageCollector
        _collector = GarbageCollector(interval=COLLECT_INTERVAL_S)


def collect_if_due() -> None:
    """Collect now (in the calling thread, which must be the GUI thread) when a generation is due."""
    if _collector is not None:
        _collector.check()


def installed() -> bool:
    return _collector is not None and not gc.isenabled()
