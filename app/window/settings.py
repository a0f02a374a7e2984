"""What the window remembers between runs: recent files and the window geometry.

A thin layer over QSettings so that tests can hand in a QSettings on a
temporary file instead of touching the user's real settings.

The settings file is checked before Qt reads it. Qt turns an INI value
"@Variant(...)" (or "@DateTime(...)", which carries a QVariant too) back into an
object through QDataStream, and PySide6 registers a type, PyObjectWrapper, whose
loader is pickle.loads: a crafted entry in ~/.config/linpar/linpar.conf would run
code as soon as any key of its section is read. linpar writes only strings,
string lists, @ByteArray values and @Invalid() (an empty list), so every entry
that Qt would decode as anything else is removed from the file, with a warning
naming the key, before the first read. Qt parses a section only on access, so the check must come
before any value(), contains() or allKeys() on the file.
"""
from __future__ import annotations

import logging
import sys
import tempfile
from pathlib import Path

from PySide6.QtCore import QByteArray, QLockFile, QSettings

from app.window.settings_ini import replace_bytes, sanitized_ini

log = logging.getLogger(__name__)

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
        q = qsettings if qsettings is not None else default_qsettings()
        # The organisation-wide and system files (~/.config/linpar.conf, /etc/xdg/...) are
        # read as fallbacks; linpar never writes them, so it does not read them either.
        q.setFallbacksEnabled(False)
        self._scratch: tempfile.TemporaryDirectory | None = None
        self.dropped: list[str] = []       # the keys removed from the file as unsafe
        self._q = self._made_safe(q)

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
        if not isinstance(value, list):
            return []
        return [v for v in value if isinstance(v, str) and v][:MAX_RECENT]

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

    # -- the file's safety -------------------------------------------------
    def _made_safe(self, q: QSettings) -> QSettings:
        """`q`, once its file holds no entry Qt would unpickle; a sanitised copy if that file cannot be rewritten."""
        ini = q.format() == QSettings.IniFormat or (
            q.format() == QSettings.NativeFormat and sys.platform not in ("win32", "darwin"))
        path = Path(q.fileName())
        if not ini or not path.is_file():
            return q
        try:
            data = path.read_bytes()
        except OSError:
            return q                        # Qt cannot read it either: it treats it as empty
        try:
            cleaned, dropped = sanitized_ini(data)
        except RuntimeError as error:
            log.error("settings: %s is not used (%s); starting with empty settings", path, error)
            return self._scratch_settings(path.name, b"")
        if not dropped:
            return q
        self.dropped = dropped
        for key in dropped:
            log.warning("settings: dropped %r from %s: its value is a serialised object that Qt would "
                        "unpickle, which can run code; linpar never writes such values", key, path)
        # The lock QSettings takes to write the file, so that another linpar's write is not lost in between.
        lock = QLockFile(str(path) + ".lock")
        lock.tryLock(2000)                  # without it after 2 s, rather than not start
        try:
            cleaned, _ = sanitized_ini(path.read_bytes())
            replace_bytes(path.resolve(), cleaned)
        except (OSError, RuntimeError) as error:
            log.error("settings: cannot rewrite %s (%s); using a cleaned copy, changes will not be saved",
                      path, error)
            return self._scratch_settings(path.name, cleaned)
        finally:
            lock.unlock()
        q.sync()    # Qt may hold the old bytes from its constructor; the size changed, so it reads them again
        return q

    def _scratch_settings(self, name: str, content: bytes) -> QSettings:
        """Settings on a private copy holding `content`: read, but never written back to the user's file."""
        self._scratch = tempfile.TemporaryDirectory(prefix="linpar-settings-")
        copy = Path(self._scratch.name) / name
        copy.write_bytes(content)
        safe = QSettings(str(copy), QSettings.IniFormat)
        safe.setFallbacksEnabled(False)
        return safe
