"""Imported once by the process pool's fork server (analysis.parallel), before it forks the workers.

What every worker would otherwise build for itself on its first fit: the modules a fit and a diagnosis
import, the table of the air load's Struve term (~0.17 s of CPU) and MINPACK's compiled routines
(analysis.fit.minpack, a few ms). The GUI starts a pool for each diagnosis, so its workers are new each
time; built here, all are paid for once per process and inherited by every worker forked after.

The server is started by the first pool, often while the window starts, and its 0.8-1.0 s of CPU here
took a core from the GUI thread on a two-core machine. So it runs below its caller, as a background pool's
workers do (BACKGROUND_NICENESS), in a thread: on Linux a thread's nice value is its own, and the server's
main thread, which forks the workers, stays at its caller's level. A worker of a plain pool then runs beside
its caller, and a background pool's initializer lowers its own once, to the same level as before, not twice.
Elsewhere (a nice value per process) the preload runs at the caller's level, as it did.
"""
from __future__ import annotations

import os
import sys
import threading

from analysis.parallel import BACKGROUND_NICENESS

niceness: int | None = None     # the nice value the preload ran at (tests read it on a worker)


def _preload() -> None:
    global niceness
    # os.nice acts on the calling thread on Linux (setpriority on the calling task), on the process elsewhere.
    niceness = os.nice(BACKGROUND_NICENESS if sys.platform.startswith("linux") else 0)
    import analysis.diagnosis.candidates  # noqa: F401 - imported to be inherited
    import analysis.fit.least_squares  # noqa: F401
    from analysis.effects.mechanical import build_tables
    from analysis.fit.minpack import load_compiled_routines
    build_tables()
    load_compiled_routines()


# Waited for: the server forks no worker before its preload is done. Should it fail, threading prints the
# traceback and the workers import what they need themselves.
_preloading = threading.Thread(target=_preload, name="pool preload")
_preloading.start()
_preloading.join()
