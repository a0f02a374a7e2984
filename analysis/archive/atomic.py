"""The archive's atomic writes: the one write_atomic (analysis.files), file modes, and durable renames."""
from __future__ import annotations

import os
from pathlib import Path

from analysis.files import DIR_MODE, FILE_MODE, write_atomic

__all__ = ["DIR_MODE", "FILE_MODE", "fsync_dir", "write_atomic"]


def fsync_dir(path: str | Path) -> None:
    """Make a rename inside `path` durable (POSIX; a no-op where directories cannot be opened)."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
