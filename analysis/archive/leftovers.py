"""What interrupted programs leave in an archive, removed once it is surely abandoned.

A store builds its folder as measurements/.incoming-XXXXXXXX and renames it
into place; a rebuild writes .index.sqlite.<pid>.<ns>.tmp (and SQLite its
.tmp-journal) beside the index and renames it over. A program killed in
between (a crash, a power cut, a full disk) leaves these behind, hidden but
taking space, forever.

They are removed when the archive is opened or rebuilt, but only once
nothing in them has changed for STALE_AFTER_S (an hour): a store writes its
few files within seconds (a long copy keeps touching the file it copies),
so a folder that old belongs to no running program, on this machine or on
another one sharing the archive. Ages are measured against the file
system's own clock (the modification time of a probe file made for the
purpose), not this machine's: on a network share the two may be hours
apart, and a clock behind the server's would make a folder in use look
old. An archive where the probe cannot be made (read-only) is left alone.

A folder is claimed before it is deleted: renamed to .removing-<uuid>, which
only one program can do. A store that still wrote into it (stalled for an
hour, a suspended laptop) then fails to rename it into place, instead of
putting a half-deleted folder into the archive; a second sweeper's rename
fails and it moves on. A .removing-* folder left by a sweeper that was
itself interrupted is already claimed and is removed once it has not
changed for REMOVING_STALE_AFTER_S (a minute) and was not claimed within
that minute (its ctime, which the rename sets): a sweeper that is deleting
it touches it with every file it removes, so two sweepers do not delete one
folder at once. Nothing is followed through a symbolic link.
"""
from __future__ import annotations

import math
import os
import shutil
import uuid
from pathlib import Path

STALE_AFTER_S = 3600.0
REMOVING_STALE_AFTER_S = 60.0
INCOMING_PREFIX = ".incoming-"
REMOVING_PREFIX = ".removing-"
PROBE_PREFIX = ".clock-probe-"


def _is_index_temp(name: str, index_name: str) -> bool:
    return name.startswith(f".{index_name}.") and name.endswith((".tmp", ".tmp-journal"))


def last_change(path: Path) -> float:
    """The newest modification time of a folder and of what is directly in it (or of a file)."""
    newest = path.lstat().st_mtime
    if path.is_dir() and not path.is_symlink():
        with os.scandir(path) as it:
            for entry in it:
                try:
                    newest = max(newest, entry.stat(follow_symlinks=False).st_mtime)
                except OSError:       # removed while we looked: that was a change too, just now
                    return math.inf
    return newest


def file_system_now(directory: Path) -> float | None:
    """The time on the clock of the file system that holds `directory`; None where nothing can be written there."""
    probe = directory / f"{PROBE_PREFIX}{uuid.uuid4().hex}"
    try:
        fd = os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except OSError:
        return None
    try:
        os.close(fd)
        return probe.lstat().st_mtime
    except OSError:
        return None
    finally:
        try:
            probe.unlink()
        except OSError:
            pass


def _candidates(folders: Path, root: Path, index_name: str) -> list[tuple[Path, bool]]:
    """(path, whether a sweeper already claimed it) of what may be a leftover."""
    found = []
    for directory in (folders, root):
        try:
            with os.scandir(directory) as it:
                for e in it:
                    if not e.name.startswith("."):
                        continue
                    if directory == folders and e.is_dir(follow_symlinks=False):
                        if e.name.startswith(INCOMING_PREFIX):
                            found.append((Path(e.path), False))
                        elif e.name.startswith(REMOVING_PREFIX):
                            found.append((Path(e.path), True))
                    elif directory == root and _is_index_temp(e.name, index_name) \
                            and e.is_file(follow_symlinks=False):
                        found.append((Path(e.path), False))
        except OSError:               # no such folder yet, or not readable: nothing to sweep there
            continue
    return found


def _remove(path: Path, claimed: bool) -> bool:
    """Delete one leftover; False when it was taken meanwhile or cannot be removed."""
    try:
        if not path.is_dir() or path.is_symlink():
            path.unlink()             # one step: nobody sees half of it
            return True
        if not claimed:
            target = path.with_name(f"{REMOVING_PREFIX}{uuid.uuid4().hex}")
            os.rename(path, target)   # ours from here on; a store still using it fails to rename it into place
            path = target
        shutil.rmtree(path)
        return True
    except OSError:                   # read-only, or taken by someone else meanwhile: leave it
        return False


def sweep(folders: Path, root: Path, index_name: str, max_age_s: float = STALE_AFTER_S,
          now: float | None = None) -> list[str]:
    """Remove abandoned .incoming-* and .removing-* folders (in `folders`) and index temporaries (in `root`).

    Returns the names removed. `now` defaults to the file system's clock (module doc).
    """
    candidates = _candidates(folders, root, index_name)
    if not candidates:
        return []                     # the usual case: nothing written, not even the probe
    if now is None:
        now = file_system_now(folders)
        if now is None:
            return []                 # a read-only archive: left as it is
    removed = []
    for path, claimed in candidates:
        try:
            changed = last_change(path)
            if claimed:               # a rename sets the ctime: claimed by a sweeper that may still be at it
                changed = max(changed, path.lstat().st_ctime)
        except OSError:
            continue                  # taken meanwhile
        if now - changed < (REMOVING_STALE_AFTER_S if claimed else max_age_s):
            continue
        if _remove(path, claimed):
            removed.append(path.name)
    return removed
