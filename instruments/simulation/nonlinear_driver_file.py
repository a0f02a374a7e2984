"""A driver file's "nonlinear" curves (analysis.drivers keeps them in DriverDefinition.extra) as a
NonlinearBlockDriver: what `linpar rig start --model nonlinear --driver FILE` simulates.

    {"name": "...", "parameters": {...},
     "nonlinear": {"bl_poly": [b1, b2], "kms_poly": [k1, k2], "le_poly": [...], "l2_poly": [...],
                   "le_i_poly": [c1, c2], "rms_v2": r2, "x_range_m": 0.008, "i_range_a": 20}}

The polynomials are relative, in ascending powers of x in metres from x^1
(instruments/simulation/nonlinear_driver.py); each key is optional. A file
whose curves cannot be simulated is one line (DriverShapeError).
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from analysis.errors import LinparError
from instruments.simulation.nonlinear_driver import NonlinearBlockDriver


class DriverShapeError(LinparError, ValueError):
    """A driver file's "nonlinear" curves that cannot be simulated (unknown keys, not numbers, a curve not
    positive, too steep for the step). One line."""


def nonlinear_driver_of(definition, sample_rate: int, **options) -> NonlinearBlockDriver:
    """The NonlinearBlockDriver of an analysis.drivers.DriverDefinition, its "nonlinear" curves included;
    DriverShapeError (one line naming the driver) for curves it cannot simulate."""
    try:
        return NonlinearBlockDriver(dict(definition.parameters), sample_rate,
                                    **{**options_from(definition.extra), **options})
    except ValueError as exc:
        raise DriverShapeError(f"driver {definition.name!r}: {exc}") from None


def options_from(definition_extra: Mapping) -> dict:
    """NonlinearBlockDriver's shape arguments from a driver file's "nonlinear" object (analysis.drivers keeps it
    in DriverDefinition.extra); {} without one. ValueError (one line) for what is not a shape."""
    spec = definition_extra.get("nonlinear") if definition_extra else None
    if spec is None:
        return {}
    if not isinstance(spec, Mapping):
        raise ValueError("the driver file's 'nonlinear' must be an object of polynomials (bl_poly, kms_poly, ...)")
    lists = ("bl_poly", "kms_poly", "le_poly", "l2_poly", "le_i_poly")
    numbers = ("rms_v2", "x_range_m", "i_range_a")
    unknown = sorted(set(spec) - set(lists) - set(numbers))
    if unknown:
        raise ValueError(f"the driver file's 'nonlinear' has unknown keys {', '.join(unknown)}; "
                         f"known: {', '.join(lists + numbers)}")
    out = {}
    for key, value in spec.items():
        if key in lists:
            if not isinstance(value, list) or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                      for v in value):
                raise ValueError(f"the driver file's nonlinear.{key}: expected a list of numbers")
            out[key] = tuple(float(v) for v in value)
        else:
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not np.isfinite(value):
                raise ValueError(f"the driver file's nonlinear.{key}: expected a finite number")
            out[key] = float(value)
    return out
