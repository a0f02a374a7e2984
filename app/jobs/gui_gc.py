"""Python's cycle collector runs in the GUI thread only, in small steps.

A reference cycle that holds a Qt object (a widget, a menu, an action) is
freed by whichever thread happens to allocate when the collector's threshold
is reached. When that is a worker thread (a measurement, a fit), the C++
destructor runs there: it takes Qt's locks and then wants the GIL, while the
GUI thread, holding the GIL, waits for the same lock. Both wait forever. The
suite met it: a level check's pool thread collected a QMenu while the GUI
thread deleted a QAction.

So the automatic collector is off and a QTimer of the GUI thread collects;
worker threads then never collect. Code that pauses the collector for a
while (the measurement's capture, a bulk read) asks gc.isenabled() first and
leaves it off.

The steps must stay small, since a collection holds the GUI thread (and the
GIL) for as long as it traverses. pyqtgraph's GarbageCollector, used until
now, looked once a second: a diagnosis' worker thread allocates ~190,000
objects in that second (each lmfit fit builds an asteval interpreter), and the
one young-generation collection that followed held the GUI thread 126 ms of
CPU, the middle generation's after it 101 ms; and it ran a full collection
every tenth middle one, whatever the heap's size (135 ms for the workstation's
170,000 objects). Here the timer looks every CHECK_INTERVAL_MS, so the young
generation holds what a worker allocates in that time; and the oldest
generation is collected as CPython's automatic collector does, only once the
objects promoted into it since the last full collection are a quarter of
those it held then. The objects that exist once the window is up (modules,
classes, the window's widgets: ~170,000) live as long as the program: they
are collected once and then frozen (gc.freeze), so that no later full
collection traverses them.
"""
from __future__ import annotations

import gc

from PySide6.QtCore import QTimer

CHECK_INTERVAL_MS = 20          # a check without anything due costs a microsecond
LONG_LIVED_SHARE = 0.25         # CPython's own rule for the oldest generation
_collector = None


class GuiCollector:
    """The automatic collector's rules, run by a QTimer of the GUI thread (see the module doc)."""

    def __init__(self, interval_ms: int = CHECK_INTERVAL_MS):
        self.threshold = gc.get_threshold()
        self.long_lived_pending = 0         # promoted into the oldest generation since its last collection
        self.long_lived_total = 0           # what the oldest generation held after its last collection
        self.frozen = False
        gc.disable()
        self.timer = QTimer()
        self.timer.timeout.connect(self.check)
        self.timer.start(interval_ms)

    def check(self) -> None:
        if not self.frozen:
            # The first turn of the event loop: start-up is over, what exists now lives as long as the program.
            self.frozen = True
            gc.collect()
            gc.freeze()
            return
        counts = gc.get_count()
        if counts[0] <= self.threshold[0]:
            return
        if counts[2] > self.threshold[2] and \
                self.long_lived_pending > LONG_LIVED_SHARE * self.long_lived_total:
            gc.collect(2)
            self.long_lived_pending = 0
            self.long_lived_total = len(gc.get_objects(generation=2))
        elif counts[1] > self.threshold[1]:
            # What survives this collection moves to the oldest generation.
            young = len(gc.get_objects(generation=0)) + len(gc.get_objects(generation=1))
            self.long_lived_pending += max(0, young - gc.collect(1))
        else:
            gc.collect(0)


def collect_in_gui_thread() -> None:
    """Call once, in the GUI thread, after the QApplication exists."""
    global _collector
    if _collector is None:
        _collector = GuiCollector()


def collect_if_due() -> None:
    """Collect now (in the calling thread, which must be the GUI thread) when a generation is due."""
    if _collector is not None:
        _collector.check()


def installed() -> bool:
    return _collector is not None and not gc.isenabled()
