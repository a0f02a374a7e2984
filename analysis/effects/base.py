"""What an effect is: a small object that adds physics to the lumped model.

An effect names its parameters, says where in the model it acts (its site),
and returns one complex frequency response there. The model (analysis.model)
composes the base lumped model with any number of effects, one per category.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING, Mapping

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from analysis.startvalues import StartContext


class Site(Enum):
    """Where an effect's response enters the model (see analysis.model.evaluate)."""

    BLOCKED = "blocked electrical impedance"      # added to Ze = RE + s*LE
    COMPLIANCE = "compliance"                     # multiplies Cms (so LCES) by a factor
    MECHANICAL = "mechanical impedance"           # added to Zm / Bl^2 (the motional admittance)
    CURRENT = "current channel"                   # multiplies the measured Z = U / I
    DISPLACEMENT = "displacement channel"         # multiplies the measured Hx = X / U


@dataclass(frozen=True, slots=True)
class ParamSpec:
    """One fitted parameter: SI unit in code, customary unit at the edge."""

    name: str
    unit: str
    display_unit: str
    display_scale: float       # display value = SI value * display_scale
    min: float
    max: float
    default: float             # start value when the data give no better guess
    description: str


@dataclass(frozen=True)
class Effect:
    """One physical effect the lumped model may lack.

    Subclasses implement `response` (and `guess` when the data say more than
    the default start values). The docstring of each subclass carries its
    equations.
    """

    id: str
    category: str
    title: str
    site: Site
    params: tuple[ParamSpec, ...]
    physics: str               # what it is, for a technician
    signature: str             # the residual it cures
    typical: str               # typical values
    reference: str             # literature
    notes: str = ""
    # Effects whose parameters this one needs (e.g. creep needs fs): none by default.
    requires: tuple[str, ...] = field(default=())

    @property
    def param_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.params)

    def response(self, s: np.ndarray, p: Mapping[str, float]) -> np.ndarray:
        raise NotImplementedError

    def guess(self, ctx: "StartContext") -> dict[str, float]:
        """Start values from the data; the defaults when nothing better is known."""
        return {spec.name: spec.default for spec in self.params}

    def starts(self, ctx: "StartContext") -> list[dict[str, float]]:
        """Start values to try in turn when one is not enough (a narrow resonance); the lowest chi^2 wins."""
        return [self.guess(ctx)]

    def describe(self) -> dict:
        """The catalogue entry as plain data (for the CLI, the GUI and reports)."""
        return {
            "id": self.id,
            "category": self.category,
            "title": self.title,
            "acts_on": self.site.value,
            "parameters": [
                {"name": p.name, "unit": p.unit, "display_unit": p.display_unit, "display_scale": p.display_scale,
                 "min": p.min, "max": p.max, "default": p.default, "description": p.description}
                for p in self.params
            ],
            "physics": self.physics,
            "signature": self.signature,
            "typical": self.typical,
            "reference": self.reference,
            "notes": self.notes,
        }
