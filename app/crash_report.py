"""Crash reports: what a bug leaves behind for whoever fixes it, while the user reads one line.

An exception that is not a user error (analysis.errors.is_user_error) is a
bug. The CLI and the GUI report it the same way: one line,

    internal error: ZeroDivisionError: float division by zero (details in /home/u/.cache/linpar/crash-....txt)

and a text file with the traceback, the command line, the version of linpar,
Python and the platform. Crash reports go to the platform's cache folder
(analysis.config_folder.cache_folder):

    $LINPAR_CACHE                         when set (tests, or a shared folder at a station)
    Linux and others  $XDG_CACHE_HOME/linpar, else ~/.cache/linpar
    macOS             ~/Library/Caches/linpar
    Windows           %LOCALAPPDATA%\\linpar\\Cache

No Qt here: the command line uses it without loading the GUI.
"""
from __future__ import annotations

import os
import platform
import sys
import traceback
from datetime import datetime
from pathlib import Path
from typing import Sequence

from analysis.config_folder import cache_folder
from analysis.errors import one_line

PREFIX = "crash-"


def cache_dir() -> Path:
    """The folder crash reports go to (module doc); not created here."""
    return cache_folder()


def version() -> str:
    try:
        from importlib.metadata import version as installed
        return installed("linpar")
    except Exception:  # noqa: BLE001 - a crash report must be written even from a source tree without metadata
        return "unknown (not installed)"


def write_crash_report(exc: BaseException, doing: str = "", argv: Sequence[str] | None = None) -> Path:
    """Write the report of `exc` to cache_dir(); its path. OSError when it cannot be written."""
    folder = cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    now = datetime.now()
    command = list(sys.argv if argv is None else ["linpar", *argv])
    text = "\n".join([
        "linpar crash report",
        f"time:     {now.isoformat(timespec='seconds')}",
        f"version:  linpar {version()}, Python {platform.python_version()}, {platform.platform()}",
        f"command:  {' '.join(command)}",
        f"doing:    {doing or '-'}",
        "",
        "".join(traceback.format_exception(exc)),
    ])
    for attempt in range(100):
        path = folder / f"{PREFIX}{now:%Y%m%d-%H%M%S}-{os.getpid()}{f'-{attempt}' if attempt else ''}.txt"
        try:
            # "x": never overwrite another report (two jobs of the GUI may fail in the same second).
            # backslashreplace: a command line of bytes that were not UTF-8 is written, not lost mid-file.
            with open(path, "x", encoding="utf-8", errors="backslashreplace") as f:
                f.write(text)
            return path
        except FileExistsError:
            continue
    raise FileExistsError(f"{folder}: no free crash report name")


def internal_error_line(exc: BaseException, doing: str = "", argv: Sequence[str] | None = None) -> str:
    """'internal error[ while DOING]: Type: message (details in FILE)', after writing the crash report."""
    what = f"{type(exc).__name__}: {one_line(exc)}" if str(exc).strip() else type(exc).__name__
    try:
        where = f"details in {write_crash_report(exc, doing, argv)}"
    except OSError as err:
        where = f"no crash report: {cache_dir()} cannot be written ({err.strerror or err})"
    while_doing = f" while {doing}" if doing else ""
    return f"internal error{while_doing}: {what} ({where})"
