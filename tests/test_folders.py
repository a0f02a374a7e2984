"""Issue 22: linpar's folders are the platform's (platformdirs), and the environment still overrides them."""
from __future__ import annotations

import sys
from pathlib import Path

import platformdirs
import platformdirs.macos
import pytest

from analysis import config_folder
from analysis.archive.archive import default_root
from analysis.archive.pg.archive import cache_folder as server_cache
from analysis.archive.pg.outbox import queue_folder
from app.crash_report import cache_dir


@pytest.fixture
def no_overrides(monkeypatch):
    for variable in ("LINPAR_ARCHIVE", "LINPAR_QUEUE", "LINPAR_CACHE", "LINPAR_EFFECTS"):
        monkeypatch.delenv(variable, raising=False)


def test_without_variables_the_folders_are_the_platforms(no_overrides):
    data = Path(platformdirs.user_data_dir("linpar", appauthor=False))
    cache = Path(platformdirs.user_cache_dir("linpar", appauthor=False))
    assert default_root() == data / "archive"
    assert queue_folder("srv") == data / "queue" / "srv"
    assert cache_dir() == cache and server_cache("srv") == cache / "archive" / "srv"
    assert config_folder.config_folder() == Path(platformdirs.user_config_dir("linpar", appauthor=False,
                                                                              roaming=True))


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the XDG variables are Linux's")
def test_on_linux_the_xdg_variables_move_them(no_overrides, monkeypatch, tmp_path):
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    assert default_root() == tmp_path / "data" / "linpar" / "archive"
    assert cache_dir() == tmp_path / "cache" / "linpar"


def test_the_environment_overrides_each(no_overrides, monkeypatch, tmp_path):
    monkeypatch.setenv("LINPAR_ARCHIVE", str(tmp_path / "a"))
    monkeypatch.setenv("LINPAR_QUEUE", str(tmp_path / "q"))
    monkeypatch.setenv("LINPAR_CACHE", str(tmp_path / "c"))
    assert default_root() == tmp_path / "a"
    assert queue_folder("srv") == tmp_path / "q" / "srv"
    assert cache_dir() == tmp_path / "c" and server_cache("srv") == tmp_path / "c" / "archive" / "srv"
    monkeypatch.setenv("LINPAR_CACHE", "  ")            # blank: as if unset
    assert cache_dir() == Path(platformdirs.user_cache_dir("linpar", appauthor=False))


def test_the_macos_folders_are_where_mac_programs_keep_theirs():
    mac = platformdirs.macos.MacOS("linpar", appauthor=False)
    assert mac.user_data_dir.endswith("Library/Application Support/linpar")
    assert mac.user_cache_dir.endswith("Library/Caches/linpar")
