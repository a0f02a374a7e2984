"""The `linpar` command line: one module per command group, each with `register(subparsers)`.

`boundary.main` parses and runs the command's `run(args)` inside the one error
boundary. Qt is imported only by `linpar gui`.
"""
import os

# One BLAS thread per process, unless the user set a number in any of the three variables (OpenBLAS reads its own
# before OMP_NUM_THREADS: setting it alone would override a user's OMP_NUM_THREADS): OpenBLAS starts a thread per
# core and spins them while it waits, and this program's matrices are small (a fit's Jacobian) while its parallel
# work already runs in processes of its own. Measured on two cores (bench/analysis_bench.py, OpenBLAS's default
# then one): the whole-catalogue diagnosis 1.16 -> 0.82 s, the real-like woofer's 1.62 -> 1.26 s; `linpar
# analyze` the same 0.34 s wall with 0.52 -> 0.34 s of CPU. Set before anything imports numpy; the window
# (`linpar gui`), the worker processes and a rig started with `linpar rig start` inherit it.
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
if not any(os.environ.get(name) for name in BLAS_THREAD_VARIABLES):
    os.environ.update(dict.fromkeys(BLAS_THREAD_VARIABLES, "1"))

from app.cli.boundary import build_parser, main  # noqa: E402 - after the BLAS threads are set

__all__ = ["build_parser", "main"]
