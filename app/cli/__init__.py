"""The `linpar` command line: one module per command group, each with `register(subparsers)`.

`boundary.main` parses and runs the command's `run(args)` inside the one error
boundary. Qt is imported only by `linpar gui`.
"""
from app.cli.boundary import build_parser, main

__all__ = ["build_parser", "main"]
