"""The archive's back ends: one interface, found from a specification (a folder, or a server's URL).

    open_archive()                                   $LINPAR_ARCHIVE_URL, else $LINPAR_ARCHIVE, else the default folder
    open_archive("/srv/linpar/archive")              a folder archive: folders + SQLite index (analysis.archive.archive)
    open_archive("postgresql://station1@qa-db/linpar")   a PostgreSQL server shared by the line's stations

Which back end a specification names is decided here and nowhere else (the
BACKENDS registry, by URL scheme; anything without "://" is a folder). An
explicit specification (a command's --archive or --root, the GUI's choice)
wins over the environment; $LINPAR_ARCHIVE_URL wins over $LINPAR_ARCHIVE, so
that a station configured for the line's server never stores into its local
folder by mistake.

Every back end offers `ArchiveBackend`; tests/analysis/archive/test_archive_backends.py
runs one suite against each.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, Iterable, Protocol

from analysis.archive.names import ArchiveError, shown  # noqa: F401 - shown: re-exported, callers show specifications
from analysis.archive.sync_report import SyncReport

URL_ENV = "LINPAR_ARCHIVE_URL"
FOLDER_ENV = "LINPAR_ARCHIVE"


class ArchiveBackend(Protocol):
    """What every archive offers (analysis.archive.Archive and analysis.archive.pg.PostgresArchive)."""

    location: str          # what messages call it: the folder, or the URL without its password
    notes: list[str]       # what opening or storing had to repair or say, for the user

    def store(self, recording, result, meta=None, laser_stream=None, now=None) -> str: ...
    def list(self, flt=None, **kwargs) -> list: ...
    def resolve(self, id_or_prefix: str) -> tuple[str, str]: ...
    def get(self, id_or_prefix: str): ...
    def export(self, id_or_prefix: str, directory) -> Path: ...
    def rebuild(self): ...
    def limits_versions(self) -> list: ...
    def limits(self, version: int | None = None): ...
    def store_limits(self, document, note: str = ""): ...
    def golden(self) -> list[str]: ...
    def set_golden(self, ids: Iterable[str], golden: bool = True) -> list[str]: ...
    def population(self, selection=None, names=None, with_stds: bool = True): ...
    def sync(self) -> SyncReport: ...
    @property
    def pending(self) -> int: ...


def _folder(spec: str) -> ArchiveBackend:
    from analysis.archive.archive import Archive
    if spec.startswith("file://"):
        spec = spec[len("file://"):]
    return Archive(Path(spec).expanduser())


def _postgresql(spec: str) -> ArchiveBackend:
    from analysis.archive.pg import PostgresArchive
    return PostgresArchive(spec)


# URL scheme -> the back end's factory. A new back end adds its scheme here and its module.
BACKENDS: dict[str, Callable[[str], ArchiveBackend]] = {"postgresql": _postgresql, "postgres": _postgresql,
                                                        "file": _folder}


def archive_spec(explicit: str | Path | None = None) -> str:
    """The archive to use: `explicit` (an option), else $LINPAR_ARCHIVE_URL, else $LINPAR_ARCHIVE, else the
    default folder."""
    if explicit is not None and str(explicit).strip():
        return str(explicit)
    for env in (URL_ENV, FOLDER_ENV):
        value = os.environ.get(env, "").strip()
        if value:
            return value
    from analysis.archive.archive import default_root
    return str(default_root())


def is_url(spec: str) -> bool:
    return "://" in str(spec)


def _factory(spec: str) -> Callable[[str], ArchiveBackend]:
    if not is_url(spec):
        return _folder
    scheme = spec.split("://", 1)[0].lower()
    if scheme not in BACKENDS:
        raise ArchiveError(f"{scheme}://...: unknown kind of archive: expected postgresql://USER@HOST[:PORT]/DATABASE "
                           "or a folder")
    return BACKENDS[scheme]


def check_spec(spec: str) -> None:
    """ArchiveError when a specification cannot name an archive (a URL of no known kind, or not well formed);
    nothing is opened or connected to: for a command that stores only after minutes of measuring."""
    if _factory(spec) is _postgresql:
        from analysis.archive.pg.server import parse_url
        parse_url(spec)


def open_archive(spec: str | Path | None = None) -> ArchiveBackend:
    """The archive a specification names (archive_spec says which when it is None)."""
    spec = archive_spec(spec)
    return _factory(spec)(spec)
