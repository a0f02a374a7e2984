"""The settings file cannot run code: entries Qt would unpickle are dropped, with a warning, before Qt reads them.

PySide6 registers PyObjectWrapper with pickle.loads as its QDataStream loader, so an
INI value "@Variant(...)" (or "@DateTime(...)", which wraps a QVariant too) naming it
runs whatever the pickle says when its section is first read. The payload here makes
a directory in the test's tmp_path: harmless, and visible.
"""
from __future__ import annotations

import logging
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from PySide6.QtCore import QByteArray, QSettings

from app.window.settings import Settings
from app.window.settings_ini import sanitized_ini
from tests.pace import paced


class _MakesMarker:
    def __init__(self, marker: Path):
        self.marker = str(marker)

    def __reduce__(self):
        return os.mkdir, (self.marker,)


def _variant_value(folder: Path, marker: Path) -> bytes:
    """The raw INI value PySide6 writes for a Python object: b'@Variant(...)'."""
    # Written through another file, so that no QSettings in this process has the target file cached.
    scratch = folder / "writer.ini"
    writer = QSettings(str(scratch), QSettings.IniFormat)
    writer.setValue("payload", _MakesMarker(marker))
    writer.sync()
    del writer
    line = next(li for li in scratch.read_bytes().splitlines() if li.startswith(b"payload="))
    value = line[len(b"payload="):]
    assert value.startswith(b"@Variant(") and b"PyObjectWrapper" in value
    return value


_NORMAL = (b"[General]\nrecent_files=/data/a.wav, /data/b.wav\n\n"
           b"[window]\ngeometry=@ByteArray(\\x1\\xd9\\xd0\\xcb\\0\\x3)\nstate=@ByteArray(\\0\\0\\0\\xff)\n\n"
           b"[wizard]\ntemplate=woofer\nout_dir=/data/out\n")


def _variants(value: bytes) -> dict[str, bytes]:
    """The same object, spelled the ways Qt's INI reader also accepts."""
    body = value[len(b"@Variant("):]
    assert body.startswith(b"\\0\\0\\0\\x7f")               # QVariant user type, Qt 4 stream
    # The Qt 5.6 stream @DateTime( uses: user type 1024, a null flag, then the type's name.
    datetime_body = b"\\0\\0\\x4\\0\\0" + body[len(b"\\0\\0\\0\\x7f"):]
    return {
        "plain": b"[wizard]\nevil=" + value + b"\n",
        "quoted": b'[wizard]\nevil="' + value + b'"\n',
        "hex-escaped @": b"[wizard]\nevil=\\x40Variant(" + body + b"\n",
        "octal-escaped @": b"[wizard]\nevil=\\100Variant(" + body + b"\n",
        "continued line": b"[wizard]\nevil=\\\n@Variant(" + body + b"\n",
        "in a list": b"[General]\nevil=/data/c.wav, " + value + b"\n",
        "@DateTime": b"[wizard]\nevil=@DateTime(" + datetime_body + b"\n",
    }


def _read_everything(q: QSettings) -> dict:
    return {key: q.value(key) for key in q.allKeys()}


def test_the_risk_is_real_without_settings(tmp_path):
    """Control: plain QSettings reading the file runs the payload (in a child process, to keep this one clean)."""
    marker = tmp_path / "ran"
    path = tmp_path / "linpar.ini"
    path.write_bytes(_NORMAL + _variants(_variant_value(tmp_path, marker))["plain"])
    code = textwrap.dedent(f"""
        from PySide6.QtCore import QSettings
        q = QSettings({str(path)!r}, QSettings.IniFormat)
        [q.value(k) for k in q.allKeys()]
    """)
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, timeout=paced(60))
    assert marker.exists()


@pytest.mark.parametrize("spelling", ["plain", "quoted", "hex-escaped @", "octal-escaped @", "continued line",
                                      "in a list", "@DateTime"])
