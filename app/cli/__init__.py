"""The `linpar` command line: one module per command group, each with `register(subparsers)`.

`boundary.main` parses and runs the command's `run(args)` inside the one error
boundary. A new command's name goes into boundary.COMMANDS with its module: a
command line builds the parser of the command it names only (the test of
app/cli/boundary.py checks the table against what each module registers).
Qt is imported only by `linpar gui`.
"""
from app.blas_threads import one_blas_thread

one_blas_thread()           # before anything imports numpy (app/blas_threads.py)

from app.cli.boundary import build_parser, main  # noqa: E402 - after the BLAS threads are set

__all__ = ["build_parser", "main"]
