"""linpar's folder in the platform's configuration folder, and where the user's own effects live.

Apart from analysis.effects.registry, which reads the effects, so that the command line can name the folder
in its help without loading the effects catalogue (and scipy) at every start.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

EFFECTS_FOLDER_ENV = "LINPAR_EFFECTS"


def config_folder() -> Path:
    """linpar's folder in the platform's configuration folder."""
    if sys.platform == "win32":
        base = Path(os.environ.get("APPDATA") or Path.home() / "AppData" / "Roaming")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Application Support"
    else:
        base = Path(os.environ.get("XDG_CONFIG_HOME") or Path.home() / ".config")
    return base / "linpar"
