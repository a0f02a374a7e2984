"""The virtual rig: a simulated amplifier, driver and sensors behind a JACK server of its own.

``RigEngine`` is the analog chain (no JACK); ``instruments.rig.jack_rig`` runs
it in a JACK client; ``instruments.rig.server`` is the rig process
(``python -m instruments.rig.server``); ``instruments.rig.manager`` starts,
finds and stops it (``linpar rig``). Only the engine is imported here: JACK
is loaded by the rig process alone.
"""
from instruments.rig.engine import (
    RIG_CALIBRATION, RIG_CHANNEL_MAP, RigEngine, RigFaults, RigNoise, RigOutputs, default_driver)

__all__ = ["RIG_CALIBRATION", "RIG_CHANNEL_MAP", "RigEngine", "RigFaults", "RigNoise", "RigOutputs",
           "default_driver"]
