"""One BLAS thread per process, unless the user set a number: imported (it needs only `os`) before numpy is.

OpenBLAS starts a thread per core and spins them while it waits, and this program's matrices are small (a fit's
Jacobian) while its parallel work already runs in processes of its own. Measured on two cores
(bench/analysis_bench.py, OpenBLAS's default then one): the whole-catalogue diagnosis 1.16 -> 0.82 s, the
real-like woofer's 1.62 -> 1.26 s; `linpar analyze` the same 0.34 s wall with 0.52 -> 0.34 s of CPU
(docs/timing.md). The command sets it (app/cli/__init__.py), and the window (`linpar gui`), the worker processes
and a rig started with `linpar rig start` inherit it; the test suite and the benchmarks' floor set it the same way.
"""
from __future__ import annotations

import os
from collections.abc import MutableMapping

VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def one_blas_thread(environ: MutableMapping[str, str] = os.environ) -> None:
    """All three variables to 1 when the user set none of them. Not each one that is unset: OpenBLAS reads its
    own before OMP_NUM_THREADS, so a user's OMP_NUM_THREADS alone would be overridden."""
    if not any(environ.get(name) for name in VARIABLES):
        environ.update(dict.fromkeys(VARIABLES, "1"))
