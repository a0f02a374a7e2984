"""Whether an installed package may declare entry points of a group, read without importing importlib.metadata.

importlib.metadata finds entry points in the entry_points.txt of each *.dist-info and *.egg-info folder of
every sys.path folder (and in the EGG-INFO of an .egg folder). Importing it (email, zipfile, csv ...) and
its scan cost each start of a command that fits 10-15 ms of CPU time, to learn, nearly always, that no
package ships an effect; reading the files takes about 1 ms. Those files' text answers the same question
first: when none names the group, importlib.metadata finds none either. Where this reading does not look as
importlib.metadata would (a zip archive on sys.path, another finder that lists distributions, a file it
cannot read), the answer is "maybe" and the caller asks importlib.metadata itself.
"""
from __future__ import annotations

import os
import sys
from importlib.machinery import PathFinder

METADATA_FOLDERS = (".dist-info", ".egg-info")


def may_declare(group: str) -> bool:
    """False only when no entry_points.txt that importlib.metadata reads names `group`."""
    if any(hasattr(finder, "find_distributions") and finder is not PathFinder for finder in sys.meta_path):
        return True
    for entry in sys.path:
        folder = entry or "."
        try:
            names = os.listdir(folder)
        except NotADirectoryError:      # a zip archive, which importlib.metadata reads inside
            return True
        except OSError:                 # not there: importlib.metadata finds nothing in it either
            continue
        metadata = [n for n in names if n.lower().endswith(METADATA_FOLDERS)]
        if os.path.basename(folder).lower().endswith(".egg"):
            metadata += [n for n in names if n.lower() == "egg-info"]
        if any(_may_name(os.path.join(folder, name, "entry_points.txt"), group) for name in metadata):
            return True
    return False


def _may_name(path: str, group: str) -> bool:
    try:
        with open(path, encoding="utf-8") as file:
            return group in file.read()
    except (FileNotFoundError, NotADirectoryError):     # no entry points (or an .egg-info file, not a folder)
        return False
    except (OSError, ValueError):                       # unreadable here: let importlib.metadata say
        return True
