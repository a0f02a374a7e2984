"""Small formulas of the lumped model that effects need without importing the model."""
from __future__ import annotations

from typing import Mapping

import numpy as np

RHO = 1.18        # kg/m^3, air at 20 C (docs/physics.md section 3)
C_SOUND = 343.0   # m/s


def resonance_frequency(p: Mapping[str, float]) -> float:
    """fs = 1 / (2*pi*sqrt(CMES*LCES)) = 1 / (2*pi*sqrt(Mms*Cms))."""
    return 1.0 / (2.0 * np.pi * np.sqrt(p["CMES"] * p["LCES"]))
