"""`linpar gui`: the workstation window (Qt is imported only when it runs)."""
from __future__ import annotations

import argparse


def register(sub) -> None:
    gui = sub.add_parser("gui", help="start the workstation window")
    gui.add_argument("path", nargs="?", help="a recording to open")
    gui.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from app.main import run_gui
    return run_gui(args.path)
