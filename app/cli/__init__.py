"""The `linpar` command line: one module per command group, each with `register(subparsers)`.

`boundary.main` parses and runs the command's `run(args)` inside the one error
boundary. Qt is imported only by `linpar gui`.
"""
import os

# One BLAS thread per process, unless the user set a number: OpenBLAS starts a thread per core and spins them
# while it waits, and this program's matrices are small (a fit's Jacobian) while its parallel work already runs
# in processes of its own. Measured on two cores (bench/analysis_bench.py, OpenBLAS's default then one): the
# whole-catalogue diagnosis 1.16 -> 0.82 s, the real-like woofer's 1.62 -> 1.26 s; `linpar analyze` the same
# 0.34 s wall with 0.52 -> 0.34 s of CPU. Set before anything imports numpy (the command, the window, the
# worker processes and the rig's server all start from here and inherit it).
for _blas_threads in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_blas_threads, "1")

from app.cli.boundary import build_parser, main  # noqa: E402 - after the BLAS threads are set

__all__ = ["build_parser", "main"]