def test_a_pickled_entry_is_dropped_before_qt_reads_it(tmp_path, caplog, spelling):
    marker = tmp_path / "ran"
    path = tmp_path / "linpar.ini"
    path.write_bytes(_NORMAL + _variants(_variant_value(tmp_path, marker))[spelling])
    q = QSettings(str(path), QSettings.IniFormat)        # constructed before, as the app's callers do

    with caplog.at_level(logging.WARNING, logger="app.window.settings"):
        settings = Settings(q)
    values = _read_everything(settings.qsettings)

    assert not marker.exists()
    key = "evil" if spelling == "in a list" else "wizard/evil"
    assert settings.dropped == [key]
    assert key not in values
    assert any(repr(key) in r.getMessage() and "unpickle" in r.getMessage() for r in caplog.records)
    assert b"PyObjectWrapper" not in path.read_bytes()   # the file itself is cleaned, not just this reading
    # Everything else is kept.
    assert settings.recent_files() == ["/data/a.wav", "/data/b.wav"]
    geometry, state = settings.window_geometry()
    assert bytes(geometry.data()) == b"\x01\xd9\xd0\xcb\x00\x03" and bytes(state.data()) == b"\x00\x00\x00\xff"
    assert values["wizard/template"] == "woofer" and values["wizard/out_dir"] == "/data/out"


def test_a_file_that_cannot_be_rewritten_is_read_from_a_cleaned_copy(tmp_path, caplog, monkeypatch):
    import app.window.settings as module

    def refuse(path, data):
        raise PermissionError("read-only")
    monkeypatch.setattr(module, "replace_bytes", refuse)
    marker = tmp_path / "ran"
    path = tmp_path / "linpar.ini"
    path.write_bytes(_NORMAL + _variants(_variant_value(tmp_path, marker))["plain"])

    with caplog.at_level(logging.WARNING, logger="app.window.settings"):
        settings = Settings(QSettings(str(path), QSettings.IniFormat))
    values = _read_everything(settings.qsettings)

    assert not marker.exists()
    assert settings.qsettings.fileName() != str(path)
    assert "wizard/evil" not in values and values["wizard/template"] == "woofer"
    assert any("cannot rewrite" in r.getMessage() for r in caplog.records)


def test_what_linpar_writes_is_left_alone(tmp_path, caplog):
    path = tmp_path / "linpar.ini"
    first = Settings(QSettings(str(path), QSettings.IniFormat))
    first.add_recent_file(tmp_path / "a.wav")
    first.add_recent_file(tmp_path / "b.wav")
    first.save_window(QByteArray(b"\x01\xd9\xd0\xcb\x00,\"=;\\"), QByteArray(b"\x00\xff"))
    first.qsettings.setValue("wizard/out_dir", "@home, \"quoted\"; and = signs")
    first.qsettings.sync()
    written = path.read_bytes()
    assert sanitized_ini(written) == (written, [])
    del first

    with caplog.at_level(logging.WARNING, logger="app.window.settings"):
        again = Settings(QSettings(str(path), QSettings.IniFormat))
    assert again.dropped == [] and not caplog.records
    assert again.recent_files() == [str((tmp_path / "b.wav").resolve()), str((tmp_path / "a.wav").resolve())]
    geometry, state = again.window_geometry()
    assert bytes(geometry.data()) == b"\x01\xd9\xd0\xcb\x00,\"=;\\" and bytes(state.data()) == b"\x00\xff"
    assert again.qsettings.value("wizard/out_dir") == "@home, \"quoted\"; and = signs"
    again.clear_recent_files()                            # written as @Invalid(): safe, kept
    assert sanitized_ini(path.read_bytes())[1] == [] and again.recent_files() == []


def test_fallback_files_are_not_read(tmp_path):
    settings = Settings(QSettings(str(tmp_path / "linpar.ini"), QSettings.IniFormat))
    assert not settings.qsettings.fallbacksEnabled()
