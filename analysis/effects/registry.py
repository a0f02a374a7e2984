"""Effects beyond the built-in catalogue: the user's files and Python packages, found and registered.

Three sources, read in this order (a later one may not reuse an id or a parameter name):

1. the user folder: every *.toml in $LINPAR_EFFECTS, else in effects/ of the platform's configuration
   folder (~/.config/linpar/effects on Linux, %APPDATA%\\linpar\\effects on Windows,
   ~/Library/Application Support/linpar/effects on macOS); a folder that does not exist holds none;
2. files named on the command line (--effects-file FILE, repeatable);
3. the entry points of the group `linpar.effects` of installed packages (importlib.metadata): each
   names an Effect, a sequence of them, or a callable returning either. importlib.metadata is imported
   only when a package's metadata names the group (analysis.effects.entry_point_files), and the effect
   files' reader (analysis.effects.user) only when there are files: most starts need neither.

The registry is the process's list of these, as pytest's plugin manager is: the CLI and the GUI fill
it once at start (the GUI again when the user saves a new effect); analysis.effects.get_effect and the
diagnosis read it beside the catalogue. Worker processes need none of it: a model travels to them
with its effect objects.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Callable, Iterable, Sequence

from analysis.config_folder import EFFECTS_FOLDER_ENV, config_folder
from analysis.effects.base import Effect, ParamSpec
from analysis.effects.entry_point_files import may_declare
from analysis.effects.file_error import EffectFileError

ENTRY_POINT_GROUP = "linpar.effects"
FOLDER_ENV = EFFECTS_FOLDER_ENV

_USER: dict[str, Effect] = {}      # by id, in the order loaded
_PACKAGE_SOURCES: dict[str, str] = {}   # id -> the entry point an effect of a package came from


def user_folder() -> Path:
    env = os.environ.get(FOLDER_ENV)
    return Path(env).expanduser() if env else config_folder() / "effects"


def user_effects() -> tuple[Effect, ...]:
    return tuple(_USER.values())


def register(effects: Iterable[Effect]) -> None:
    """Add effects to the process's registry (ids already registered are replaced by the newer)."""
    for effect in effects:
        _USER[effect.id] = effect


def clear() -> None:
    _USER.clear()


def _builtin_names() -> tuple[dict[str, str], frozenset[str]]:
    """Parameter names in use (with their owner, for messages) and effect ids of the built-in catalogue."""
    from analysis.effects.catalogue import CATALOGUE
    from analysis.model.composed import BASE_PARAMS, BL_PARAM
    taken = {p.name: "the base model" for p in (*BASE_PARAMS, BL_PARAM)}
    for effect in CATALOGUE.values():
        for p in effect.params:
            taken.setdefault(p.name, f"the catalogue's {effect.id}")
    return taken, frozenset(CATALOGUE)


def _claim(effect: Effect, source: str, taken: dict[str, str], ids: set[str]) -> None:
    if effect.id in ids:
        raise EffectFileError(f"{source}: id: {effect.id!r} is already an effect; choose another id")
    ids.add(effect.id)
    for p in effect.params:
        taken.setdefault(p.name, f"{effect.id} ({source})")


def _folder_files(folder: Path) -> list[Path]:
    if not folder.exists():
        return []
    if not folder.is_dir():
        raise EffectFileError(f"{folder}: the effects folder (${FOLDER_ENV} or the configuration folder) is not "
                              "a folder")
    try:
        return sorted(p for p in folder.iterdir() if p.suffix.lower() == ".toml")
    except OSError as exc:
        raise EffectFileError(f"{folder}: the effects folder cannot be read ({exc.strerror or exc})") from None


