"""What interrupted programs leave in an archive, removed once it is surely abandoned.

A store builds its folder as measurements/.incoming-XXXXXXXX and renames it
into place; a rebuild writes .index.sqlite.<pid>.<ns>.tmp beside the index
and renames it over. A program killed in between (a crash, a power cut, a
full disk) leaves these behind, hidden but taking space, forever.

They are removed when the archive is opened or rebuilt, but only once
nothing in them has changed for STALE_AFTER_S (an hour): a store writes its
few files within seconds (a long copy keeps touching the file it copies),
so a folder that old belongs to no running program, on this machine or on
another one sharing the archive. Nothing is followed through a symbolic
link, and what cannot be removed (a read-only archive) is left alone.
"""
from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

STALE_AFTER_S = 3600.0
INCOMING_PREFIX = ".incoming-"


def _is_index_temp(name: str, index_name: str) -> bool:
    return name.startswith(f".{index_name}.") and name.endswith(".tmp")


def last_change(path: Path) -> float:
    """The newest modification time of a folder and of what is directly in it (or of a file)."""
    newest = path.lstat().st_mtime
    if path.is_dir() and not path.is_symlink():
        with os.scandir(path) as it:
            for entry in it:
                try:
                    newest = max(newest, entry.stat(follow_symlinks=False).st_mtime)
                except OSError:       # removed while we looked: that was a change too
                    return time.time()
    return newest


def sweep(folders: Path, root: Path, index_name: str, max_age_s: float = STALE_AFTER_S,
          now: float | None = None) -> list[str]:
    """Remove abandoned .incoming-* folders (in `folders`) and index temporaries (in `root`); their names."""
    now = time.time() if now is None else now
    candidates: list[Path] = []
    for directory, wanted in ((folders, lambda e: e.name.startswith(INCOMING_PREFIX)
                               and e.is_dir(follow_symlinks=False)),
                              (root, lambda e: _is_index_temp(e.name, index_name)
                               and e.is_file(follow_symlinks=False))):
        try:
            with os.scandir(directory) as it:
                candidates += [Path(e.path) for e in it if e.name.startswith(".") and wanted(e)]
        except OSError:               # no such folder yet, or not readable: nothing to sweep there
            continue
    removed = []
    for path in candidates:
        try:
            if now - last_change(path) < max_age_s:
                continue
            if path.is_dir():
                shutil.rmtree(path)
            else:
                path.unlink()
            removed.append(path.name)
        except OSError:
            continue                  # read-only, or taken by someone else meanwhile: leave it
    return removed
