"""What an effect is: a small object that adds physics to the lumped model.

An effect names its parameters, says where in the model it acts (its site),
and returns one complex frequency response there. The model (analysis.model.composed)
composes the base lumped model with any number of effects, one per category.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING, Mapping

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from analysis.fit.startvalues import StartContext


class Site(Enum):
    """Where an effect's response enters the model (docs/physics.md section 8; analysis.model.composed composes them).

    The member's `key` is the site's name in files, JSON and on screen: the
    same six names are the sites of the catalogue, of the site localisation
    (analysis.diagnosis.sites) and of effects of the user's own.
    """

    BLOCKED = "blocked electrical impedance"      # added to Ze = RE + s*LE (ohm)
    FORCE_FACTOR = "force factor"                 # multiplies Bl, in the force and the back-EMF alike
    MECHANICAL = "mechanical impedance"           # added to Zm / Bl^2 (the motional admittance)
    COMPLIANCE = "compliance"                     # multiplies Cms (so LCES) by a factor
    CURRENT = "current channel"                   # multiplies the measured Z = U / I
    DISPLACEMENT = "displacement channel"         # multiplies the measured Hx = X / U

    # Members are singletons: hashed by identity, not by Enum's Python-level hash of the name (a fit looks
    # the model's effects up by site hundreds of thousands of times).
    __hash__ = object.__hash__

    @property
    def key(self) -> str:
        return SITE_KEYS[self]

    @classmethod
    def from_key(cls, key: str) -> "Site":
        for site, name in SITE_KEYS.items():
            if name == key:
                return site
        raise KeyError(f"unknown site {key!r}; the sites are: {', '.join(SITE_KEYS.values())}")


SITE_KEYS = {Site.BLOCKED: "electrical", Site.FORCE_FACTOR: "force-factor", Site.MECHANICAL: "mechanical",
             Site.COMPLIANCE: "compliance", Site.CURRENT: "current", Site.DISPLACEMENT: "displacement"}


# A parameter this close (relative to its size) to a bound is "on" it.
AT_BOUND_RELATIVE = 1e-6


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
    # Where the value usually lies (SI); the diagnosis flags a fit that ends outside. None: no range.
    typical: tuple[float, float] | None = None

    def on_bound(self, value: float) -> bool:
        """True when `value` sits on a bound (within AT_BOUND_RELATIVE of the value's size)."""
        scale = max(abs(self.default), abs(value), 1e-300)
        return value - self.min <= AT_BOUND_RELATIVE * scale or self.max - value <= AT_BOUND_RELATIVE * scale

    def within_typical(self, value: float) -> bool:
        """True when `value` lies in the typical range, or no range is given."""
        return self.typical is None or self.typical[0] <= value <= self.typical[1]

    def typical_text(self) -> str:
        """'0.01 to 10 mH': the typical range in display units, for the catalogue and flags."""
        if self.typical is None:
            return ""
        lo, hi = (v * self.display_scale for v in self.typical)
        unit = "" if self.display_unit in ("-", "1") else f" {self.display_unit}"
        return f"{lo:.4g} to {hi:.4g}{unit}"


@dataclass(frozen=True)
class Effect:
    """One physical effect the lumped model may lack.

    Subclasses implement `response` (and `guess` when the data say more than
    the default start values). The docstring of each subclass carries its
    equations. A subclass that adds no field is a plain class: it inherits
    the methods generated here, and a @dataclass of its own would generate
    them again at every start (~0.4 ms a class, 10 ms of the catalogue).
    Its fields stay frozen; an attribute that is not a field could be added
    to such an instance (the generated __setattr__ refuses it only on Effect
    itself), and nothing does.
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
    # True when a model that lacks this effect bends every other parameter to imitate it (a channel
    # delay): far from the data, the diagnosis then also refits it from the data's own start values,
    # not only from the bent fit, and keeps the better.
    cold_start: bool = False

    @property
    def param_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.params)

    @property
    def needs_bl(self) -> bool:
        """True when the response needs Bl (kg/s or kg turned into the model's admittance Zm / Bl^2): without
        the laser Bl is unknown, so the effect needs the displacement channel."""
        return False

    @property
    def needs_displacement(self) -> bool:
        return self.site is Site.DISPLACEMENT or self.needs_bl

    def check_finite(self, s: np.ndarray, p: Mapping[str, float], where: str) -> None:
        """Raise a ValueError naming the effect when its response is not finite at `s` (effects of the
        user's own check their formula; the catalogue's equations are tested instead)."""

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
            "site": self.site.key,
            "parameters": [
                {"name": p.name, "unit": p.unit, "display_unit": p.display_unit, "display_scale": p.display_scale,
                 "min": p.min, "max": p.max, "default": p.default, "description": p.description,
                 "typical": list(p.typical) if p.typical else None}
                for p in self.params
            ],
            "physics": self.physics,
            "signature": self.signature,
            "typical": self.typical,
            "reference": self.reference,
            "notes": self.notes,
        }
