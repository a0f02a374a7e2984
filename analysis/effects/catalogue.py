"""The built-in effects, by id: every effect the model lab can add (analysis.effects finds them by id)."""
from __future__ import annotations

from analysis.effects import breakup, channels, creep, creep_at_fs, enclosure, forcefactor, inductance, mechanical
from analysis.effects.base import Effect

# Grouped by category; within a category the effects are alternatives (one per model).
_ALL: tuple[Effect, ...] = (
    inductance.lr2,
    inductance.lr3,
    inductance.leach,
    inductance.wright,
    creep.creep_log,
    creep.creep_log_causal,
    creep.creep_3p,
    creep.creep_fractional,
    creep.creep_rs,
    creep.creep_kv,
    creep.creep_zener,
    channels.delay_current,
    channels.lowpass_current,
    channels.delay_x,
    channels.lowpass_x,
    channels.lowpass2_x,
    breakup.breakup,
    breakup.breakup_spot,
    breakup.breakup_coil,
    forcefactor.bl_eddy,
    mechanical.air_load,
    mechanical.damping_power,
    enclosure.closed_box,
    enclosure.vented_box,
    enclosure.vented_box_absorption,
    enclosure.vented_box_port,
)

CATALOGUE: dict[str, Effect] = {e.id: e for e in _ALL}

# Forms a fit uses by id that the catalogue leaves out: the same physics as one of its effects, re-expressed
# (the Model lab and the diagnosis, which try the catalogue, would find them equal to it).
FORMS: dict[str, Effect] = {e.id: e for e in (creep_at_fs.creep_log_causal_at_fs,)}
