"""What the window remembers between runs: recent files and the window geometry.

A thin layer over QSettings so that tests can hand in a QSettings on a
temporary file instead of touching the user's real settings.
"""
from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QByteArray, QSettings

ORGANIZATION = "linpar"
APPLICATION = "linpar"
MAX_RECENT = 8

_RECENT = "recent_files"
_GEOMETRY = "window/geometry"
_STATE = "window/state"


def default_qsettings() -> QSettings:
    return QSettings(ORGANIZATION, APPLICATION)


class Settings:
    def __init__(self, qsettings: QSettings | None = None):
        self._q = qsettings if qsettings is not None else default_qsettings()

    @property
    def qsettings(self) -> QSettings:
        return self._q

    # -- recent files ------------------------------------------------------
    def recent_files(self) -> list[str]:
        value = self._q.value(_RECENT, [])
        # QSettings gives a str for a one-element list in INI files, None for empty.
        if value is None:
            return []
        if isinstance(value, str):
            value = [value]
        return [str(v) for v in value if v][:MAX_RECENT]

    def add_recent_file(self, path: str | Path) -> list[str]:
        path = str(Path(path).resolve())
        files = [path] + [f for f in self.recent_files() if f != path]
        files = files[:MAX_RECENT]
        self._q.setValue(_RECENT, files)
        self._q.sync()
        return files

    def remove_recent_file(self, path: str) -> list[str]:
        files = [f for f in self.recent_files() if f != path]
        self._q.setValue(_RECENT, files)
        self._q.sync()
        return files

    def clear_recent_files(self) -> None:
        self._q.setValue(_RECENT, [])
        self._q.sync()

    # -- window ------------------------------------------------------------
    def window_geometry(self) -> tuple[QByteArray | None, QByteArray | None]:
        return self._bytes(_GEOMETRY), self._bytes(_STATE)

    def save_window(self, geometry: QByteArray, state: QByteArray) -> None:
        self._q.setValue(_GEOMETRY, geometry)
        self._q.setValue(_STATE, state)
        self._q.sync()

    def _bytes(self, key: str) -> QByteArray | None:
        value = self._q.value(key)
        return value if isinstance(value, QByteArray) and not value.isEmpty() else None
