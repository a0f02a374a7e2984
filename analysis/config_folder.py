"""linpar's folders in the platform's own places (platformdirs); an environment variable overrides each.

    what                        variable          Linux                     macOS                                Windows
    configuration (effects)     $LINPAR_EFFECTS   ~/.config/linpar          ~/Library/Application Support/linpar %APPDATA%\\linpar
    data (archive, queue)       $LINPAR_ARCHIVE,  ~/.local/share/linpar     ~/Library/Application Support/linpar %LOCALAPPDATA%\\linpar
                                $LINPAR_QUEUE
    cache (crash reports,       $LINPAR_CACHE     ~/.cache/linpar           ~/Library/Caches/linpar              %LOCALAPPDATA%\\linpar\\Cache
    server files)

On Linux the XDG variables ($XDG_CONFIG_HOME, $XDG_DATA_HOME, $XDG_CACHE_HOME) move them, as they should.
Apart from analysis.effects.registry, which reads the effects, so that the command line can name the folders
in its help without loading the effects catalogue (and scipy) at every start. No Qt: analysis/ never loads it.
"""
from __future__ import annotations

import os
from pathlib import Path

import platformdirs

APP = "linpar"
EFFECTS_FOLDER_ENV = "LINPAR_EFFECTS"
CACHE_ENV = "LINPAR_CACHE"


def config_folder() -> Path:
    """linpar's folder in the platform's configuration folder (roaming on Windows: it holds the user's effects)."""
    return Path(platformdirs.user_config_dir(APP, appauthor=False, roaming=True))


def data_folder() -> Path:
    """linpar's folder for what it keeps (the measurement archive, a station's queue); local, never roaming."""
    return Path(platformdirs.user_data_dir(APP, appauthor=False))


def cache_folder() -> Path:
    """$LINPAR_CACHE, else linpar's folder in the platform's cache folder (crash reports, files fetched)."""
    return overridden(CACHE_ENV) or Path(platformdirs.user_cache_dir(APP, appauthor=False))


def overridden(variable: str) -> Path | None:
    """The folder an environment variable names (``~`` expanded), or None when it is unset or blank."""
    value = os.environ.get(variable, "").strip()
    return Path(value).expanduser() if value else None
