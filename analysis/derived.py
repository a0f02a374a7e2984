"""Derived parameters with propagated uncertainties (docs/physics.md sections 1 and 3).

    fs  = 1 / (2 pi sqrt(CMES LCES))      Mms = CMES Bl^2     Rms = Bl^2 / RES
    Cms = LCES / Bl^2    Kms = 1 / Cms    Qes = 2 pi fs CMES RE    Qms = 2 pi fs CMES RES
    Qts = Qes Qms / (Qes + Qms)           Vas = rho c^2 Sd^2 Cms
    eta0 = rho Bl^2 Sd^2 / (2 pi c RE Mms^2)          (reference efficiency, piston in half space)
    SPL(1 W, 1 m) = 10 log10(rho c eta0 / (2 pi p0^2))   SPL(2.83 V, 1 m) = SPL(1 W) + 10 log10(2.83^2 / RE)

Uncertainties are propagated to first order through the full covariance of
the fitted parameters, so correlations count: fs is far better known than
CMES or LCES alone. The gradient of each formula is taken by central
differences (relative step STEP): the same first-order propagation the
`uncertainties` package makes with exact derivatives, to 1e-8 of the value
(tests/analysis/test_derived.py compares them), without its import, 7 ms of
each `linpar analyze` (a fifth of its start beyond reading the recording).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Mapping, Sequence

import numpy as np

from analysis.model.lumped import C_SOUND, RHO     # air at 20 C, shared with the air-load effect

if TYPE_CHECKING:       # the fit needs scipy.optimize (half a second to import): not for a table of units (`qa stats`)
    from analysis.fit.least_squares import FitResult

STEP = 1e-6      # a parameter's relative step for the gradient: truncation ~STEP^2, rounding ~1e-16 / STEP
P_REF = 20e-6     # Pa
V_283 = 2.83      # V, the customary sensitivity drive (1 W into 8 ohm)

NO_DISPLACEMENT = ("not identifiable without displacement: Bl only appears in Hx; measure with the laser "
                   "or use an added-mass method")
NO_SD = "needs Sd: give the effective radiating area (--sd, or the driver's diaphragm diameter)"


@dataclass(frozen=True, slots=True, kw_only=True)
class ParameterValue:
    """One parameter of the table: its value and standard uncertainty in SI, its display unit, or why it has none."""

    name: str
    value: float | None
    std: float | None
    unit: str                  # SI
    display_unit: str
    display_scale: float       # display = SI * scale
    reason: str | None = None  # why value is None
    fitted: bool = False
    # The two parts of `std` (the total the user reads, sqrt(noise^2 + model^2)): the noise's, and how far
    # the value moves between the models the data cannot tell apart. None: not estimated.
    std_noise: float | None = None
    std_model: float | None = None

    def as_json(self) -> dict:
        if self.value is None:
            return {"value": None, "reason": self.reason, "unit": self.unit}
        out = {"value": self.value, "std": self.std, "unit": self.unit}
        if self.std_noise is not None:
            out["std_noise"] = self.std_noise
        if self.std_model is not None:
            out["std_model"] = self.std_model
        return out


@dataclass(frozen=True, slots=True)
class _Derived:
    """How a derived parameter is computed from the fitted ones, and what it needs."""

    name: str
    unit: str
    display_unit: str
    display_scale: float
    needs_bl: bool
    needs_sd: bool
    formula: Callable


def _fs(p):
    return 1.0 / (2 * np.pi * math.sqrt(p["CMES"] * p["LCES"]))


def _qes(p):
    return 2 * np.pi * _fs(p) * p["CMES"] * p["RE"]


def _qms(p):
    return 2 * np.pi * _fs(p) * p["CMES"] * p["RES"]


def _eta0(p, sd):
    mms = p["CMES"] * p["Bl"] ** 2
    return RHO * p["Bl"] ** 2 * sd**2 / (2 * np.pi * C_SOUND * p["RE"] * mms**2)


def _spl_1w(p, sd):
    return 10 * math.log10(RHO * C_SOUND * _eta0(p, sd) / (2 * np.pi * P_REF**2))


DERIVED: tuple[_Derived, ...] = (
    _Derived("fs", "Hz", "Hz", 1.0, False, False, lambda p, sd: _fs(p)),
    _Derived("Mms", "kg", "g", 1e3, True, False, lambda p, sd: p["CMES"] * p["Bl"] ** 2),
    _Derived("Rms", "kg/s", "kg/s", 1.0, True, False, lambda p, sd: p["Bl"] ** 2 / p["RES"]),
    _Derived("Cms", "m/N", "mm/N", 1e3, True, False, lambda p, sd: p["LCES"] / p["Bl"] ** 2),
    _Derived("Kms", "N/m", "N/mm", 1e-3, True, False, lambda p, sd: p["Bl"] ** 2 / p["LCES"]),
    _Derived("Qes", "1", "-", 1.0, False, False, lambda p, sd: _qes(p)),
    _Derived("Qms", "1", "-", 1.0, False, False, lambda p, sd: _qms(p)),
    _Derived("Qts", "1", "-", 1.0, False, False, lambda p, sd: _qes(p) * _qms(p) / (_qes(p) + _qms(p))),
    _Derived("Vas", "m^3", "l", 1e3, True, True,
             lambda p, sd: RHO * C_SOUND**2 * sd**2 * p["LCES"] / p["Bl"] ** 2),
    _Derived("eta0", "1", "%", 100.0, True, True, _eta0),
    _Derived("SPL_1W_1m", "dB", "dB SPL", 1.0, True, True, _spl_1w),
    _Derived("SPL_2.83V_1m", "dB", "dB SPL", 1.0, True, True,
             lambda p, sd: _spl_1w(p, sd) + 10 * math.log10(V_283**2 / p["RE"])),
)


def _covariance(fit: FitResult) -> np.ndarray | None:
    """The fit's covariance as the propagation uses it: through the correlation matrix, its negative eigenvalues
    (rounding) set to zero, as the `uncertainties` package does; None when there is none or it is not a matrix
    of numbers."""
    if fit.covar is None or not fit.varying:
        return None
    covar = np.asarray(fit.covar, dtype=float)
    if covar.shape != (len(fit.varying),) * 2:
        return None
    std = np.sqrt(np.diag(covar))
    scale = np.where(std == 0, 1.0, std)
    try:
        variances, axes = np.linalg.eigh(covar / scale / scale[:, np.newaxis])
    except np.linalg.LinAlgError:
        return None         # not positive semi-definite, or not finite: values without uncertainty
    return std[:, np.newaxis] * ((axes * np.maximum(variances, 0.0)) @ axes.T) * std[np.newaxis, :]


def _value_and_std(formula: Callable, values: Mapping[str, float], sd_m2: float | None, varying: Sequence[str],
                   covar: np.ndarray | None) -> tuple[float, float | None]:
    """formula(values, sd_m2), and its standard uncertainty sqrt(g C g) with g its gradient in the varying
    parameters (central differences); None when the gradient cannot be taken there (a domain's edge)."""
    value = float(formula(values, sd_m2))
    if covar is None:
        return value, None
    gradient = np.empty(len(varying))
    for i, name in enumerate(varying):
        step = STEP * (abs(values[name]) or 1.0)
        try:
            up = formula({**values, name: values[name] + step}, sd_m2)
            down = formula({**values, name: values[name] - step}, sd_m2)
        except (ValueError, ZeroDivisionError, OverflowError):
            return value, None
        gradient[i] = (up - down) / (2 * step)
    variance = float(gradient @ covar @ gradient)
    std = math.sqrt(variance) if variance >= 0 else math.nan
    return value, std if math.isfinite(std) else None


def parameter_table(fit: FitResult, sd_m2: float | None,
                    no_displacement: str = NO_DISPLACEMENT) -> dict[str, ParameterValue]:
    """Fitted and derived parameters, in the order of docs/physics.md, with reasons for the missing.

    `no_displacement`: why the parameters that need Bl are missing when the fit had no displacement.
    """
    table: dict[str, ParameterValue] = {}
    for spec in fit.model.param_specs:
        table[spec.name] = ParameterValue(name=spec.name, value=fit.values[spec.name], std=fit.stderr.get(spec.name),
                                          unit=spec.unit, display_unit=spec.display_unit,
                                          display_scale=spec.display_scale, fitted=True)
    has_bl = fit.model.with_displacement
    if not has_bl:
        table["Bl"] = ParameterValue(name="Bl", value=None, std=None, unit="T*m", display_unit="T*m",
                                     display_scale=1.0, reason=no_displacement)
    values, covar = dict(fit.values), _covariance(fit)
    for d in DERIVED:
        if d.needs_bl and not has_bl:
            table[d.name] = ParameterValue(name=d.name, value=None, std=None, unit=d.unit,
                                           display_unit=d.display_unit, display_scale=d.display_scale,
                                           reason=no_displacement)
            continue
        if d.needs_sd and not sd_m2:
            table[d.name] = ParameterValue(name=d.name, value=None, std=None, unit=d.unit,
                                           display_unit=d.display_unit, display_scale=d.display_scale, reason=NO_SD)
            continue
        try:
            value, std = _value_and_std(d.formula, values, sd_m2, fit.varying, covar)
        except (ValueError, ZeroDivisionError, OverflowError) as exc:     # math of extreme fitted values
            table[d.name] = ParameterValue(name=d.name, value=None, std=None, unit=d.unit,
                                           display_unit=d.display_unit, display_scale=d.display_scale,
                                           reason=f"cannot be computed from the fitted values ({exc})")
            continue
        if not math.isfinite(value):
            table[d.name] = ParameterValue(name=d.name, value=None, std=None, unit=d.unit,
                                           display_unit=d.display_unit, display_scale=d.display_scale,
                                           reason=f"cannot be computed from the fitted values ({value})")
            continue
        table[d.name] = ParameterValue(name=d.name, value=value, std=std, unit=d.unit, display_unit=d.display_unit,
                                       display_scale=d.display_scale)
    return table


def unmeasured_table(model, reason: str) -> dict[str, ParameterValue]:
    """Every parameter of `model` (an analysis.model.composed.Model) and the derived ones, each "not measured: reason"."""
    table = {spec.name: ParameterValue(name=spec.name, value=None, std=None, unit=spec.unit,
                                       display_unit=spec.display_unit, display_scale=spec.display_scale,
                                       reason=reason)
             for spec in model.param_specs}
    table.setdefault("Bl", ParameterValue(name="Bl", value=None, std=None, unit="T*m", display_unit="T*m",
                                          display_scale=1.0, reason=reason))
    for d in DERIVED:
        table[d.name] = ParameterValue(name=d.name, value=None, std=None, unit=d.unit, display_unit=d.display_unit,
                                       display_scale=d.display_scale, reason=reason)
    return table


def derived_from_values(values: Mapping[str, float], sd_m2: float | None = None) -> dict[str, float]:
    """Derived parameters of plain values (no uncertainties), e.g. for a driver definition."""
    out = {}
    for d in DERIVED:
        if (d.needs_bl and "Bl" not in values) or (d.needs_sd and not sd_m2):
            continue
        out[d.name] = float(d.formula(dict(values), sd_m2))
    return out