def _entry_point_effects(in_use: Callable[[], tuple[dict[str, str], set[str]]]) -> list[Effect]:
    """The effects of the packages' entry points; `in_use()` gives the names and ids they may not reuse."""
    if not may_declare(ENTRY_POINT_GROUP):
        return []
    taken, ids = in_use()
    import importlib.metadata
    found = []
    for ep in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
        source = f"entry point {ep.name} = {ep.value} ({ENTRY_POINT_GROUP})"
        try:
            obj = ep.load()
            if callable(obj) and not isinstance(obj, Effect):
                obj = obj()
        except Exception as exc:      # a third-party package's import: its failure is input, not a linpar bug
            raise EffectFileError(f"{source}: cannot be loaded ({type(exc).__name__}: {exc})") from None
        effects = [obj] if isinstance(obj, Effect) else list(obj) if isinstance(obj, (list, tuple)) else None
        if effects is None or not all(isinstance(e, Effect) for e in effects):
            raise EffectFileError(f"{source}: expected an analysis.effects.Effect, a list of them, or a callable "
                                  "returning either")
        for effect in effects:
            for p in effect.params:
                if p.name in taken and not taken[p.name].endswith(f"({source})"):
                    raise EffectFileError(f"{source}: parameter {p.name!r} of {effect.id!r} is already a parameter "
                                          f"of {taken[p.name]}; rename it")
            _claim(effect, source, taken, ids)
            _PACKAGE_SOURCES[effect.id] = source
            found.append(effect)
    return found


def load_user_effects(files: Sequence[str | Path] = (), folder: Path | None = None, packages: bool = True,
                      problems: list[str] | None = None) -> tuple[Effect, ...]:
    """Every effect of the user folder (default: user_folder()), of `files` and of installed packages.

    Raises EffectFileError (one line naming the file) on the first that cannot be used; with a `problems`
    list (the GUI's way), its line is added there and the file is left out instead. Nothing is
    registered: pass the result to register().
    """
    # The names and ids in use, made when a file or a package first needs them: they import the whole
    # catalogue, which a command without effects of the user's own does not load (analysis.effects.catalogue).
    names: list[tuple[dict[str, str], set[str]]] = []

    def in_use() -> tuple[dict[str, str], set[str]]:
        if not names:
            taken, builtin_ids = _builtin_names()
            names.append((taken, set(builtin_ids)))
        return names[0]

    loaded: list[Effect] = []
    seen: set[Path] = set()

    def attempt(load):
        try:
            return load()
        except EffectFileError as exc:
            if problems is None:
                raise
            problems.append(str(exc))
            return None

    paths = attempt(lambda: _folder_files(user_folder() if folder is None else folder)) or []
    for path in [*paths, *map(Path, files)]:
        key = path.resolve() if path.exists() else path
        if key in seen:
            continue
        seen.add(key)
        from analysis.effects.user import load_effect_file
        taken, ids = in_use()
        effect = attempt(lambda: load_effect_file(path, taken, frozenset(ids)))
        if effect is not None:
            _claim(effect, str(path), taken, ids)
            loaded.append(effect)
    if packages:
        loaded += attempt(lambda: _entry_point_effects(in_use)) or []
    return tuple(loaded)


def taken_names() -> tuple[dict[str, str], frozenset[str]]:
    """Parameter names (with their owner) and effect ids in use by the catalogue and the registered effects:
    what a new effect must not reuse."""
    taken, ids = _builtin_names()
    for effect in _USER.values():
        for p in effect.params:
            taken.setdefault(p.name, f"{effect.id} ({source_of(effect)})")
    return taken, ids | frozenset(_USER)


def save_effect_file(text: str, effect_id: str, folder: Path | None = None) -> Path:
    """Write an effect file's text to the user folder as ID.toml, atomically; the path written."""
    from analysis.archive.atomic import write_atomic
    folder = user_folder() if folder is None else folder
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{effect_id}.toml"
    if path.exists() and not path.is_file():
        raise EffectFileError(f"{path}: not a regular file; the effect was not saved")
    write_atomic(path, text)
    return path


def source_of(effect: Effect) -> str:
    """The file or entry point an effect came from ('' for the built-in catalogue)."""
    return _PACKAGE_SOURCES.get(effect.id) or getattr(effect, "source", "")


def is_user_effect(effect: Effect) -> bool:
    if effect.id in _USER:
        return True
    # Not imported, no UserEffect can exist: the Model lab asks this of the candidate a first diagnosis selects,
    # and the module's import (tomllib, the formula parser: 17 ms) held the GUI thread in that turn.
    user = sys.modules.get("analysis.effects.user")
    return user is not None and isinstance(effect, user.UserEffect)


__all__ = ["ENTRY_POINT_GROUP", "FOLDER_ENV", "EffectFileError", "ParamSpec", "clear", "config_folder",
           "is_user_effect", "load_user_effects", "register", "save_effect_file",
           "source_of", "taken_names", "user_effects", "user_folder"]
