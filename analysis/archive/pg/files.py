"""A measurement's files as large objects: sent in chunks whose checksums the server checks, read back in
chunks against the whole file's SHA-256.

Large objects rather than bytea: a recording may be up to 2 GB
(analysis.bounds.SizeLimits.wav) and bytea stops at 1 GB; a large object is
written and read in pieces, so neither side holds a whole recording in memory.
Writing goes through the schema's SECURITY DEFINER functions (see
analysis.archive.pg.schema), inside the transaction that stores the
measurement's row: the row and its files are stored together or not at all.
"""
from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

from analysis.archive.atomic import FILE_MODE
from analysis.archive.names import ArchiveError

CHUNK = 1024 * 1024


def file_sha256(path: Path) -> tuple[str, int]:
    """(hex SHA-256, size) of a file, read in chunks."""
    digest, size = hashlib.sha256(), 0
    with open(path, "rb") as f:
        while chunk := f.read(CHUNK):
            digest.update(chunk)
            size += len(chunk)
    return digest.hexdigest(), size


def send_file(conn, measurement_id: str, role: str, name: str, path: Path) -> None:
    """Write one file as a large object and seal it to the measurement (in the caller's transaction)."""
    (lo,) = conn.execute("SELECT linpar.file_create()").fetchone()
    digest, at = hashlib.sha256(), 0
    with open(path, "rb") as f:
        while chunk := f.read(CHUNK):
            digest.update(chunk)
            conn.execute("SELECT linpar.file_write(%s, %s, %s, %s)",
                         (lo, at, chunk, hashlib.sha256(chunk).hexdigest()))
            at += len(chunk)
    conn.execute("SELECT linpar.file_seal(%s, %s, %s, %s, %s, %s)",
                 (measurement_id, role, name, lo, at, digest.hexdigest()))


def fetch_file(conn, lo: int, size: int, sha256: str, target: Path, where: str) -> Path:
    """Read a large object into `target` (written atomically), checked against its size and SHA-256.

    A `target` already there with the right checksum is kept as it is (a cache hit).
    """
    if target.is_file() and not target.is_symlink():
        try:
            if file_sha256(target) == (sha256, size):
                return target
        except OSError:
            pass
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    try:
        digest, got = hashlib.sha256(), 0
        with os.fdopen(fd, "wb") as f:
            while got < size:
                (chunk,) = conn.execute("SELECT lo_get(%s, %s, %s)", (lo, got, min(CHUNK, size - got))).fetchone()
                if not chunk:
                    break
                digest.update(chunk)
                f.write(chunk)
                got += len(chunk)
        if got != size or digest.hexdigest() != sha256:
            raise ArchiveError(f"{where}: the stored file does not match its checksum (read {got} of {size} bytes, "
                               f"SHA-256 {digest.hexdigest()[:12]}... instead of {sha256[:12]}...): it is damaged "
                               "on the server; ask the line's administrator to restore it from a backup")
        os.chmod(tmp, FILE_MODE)
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return target
