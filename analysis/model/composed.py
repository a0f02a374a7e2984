"""The lumped loudspeaker model (docs/physics.md section 1), composed with effects.

    Ze(s) = RE + s*LE + sum(blocked effects)
    Y(s)  = s*CMES + 1/RES + 1/(s*LCES*c(s)) + sum(mechanical effects)   c(s): product of compliance factors
    ZR(s) = 1 / Y(s)
    g(s)  = prod(force-factor effects)                                   1 without any
    Zd(s) = Ze + g^2 * ZR                                                the driver's own impedance
    Z(s)  = Zd * prod(current-channel factors)
    Hx(s) = g * ZR / (Zd * Bl * s) * prod(displacement-channel factors)

The motional branch is written as an admittance so that mechanical effects
(which add to Zm, and Y = Zm / Bl^2) simply add. Bl only scales Hx. A
force-factor effect multiplies Bl in the force and in the back-EMF alike
(docs/physics.md section 8: U = Ze*I + g*Bl*v, g*Bl*I = Zm*v), hence g^2 in Z and
g in Hx; with g = 1 Hx is the textbook ZR / (ZR + Ze) / (Bl*s).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable, Mapping

import numpy as np

from analysis.effects.base import Effect, ParamSpec, Site
from analysis.errors import LinparError
from analysis.model import response_memo

# The textbook model without extra effects: the lumped elements of docs/physics.md section 1.
BASE_PARAMS: tuple[ParamSpec, ...] = (
    ParamSpec("RE", "ohm", "ohm", 1.0, 1e-3, 1e3, 6.0, "voice-coil DC resistance"),
    ParamSpec("LE", "H", "mH", 1e3, 0.0, 1.0, 1e-4, "voice-coil inductance"),
    ParamSpec("CMES", "F", "uF", 1e6, 1e-9, 10.0, 4e-4, "moving mass seen from the terminals (Mms / Bl^2)"),
    ParamSpec("LCES", "H", "mH", 1e3, 1e-7, 100.0, 1e-2, "compliance seen from the terminals (Cms * Bl^2)"),
    ParamSpec("RES", "ohm", "ohm", 1.0, 1e-3, 1e6, 20.0, "mechanical losses seen from the terminals (Bl^2 / Rms)"),
)
BL_PARAM = ParamSpec("Bl", "T*m", "T*m", 1.0, 1e-3, 1e3, 5.0, "force factor")
ELECTRICAL_BASE = tuple(p.name for p in BASE_PARAMS)


class ModelError(LinparError, ValueError):
    """A model that cannot be composed (unknown effect, two effects of one category, a name collision)."""


@dataclass(frozen=True)
class Model:
    """The base lumped model plus effects, at most one per category."""

    effects: tuple[Effect, ...] = ()
    with_displacement: bool = True
    # The effects at each site, worked out once: a fit evaluates the model tens of thousands of times.
    _by_site: dict = field(init=False, repr=False, compare=False, default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_by_site", {site: tuple(e for e in self.effects if e.site is site) for site in Site})
        seen_categories: dict[str, str] = {}
        seen_names = {p.name for p in self.base_params}
        for effect in self.effects:
            if effect.category in seen_categories:
                raise ModelError(
                    f"effects {seen_categories[effect.category]!r} and {effect.id!r} are both of category "
                    f"{effect.category!r}: keep one (swap instead of adding)")
            seen_categories[effect.category] = effect.id
            if effect.needs_bl and not self.with_displacement:
                raise ModelError(f"effect {effect.id!r} acts in kg/s or kg on the mechanical impedance, which needs "
                                 "Bl: without the laser's displacement Bl is unknown")
            for name in effect.param_names:
                if name in seen_names:
                    raise ModelError(f"effect {effect.id!r} adds parameter {name!r}, which the model already has")
                seen_names.add(name)

    @property
    def base_params(self) -> tuple[ParamSpec, ...]:
        return BASE_PARAMS + ((BL_PARAM,) if self.with_displacement else ())

    @property
    def param_specs(self) -> tuple[ParamSpec, ...]:
        specs = list(self.base_params)
        for effect in self.effects:
            if effect.site is Site.DISPLACEMENT and not self.with_displacement:
                continue
            specs.extend(effect.params)
        return tuple(specs)

    @property
    def effect_ids(self) -> tuple[str, ...]:
        return tuple(e.id for e in self.effects)

    def spec(self, name: str) -> ParamSpec:
        for p in self.param_specs:
            if p.name == name:
                return p
        raise KeyError(name)

    def with_effects(self, effects: Iterable[Effect]) -> "Model":
        return Model(tuple(effects), self.with_displacement)

    def _site(self, site: Site) -> tuple[Effect, ...]:
        return self._by_site[site]

    def blocked_impedance(self, s: np.ndarray, p: Mapping[str, float]) -> np.ndarray:
        memo = response_memo.for_model(self, s)
        Ze = p["RE"] + s * p["LE"]
        for effect in self._site(Site.BLOCKED):
            Ze = Ze + memo.response(effect, s, p)
        return Ze

    def motional_compliance_factor(self, s: np.ndarray, p: Mapping[str, float]) -> np.ndarray | float:
        """c(s): the product of the compliance-site factors (1.0 without any)."""
        memo = response_memo.for_model(self, s)
        compliance = 1.0
        for effect in self._site(Site.COMPLIANCE):
            compliance = compliance * memo.response(effect, s, p)
        return compliance

    def motional_impedance(self, s: np.ndarray, p: Mapping[str, float]) -> np.ndarray:
        compliance = self.motional_compliance_factor(s, p)
        Y = s * p["CMES"] + 1.0 / p["RES"] + 1.0 / (s * p["LCES"] * compliance)
        memo = response_memo.for_model(self, s)
        for effect in self._site(Site.MECHANICAL):
            Y = Y + memo.response(effect, s, p)
        return 1.0 / Y

    def force_factor(self, s: np.ndarray, p: Mapping[str, float]) -> np.ndarray | None:
        """g(s), the factor on Bl; None when no effect acts there (g = 1, nothing to multiply)."""
        effects = self._site(Site.FORCE_FACTOR)
        if not effects:
            return None
        memo = response_memo.for_model(self, s)
        g = memo.response(effects[0], s, p)
        for effect in effects[1:]:
            g = g * memo.response(effect, s, p)
        return g

    def driver_impedance(self, s: np.ndarray, p: Mapping[str, float]) -> np.ndarray:
        """Zd = Ze + g^2 * ZR: the driver's impedance, before the current channel sees it."""
        ZR = self.motional_impedance(s, p)
        g = self.force_factor(s, p)
        return self.blocked_impedance(s, p) + (ZR if g is None else g * g * ZR)

    def impedance(self, s: np.ndarray, p: Mapping[str, float]) -> np.ndarray:
        """Z = U / I as the current channel measures it."""
        Z = self.driver_impedance(s, p)
        memo = response_memo.for_model(self, s)
        for effect in self._site(Site.CURRENT):
            Z = Z * memo.response(effect, s, p)
        return Z

    def displacement(self, s: np.ndarray, p: Mapping[str, float]) -> np.ndarray:
        """Hx = X / U as the displacement channel measures it."""
        Ze = self.blocked_impedance(s, p)
        ZR = self.motional_impedance(s, p)
        g = self.force_factor(s, p)
        if g is None:
            Hx = ZR / (ZR + Ze) / (p["Bl"] * s)
        else:
            Hx = g * ZR / (Ze + g * g * ZR) / (p["Bl"] * s)
        memo = response_memo.for_model(self, s)
        for effect in self._site(Site.DISPLACEMENT):
            Hx = Hx * memo.response(effect, s, p)
        return Hx

    def responses(self, s: np.ndarray, p: Mapping[str, float]) -> tuple[np.ndarray, np.ndarray]:
        """(Z, Hx) at the same `s`, the branches worked out once: what a fit of both channels evaluates.

        The same numbers as impedance(s, p) and displacement(s, p), in half the work.
        """
        memo = response_memo.for_model(self, s)
        by_site = self._by_site
        Ze = p["RE"] + s * p["LE"]
        for effect in by_site[Site.BLOCKED]:
            Ze = Ze + memo.response(effect, s, p)
        compliance = 1.0
        for effect in by_site[Site.COMPLIANCE]:
            compliance = compliance * memo.response(effect, s, p)
        Y = s * p["CMES"] + 1.0 / p["RES"] + 1.0 / (s * p["LCES"] * compliance)
        for effect in by_site[Site.MECHANICAL]:
            Y = Y + memo.response(effect, s, p)
        ZR = 1.0 / Y
        g = self.force_factor(s, p)
        Zd = Ze + (ZR if g is None else g * g * ZR)
        Z = Zd
        for effect in by_site[Site.CURRENT]:
            Z = Z * memo.response(effect, s, p)
        Hx = (ZR if g is None else g * ZR) / Zd / (p["Bl"] * s)
        for effect in by_site[Site.DISPLACEMENT]:
            Hx = Hx * memo.response(effect, s, p)
        return Z, Hx

    def describe(self) -> str:
        return ",".join(self.effect_ids) if self.effects else "textbook"

