"""The built-in effects, by id: every effect the model lab can add (analysis.effects finds them by id).

Each is named here with the module of analysis.effects that defines it, and that module is imported when one
of its effects is first asked for: a fit of the default model loads inductance.py and creep.py, not the
enclosures (and their start values), the break-up, the channels' delays ... Each module made the catalogue's
Effect and ParamSpec objects at every start (about 12 M instructions, 2-3 ms of `linpar analyze`). CATALOGUE
and FORMS, which need them all, are made on first use (PEP 562 below).
"""
from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from analysis.effects.base import Effect

# (id, module of analysis.effects, the name it has there). Grouped by category; within a category the effects
# are alternatives (one per model). This order is the catalogue's: the Model lab's and the diagnosis's.
_ALL: tuple[tuple[str, str, str], ...] = (
    ("lr2", "inductance", "lr2"),
    ("lr3", "inductance", "lr3"),
    ("leach", "inductance", "leach"),
    ("wright", "inductance", "wright"),
    ("creep-log", "creep", "creep_log"),
    ("creep-log-causal", "creep", "creep_log_causal"),
    ("creep-3p", "creep", "creep_3p"),
    ("creep-fractional", "creep", "creep_fractional"),
    ("creep-rs", "creep", "creep_rs"),
    ("creep-kv", "creep", "creep_kv"),
    ("creep-zener", "creep", "creep_zener"),
    ("delay-current", "channels", "delay_current"),
    ("lowpass-current", "channels", "lowpass_current"),
    ("delay-x", "channels", "delay_x"),
    ("lowpass-x", "channels", "lowpass_x"),
    ("lowpass2-x", "channels", "lowpass2_x"),
    ("breakup", "breakup", "breakup"),
    ("breakup-spot", "breakup", "breakup_spot"),
    ("breakup-coil", "breakup", "breakup_coil"),
    ("bl-eddy", "forcefactor", "bl_eddy"),
    ("air-load", "mechanical", "air_load"),
    ("damping-power", "mechanical", "damping_power"),
    ("closed-box", "enclosure", "closed_box"),
    ("vented-box", "enclosure", "vented_box"),
    ("vented-box-absorption", "enclosure", "vented_box_absorption"),
    ("vented-box-port", "enclosure", "vented_box_port"),
)

# Forms a fit uses by id that the catalogue leaves out: the same physics as one of its effects, re-expressed
# (the Model lab and the diagnosis, which try the catalogue, would find them equal to it).
_FORMS: tuple[tuple[str, str, str], ...] = (
    ("creep-log-causal-fs", "creep_at_fs", "creep_log_causal_at_fs"),
)

_HOMES = {effect_id: (module, name) for effect_id, module, name in _ALL}
_FORM_HOMES = {effect_id: (module, name) for effect_id, module, name in _FORMS}

IDS: tuple[str, ...] = tuple(_HOMES)        # the catalogue's ids, in its order, without importing an effect


def _loaded(module: str, name: str) -> Effect:
    return getattr(import_module(f"analysis.effects.{module}"), name)


def built_in(effect_id: str) -> Effect | None:
    """The catalogue's effect of that id, else the form of that id (FORMS), else None; only its module is
    imported."""
    home = _HOMES.get(effect_id) or _FORM_HOMES.get(effect_id)
    return None if home is None else _loaded(*home)


def __getattr__(name: str):
    """CATALOGUE (id -> Effect, in the catalogue's order) and FORMS, their modules imported on first use; then
    module attributes like any other (one dict, even when two threads ask first at once: treat it as
    read-only)."""
    entries = {"CATALOGUE": _ALL, "FORMS": _FORMS}.get(name)
    if entries is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return globals().setdefault(name, {effect_id: _loaded(module, attr) for effect_id, module, attr in entries})
