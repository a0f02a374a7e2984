"""Exclusive locks on a file, on every system: flock on Linux and macOS, LockFileEx on Windows (filelock).

The operating system frees such a lock when its holder ends, also by a
crash, which the recovery journal relies on: a journal whose lock nobody
holds belongs to a measurement that is no longer running. Where the native
lock is missing (a filesystem without flock), filelock falls back to a lock
file that names its holder's process and is taken over once that process is
gone.
"""
from __future__ import annotations

import contextlib
import warnings
from pathlib import Path
from typing import Iterator

with warnings.catch_warnings():
    # filelock warns at import when it must use its lock-file fallback; exclusive() still works then.
    warnings.simplefilter("ignore", UserWarning)
    from filelock import FileLock, Timeout


def take(path: Path | str, wait_s: float = -1.0) -> FileLock | None:
    """Hold the lock of ``path`` (created if missing) until ``release()``; None when another holder has it.

    ``wait_s``: how long to wait for it; 0 asks once, a negative value waits for as long as it takes.
    """
    lock = FileLock(str(path), timeout=wait_s)
    try:
        lock.acquire()
    except Timeout:
        return None
    return lock


def held(path: Path | str) -> bool:
    """Whether another holder has the lock of ``path`` now (False when there is no such file, or it cannot be
    opened: a lock nobody can take is held by nobody)."""
    if not Path(path).exists():
        return False
    try:
        lock = take(path, wait_s=0)
    except OSError:
        return False
    if lock is None:
        return True
    lock.release()
    return False


@contextlib.contextmanager
def exclusive(path: Path | str, wait: bool = True) -> Iterator[bool]:
    """Hold the lock of ``path`` inside the block; yields False (without it) when ``wait`` is False and another
    holder has it."""
    lock = take(path, -1.0 if wait else 0.0)
    try:
        yield lock is not None
    finally:
        if lock is not None:
            lock.release()
