"""The effects a fit uses when none are named.

Kept apart from the catalogue (analysis.effects, which loads scipy) so that the
command line's help can say the defaults without loading the models.
"""
from __future__ import annotations

DEFAULT_EFFECTS = ("lr2", "creep-log")
# The impedance-only fits need the semi-inductance: with LR-2 the blocked
# impedance of real coils leaks into RE and the motional branch (SEAS L16RNX:
# Bl 4 % low over 10 Hz-20 kHz with lr2,creep-log; within 1 % with this).
ADDED_MASS_EFFECTS = ("leach", "creep-log-causal")
