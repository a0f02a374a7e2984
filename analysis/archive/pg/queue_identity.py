"""Which local queue a station's measurements wait in: the server's identity, not the URL's spelling.

postgresql://station1@localhost/linpar and postgresql://station1@127.0.0.1:5432/linpar name one server, and
a queue kept per URL spelling put a measurement queued under one in a folder the other never read: "nothing
waits" while it did. The server says who it is on every connection: its cluster's system identifier
(pg_control_system(): the same whatever address, port or name reaches it), the database and the session's
user. The queue is kept under that identity (identity_folder).

A station cut off from the server must still find that queue, so the URL's own folder keeps a pointer to it
(POINTER_FILE), written the first time the URL reaches the server. Measurements queued in the URL's folder
(by a linpar before this one, or under a spelling that had never reached the server) are moved into the
identity's folder when the pointer is known: on opening and at the first connection. Each is one folder,
renamed whole (one step, on one file system: it is in one queue or the other, never in neither); each
folder archive's index follows its folders on opening (analysis.archive.index).
"""
from __future__ import annotations

import hashlib
import os
import re
import shutil
from pathlib import Path

from analysis import file_lock
from analysis.archive.archive import FOLDERS
from analysis.archive.pg.outbox import LIMITS_CACHE, LOCK_FILE

POINTER_FILE = "server-identity"
_FOLDER_NAME = re.compile(r"^[A-Za-z0-9@._-]{1,120}$")


def folder_key(raw: str) -> str:
    """A folder name for `raw` (readable, with a hash of it so that two raws never share one)."""
    tail = hashlib.sha256(raw.encode()).hexdigest()[:8]
    return re.sub(r"[^A-Za-z0-9@._-]+", "-", raw)[:80] + "-" + tail


def server_identity(conn) -> str | None:
    """The queue folder's name for the server, database and user of `conn`; None when the server does not say
    (pg_control_system() revoked: the URL's spelling keys the queue, as before)."""
    import psycopg
    try:
        system_id, database, user = conn.execute(
            "SELECT system_identifier::text, current_database(), session_user FROM pg_control_system()").fetchone()
    except psycopg.Error:
        return None
    return folder_key(f"{user}@server-{system_id}-{database}")


def remembered(url_folder: Path) -> Path | None:
    """The identity folder the URL's folder points to, or None (never reached the server, or no pointer)."""
    try:
        name = (url_folder / POINTER_FILE).read_text(encoding="utf-8").strip()
    except (OSError, UnicodeDecodeError):
        return None
    return url_folder.parent / name if _FOLDER_NAME.match(name) and name not in (".", "..") else None


def adopt(source: Path, target: Path) -> list[str]:
    """Move what waits in the queue folder `source` into `target`; the names of the measurement folders moved.
    Under `source`'s sending lock: a program sending from it now is left to send (nothing moved this time)."""
    if source == target or not source.is_dir():
        return []
    lock = file_lock.take(source / LOCK_FILE, wait_s=0)
    if lock is None:
        return []
    try:
        moved = []
        waiting = source / FOLDERS
        names = sorted(e.name for e in os.scandir(waiting) if e.is_dir(follow_symlinks=False)
                       and not e.name.startswith(".")) if waiting.is_dir() else []
        if names:
            (target / FOLDERS).mkdir(parents=True, exist_ok=True)
        for name in names:
            try:
                os.rename(waiting / name, target / FOLDERS / name)      # refused when target has one so named
                moved.append(name)
            except OSError:
                pass            # stays where it was: sent from there under that URL, never lost
        if (source / LIMITS_CACHE).is_file() and not (target / LIMITS_CACHE).exists():
            shutil.copy2(source / LIMITS_CACHE, target / LIMITS_CACHE)
        return moved
    finally:
        lock.release()


def point(url_folder: Path, target: Path) -> None:
    """Leave the URL's queue folder pointing to the server's (`target`), for when the server cannot be reached."""
    from analysis.archive.atomic import write_atomic
    target.mkdir(parents=True, exist_ok=True)
    if remembered(url_folder) != target:
        url_folder.mkdir(parents=True, exist_ok=True)
        write_atomic(url_folder / POINTER_FILE, target.name + "\n")
