"""Small formulas of the lumped model that effects need without importing the model."""
from __future__ import annotations

from typing import Mapping

import numpy as np


def resonance_frequency(p: Mapping[str, float]) -> float:
    """fs = 1 / (2*pi*sqrt(CMES*LCES)) = 1 / (2*pi*sqrt(Mms*Cms))."""
    return 1.0 / (2.0 * np.pi * np.sqrt(p["CMES"] * p["LCES"]))
