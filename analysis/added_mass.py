"""Bl and Mms without a laser: impedance curves with known masses added to the cone.

Three methods, from the classical to the over-determined:

- single added mass (classical): fit the free-air curve and the one with mass
  m alone; the resonance falls from fs to fs', and with the same suspension
      Mms = m / ((fs/fs')^2 - 1),  Cms = 1 / ((2 pi fs)^2 Mms),
      Bl = sqrt(2 pi fs Mms RE / Qes),  Rms = 2 pi fs Mms / Qms;
- joint fit (any number of masses): all curves fitted at once with one set
  of electrical and mechanical parameters, the known mass m_k the only
  difference: Zm_k = Zm + s m_k, i.e. in the model's terms the motional
  admittance gains s m_k / Bl^2. With two masses the problem is
  over-determined: both shifts must agree on one Bl and one Mms. The
  suspension (creep included) is the free-air one in every curve: its
  reference frequency stays the free-air fs, since a mass on the cone does
  not change the spider;
- model-free dual added mass (Candy and Futtrup, AES 2017, as Speakerbench
  does it): differences of the three curves cancel the blocked impedance,
      dZ_k = Z0 - Zk,  Zms = (1 - mu) dZ1 dZ2 / (dZ2 - mu dZ1),  mu = m2/m1,
  Bl^2 = m1 Re<j w Zms (Zms - dZ1) / dZ1> over 0.8..1.2 fs, and Mms from a
  linear fit of 1/Zms = j w CMES + 1/R + q(w)/(j w L), q = 1/(1 - beta ln(j w)),
  over the same band (beta by a 1-D search).

The joint fit is the primary result (any model of the catalogue, all lines,
uncertainties from the residual scatter). Speakerbench's published dual
added-mass numbers come from the model-free method; it is kept as the
cross-check that reproduces them (SEAS L16RNX: Bl 7.006, Mms 15.05 g).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np
import uncertainties
from scipy.optimize import minimize_scalar

from analysis.curves.fitting import (UNCERTAINTY_NOTE, CurveFitError, FitRange, covariance_with_bounds, fit_curves,
                                     relative_residual)
from analysis.derived import C_SOUND, DERIVED, RHO, ParameterValue, parameter_table
from analysis.effects import Effect, parse_effects
from analysis.effects.base import Site
from analysis.fit.bounded_leastsq import Start, bounded_leastsq
from analysis.fit.least_squares import ASSUMED_RELATIVE_STD, ChannelFit, FitData, FitResult, fit_model
from analysis.fit.startvalues import start_context
from analysis.model.composed import BASE_PARAMS, BL_PARAM, Model, ModelError
from analysis.model.defaults import ADDED_MASS_EFFECTS
from analysis.pipeline import model_json
from analysis.spectra import TransferFunction
from analysis.validity.result import UNKNOWN

# Agreement of an added-mass result with the laser's, per parameter: green
# when within AGREE_SIGMA combined sigmas or AGREE_PERCENT, red when beyond
# DISAGREE_SIGMA and DISAGREE_PERCENT, yellow between. Both tests, because
# real tools disagree by a few percent (see the data README) while their
# own sigmas can be far smaller.
AGREE_SIGMA, DISAGREE_SIGMA = 2.0, 3.0
AGREE_PERCENT, DISAGREE_PERCENT = 2.0, 5.0
COMPARED = ("Bl", "Mms", "Cms")
DEFAULT_EFFECTS = ",".join(ADDED_MASS_EFFECTS)      # why these: analysis.model.defaults
MODEL_FREE_BAND = (0.8, 1.2)     # x fs, Speakerbench's averaging band
REPORTED = ("Bl", "Mms", "Cms", "Rms", "Vas", "fs", "Qms", "Qes", "Qts", "RE")


@dataclass(frozen=True, kw_only=True)
class MassCurve:
    impedance: TransferFunction
    added_mass_kg: float            # 0 for the free-air curve
    label: str = ""

    @property
    def name(self) -> str:
        return self.label or ("free air" if self.added_mass_kg == 0 else f"+{self.added_mass_kg * 1e3:g} g")


@dataclass(frozen=True, kw_only=True)
class AddedMassResult:
    method: str
    parameters: dict[str, ParameterValue]
    masses_kg: tuple[float, ...]
    fit: FitResult | None = None
    notes: tuple[str, ...] = ()

    def value(self, name: str) -> float | None:
        p = self.parameters.get(name)
        return None if p is None else p.value

    def report(self) -> str:
        """The method, the reported parameters with their 1-sigma, the model and its reduced chi^2, the notes."""
        from analysis.result_text import format_value
        lines = [f"{self.method}", f"{'parameter':<10}{'value':>14}  {'1-sigma':>10}  unit"]
        for name in REPORTED:
            p = self.parameters.get(name)
            if p is None or p.value is None:
                continue
            value, std = format_value(p)
            lines.append(f"{name:<10}{value:>14}  {std:>10}  {p.display_unit}")
        if self.fit is not None:
            chi = ", ".join(f"{k} {v:.3g}" for k, v in self.fit.chi2_red_by_channel().items())
            lines.append(f"model: {self.fit.model.describe()}   reduced chi^2: {chi}")
        lines += [f"  {n}" for n in self.notes]
        return "\n".join(lines)

    def as_json(self) -> dict:
        return added_mass_json(self)


# Imported curves carry no per-line noise: the added-mass fits' validity is not checked, only said so.
NOT_CHECKED = "imported curves: no per-line noise, no validity checks"


def added_mass_document(primary: AddedMassResult, checks: Sequence[AddedMassResult], imports: Sequence[str]) -> dict:
    """What `linpar addedmass --json` prints: the joint fit, its validity (unknown: NOT_CHECKED, and how each
    curve was read, `imports`), then the cross-checks' own results."""
    doc = primary.as_json()
    doc["validity"] = {"overall": UNKNOWN, "note": NOT_CHECKED, "import": list(imports)}
    doc["cross_checks"] = [check.as_json() for check in checks]
    return doc


def _units(name: str) -> tuple[str, str, float]:
    for spec in BASE_PARAMS + (BL_PARAM,):
        if spec.name == name:
            return spec.unit, spec.display_unit, spec.display_scale
    d = next(d for d in DERIVED if d.name == name)
    return d.unit, d.display_unit, d.display_scale


def _pv(name: str, x) -> ParameterValue:
    unit, display, scale = _units(name)
    if hasattr(x, "nominal_value"):
        std = float(x.std_dev)
        return ParameterValue(name=name, value=float(x.nominal_value), std=std if np.isfinite(std) else None,
                              unit=unit, display_unit=display, display_scale=scale)
    return ParameterValue(name=name, value=float(x), std=None, unit=unit, display_unit=display, display_scale=scale)


def _effects(effects: Sequence[Effect] | str | None) -> tuple[Effect, ...]:
    if effects is None or isinstance(effects, str):
        found = parse_effects(DEFAULT_EFFECTS if effects is None else effects)
    else:
        found = tuple(effects)
    channel_only = [e.id for e in found if e.site is Site.DISPLACEMENT]
    if channel_only:
        raise ModelError(f"effect(s) {', '.join(channel_only)} act on the displacement channel: "
                         "an added-mass fit has impedance only")
    return found


def _fitted(fit: FitResult) -> dict[str, object]:
    """The fit's values as correlated ufloats (fixed or unknown ones as floats)."""
    values: dict[str, object] = dict(fit.values)
    if fit.covar is not None and fit.varying:
        try:
            nominal = [fit.values[n] for n in fit.varying]
            values.update(zip(fit.varying, uncertainties.correlated_values(nominal, fit.covar)))
        except (np.linalg.LinAlgError, ValueError):
            pass
    return values


def _resonance(p) -> tuple[object, object, object]:
    """fs, Qes, Qms of one fitted curve (model terms: CMES, LCES, RES, RE)."""
    fs = 1.0 / (2 * np.pi * (p["CMES"] * p["LCES"]) ** 0.5)
    return fs, 2 * np.pi * fs * p["CMES"] * p["RE"], 2 * np.pi * fs * p["CMES"] * p["RES"]


def single_added_mass(free: TransferFunction, loaded: TransferFunction, mass_kg: float,
                      effects: Sequence[Effect] | str | None = None, sd_m2: float | None = None,
                      f_range: FitRange | None = None) -> AddedMassResult:
    """The classical single-added-mass method: two separate fits and the fs shift."""
    if not mass_kg > 0:
        raise CurveFitError(f"the added mass must be positive, not {mass_kg!r} kg")
    effects = _effects(effects)
    fits = [fit_curves(tf, None, effects, None, f_range).fit for tf in (free, loaded)]
    p0, p1 = (_fitted(f) for f in fits)
    fs, qes, qms = _resonance(p0)
    fs1 = _resonance(p1)[0]
    ratio2 = (fs / fs1) ** 2
    if not _nominal(ratio2) > 1:
        raise CurveFitError(f"the resonance did not fall with the added mass (fs {_nominal(fs):.4g} Hz, with "
                            f"{mass_kg * 1e3:g} g {_nominal(fs1):.4g} Hz): check the files and the mass")
    mms = mass_kg / (ratio2 - 1)
    cms = 1 / ((2 * np.pi * fs) ** 2 * mms)
    bl = (2 * np.pi * fs * mms * p0["RE"] / qes) ** 0.5
    out = {"Bl": bl, "Mms": mms, "Cms": cms, "Rms": 2 * np.pi * fs * mms / qms, "fs": fs, "Qms": qms,
           "Qes": qes, "Qts": qes * qms / (qes + qms), "RE": p0["RE"]}
    if sd_m2:
        out["Vas"] = RHO * C_SOUND**2 * sd_m2**2 * cms
    params = {name: _pv(name, out[name]) for name in REPORTED if name in out}
    note = (f"fs {_nominal(fs):.4g} Hz free, {_nominal(fs1):.4g} Hz with {mass_kg * 1e3:g} g; the uncertainties "
            "come from the two fits' residual scatter")
    return AddedMassResult(method="single added mass (classical)", parameters=params, masses_kg=(mass_kg,),
                           notes=(note,))


def _nominal(x) -> float:
    return float(getattr(x, "nominal_value", x))


def joint_added_mass(curves: Sequence[MassCurve], effects: Sequence[Effect] | str | None = None,
                     sd_m2: float | None = None, f_range: FitRange | None = None) -> AddedMassResult:
    """One fit of all curves with shared parameters and the known added masses."""
    if sum(c.added_mass_kg == 0 for c in curves) != 1 or len(curves) < 2:
        raise CurveFitError("expected one free-air curve (added mass 0) and at least one with an added mass")
    if any(c.added_mass_kg < 0 for c in curves):
        raise CurveFitError("added masses must be positive")
    effects = _effects(effects)
    f_range = f_range or FitRange()
    curves = sorted(curves, key=lambda c: c.added_mass_kg)
    data = [f_range.select(c.impedance, None) for c in curves]
    masses = [c.added_mass_kg for c in curves]
    model = Model(effects, with_displacement=True)
    values = _joint_start(model, effects, data, masses)

    def curve_impedance(p, tf, mass):
        s = 2j * np.pi * tf.freqs
        Y = 1.0 / model.motional_impedance(s, p) + s * mass / p["Bl"] ** 2
        Z = model.blocked_impedance(s, p) + 1.0 / Y
        for effect in model.effects:
            if effect.site is Site.CURRENT:
                Z = Z * effect.response(s, p)
        return Z

    def residual(p):
        return np.concatenate([part for tf, m in zip(data, masses)
                               for part in relative_residual(curve_impedance(p, tf, m), tf)])

    start = Start.of({s.name: values[s.name] for s in model.param_specs},
                     {s.name: (s.min, s.max) for s in model.param_specs})

    def bounded_residual(p):
        return np.nan_to_num(residual(p), nan=1e12, posinf=1e12, neginf=-1e12)

    result = bounded_leastsq(bounded_residual, start, xtol=1e-12, ftol=1e-12, max_nfev=20000)
    fit = _fit_result(model, dict(result.values), data, masses, [c.name for c in curves], curve_impedance, result)
    fit, held = covariance_with_bounds(fit, residual)
    notes = [f"{len(curves)} curves fitted jointly: shared electrical and mechanical parameters, known added "
             f"masses {', '.join(f'{m * 1e3:g} g' for m in masses if m)}"]
    if held:
        notes.append("on a bound, held for the uncertainties: " + ", ".join(held))
    table = parameter_table(fit, sd_m2)
    notes.append(UNCERTAINTY_NOTE)
    return AddedMassResult(method=f"joint fit of {len(curves)} curves", parameters=table,
                           masses_kg=tuple(m for m in masses if m), fit=fit, notes=tuple(notes))


def _joint_start(model: Model, effects, data, masses) -> dict[str, float]:
    """Start values: the free-air fit, and Bl from each curve's own CMES shift (Bl^2 = m / dCMES)."""
    z_model = Model(effects, with_displacement=False)
    fits = [fit_model(FitData(tf), z_model) for tf in data]
    values = dict(fits[0].values)
    cmes0 = values["CMES"]
    bl2 = [m / (f.values["CMES"] - cmes0) for f, m in zip(fits[1:], masses[1:]) if f.values["CMES"] > cmes0]
    values["Bl"] = float(np.sqrt(np.median(bl2))) if bl2 else BL_PARAM.default
    for spec in model.param_specs:
        values.setdefault(spec.name, spec.default)
    return values


def _fit_result(model, values, data, masses, labels, curve_impedance, result) -> FitResult:
    channels = {}
    k = len(result.varying)
    n_total = sum((2 if tf.has_phase else 1) * len(tf.freqs) for tf in data)
    for label, tf, m in zip(labels, data, masses):
        z = curve_impedance(values, tf, m)
        parts = relative_residual(z, tf)
        chi2 = float(sum(np.sum(p**2) for p in parts))
        n = len(parts) * len(tf.freqs)
        dof = max(n - k * n / n_total, 1.0)
        std = ASSUMED_RELATIVE_STD * np.abs(tf.value)
        channels[label] = ChannelFit(name=label, freqs=tf.freqs, measured=tf.value, model=z, std=std, chi2=chi2,
                                     n_points=n, chi2_red=chi2 / dof, has_phase=tf.has_phase)
    chi2 = sum(c.chi2 for c in channels.values())
    return FitResult(model=model, values=values, stderr={n: None for n in values}, varying=result.varying, covar=None,
                     channels=channels, chi2=chi2, n_data=n_total, success=bool(result.success),
                     message=str(result.message), nfev=int(result.nfev), noise_known=False)


def model_free_dual_mass(free: TransferFunction, first: TransferFunction, m1_kg: float,
                         second: TransferFunction, m2_kg: float, sd_m2: float | None = None) -> AddedMassResult:
    """Candy and Futtrup's model-free dual-added-mass method (what Speakerbench reports as Bl and Mms)."""
    if not (0 < m1_kg < m2_kg):
        raise CurveFitError("expected two different positive added masses")
    if not (free.has_phase and first.has_phase and second.has_phase):
        raise CurveFitError("the model-free method subtracts complex impedances: it needs the phase of all three")
    f = free.freqs
    z0, z1, z2 = free.value, _on_grid(first, f), _on_grid(second, f)
    mu = m2_kg / m1_kg
    dz1, dz2 = z0 - z1, z0 - z2
    with np.errstate(divide="ignore", invalid="ignore"):
        zms = (1 - mu) * dz1 * dz2 / (dz2 - mu * dz1)
        w = 2 * np.pi * f
        bl2_line = m1_kg * (1j * w * zms * (zms - dz1) / dz1).real
    fs_guess = start_context(free).fs
    near = (f > 0.7 * fs_guess) & (f < 1.4 * fs_guess) & np.isfinite(zms)
    if near.sum() < 3:
        raise CurveFitError("too few lines around the resonance for the model-free method")
    fs = float(f[near][np.argmax(np.abs(zms[near]))])
    band = (f >= MODEL_FREE_BAND[0] * fs) & (f <= MODEL_FREE_BAND[1] * fs) & np.isfinite(bl2_line)
    if band.sum() < 3 or np.mean(bl2_line[band]) <= 0:
        raise CurveFitError("no usable lines between 0.8 and 1.2 fs for the model-free Bl")
    per_line = np.sqrt(np.abs(bl2_line[band]))
    bl = uncertainties.ufloat(np.sqrt(np.mean(bl2_line[band])), np.std(per_line, ddof=1) / np.sqrt(band.sum()))
    y, wb = 1.0 / zms[band], w[band]
    beta = minimize_scalar(lambda b: _log_model_lsq(b, y, wb)[1], bounds=(-0.2, 0.5), method="bounded").x
    (cmes, g, c), _ = _log_model_lsq(beta, y, wb, with_covariance=True)
    mms = cmes * bl**2
    # Speakerbench's equivalent TS values at ws: g(ws) = 1/RES + 1/(j ws LCES), 1/L = -c, 1/R = g.
    ws = 2 * np.pi * fs
    a, b = 1 - beta * np.log(ws), np.pi * beta / 2
    inv_l = -c
    lces = 1.0 / (inv_l * a / (a**2 + b**2))
    res = 1.0 / (g + inv_l / ws * b / (a**2 + b**2))
    out = {"Bl": bl, "Mms": mms, "Cms": lces / bl**2, "Rms": bl**2 / res, "fs": fs}
    if sd_m2:
        out["Vas"] = RHO * C_SOUND**2 * sd_m2**2 * out["Cms"]
    params = {name: _pv(name, out[name]) for name in REPORTED if name in out}
    notes = (f"fs {fs:.4g} Hz from the peak of the model-free motional impedance; Bl averaged over "
             f"{band.sum()} lines in 0.8..1.2 fs (standard error of the mean); LOG creep beta {beta:.3g}",)
    return AddedMassResult(method="model-free dual added mass (Candy-Futtrup, Speakerbench)", parameters=params,
                           masses_kg=(m1_kg, m2_kg), notes=notes)


def _log_model_lsq(beta: float, y: np.ndarray, w: np.ndarray, with_covariance: bool = False):
    """Linear least squares of 1/Zms = j w a + b + j q c / w (q = 1/(1 - beta ln(j w))) for (a, b, c)."""
    q = 1.0 / (1.0 - beta * np.log(1j * w))
    cols = [1j * w, np.ones_like(w), 1j * q / w]
    A = np.vstack([np.concatenate([col.real, col.imag]) for col in cols]).T
    rhs = np.concatenate([y.real, y.imag])
    scale = np.abs(A).max(axis=0)
    sol, *_ = np.linalg.lstsq(A / scale, rhs, rcond=None)
    sol = sol / scale
    r = A @ sol - rhs
    cost = float(r @ r)
    if not with_covariance:
        return sol, cost
    dof = max(len(rhs) - 3, 1)
    cov = np.linalg.pinv(A.T @ A) * cost / dof
    return uncertainties.correlated_values(sol, cov), cost


def _on_grid(tf: TransferFunction, freqs: np.ndarray) -> np.ndarray:
    """tf's values at `freqs`: as they are when the grids match (to export rounding), else interpolated."""
    if len(tf.freqs) == len(freqs) and np.allclose(tf.freqs, freqs, rtol=1e-3, atol=0):
        return tf.value
    if tf.freqs[0] > freqs[0] * (1 + 1e-3) or tf.freqs[-1] < freqs[-1] * (1 - 1e-3):
        raise CurveFitError(f"the curves cover different bands ({tf.freqs[0]:g}..{tf.freqs[-1]:g} Hz against "
                            f"{freqs[0]:g}..{freqs[-1]:g} Hz): the model-free method needs them on one grid")
    lf, lx = np.log(tf.freqs), np.log(freqs)
    return np.interp(lx, lf, tf.value.real) + 1j * np.interp(lx, lf, tf.value.imag)


def added_mass_json(result: AddedMassResult) -> dict:
    out = {"method": result.method, "added_masses_kg": list(result.masses_kg),
           "parameters": {n: p.as_json() for n, p in result.parameters.items()}, "notes": list(result.notes)}
    if result.fit is not None:
        out["model"] = model_json(result.fit)
    return out


@dataclass(frozen=True, kw_only=True)
class Finding:
    code: str
    severity: str             # "green", "yellow" or "red"
    parameter: str
    message: str
    sigmas: float | None      # |difference| / combined standard deviation
    percent: float            # |difference| / laser value, in %

    def as_json(self) -> dict:
        return {"code": self.code, "severity": self.severity, "parameter": self.parameter,
                "message": self.message, "sigmas": self.sigmas, "percent": self.percent}


def _value_std(x: Any) -> tuple[float | None, float | None]:
    if x is None:
        return None, None
    if isinstance(x, ParameterValue):
        return x.value, x.std
    if isinstance(x, tuple):
        return float(x[0]), (None if x[1] is None else float(x[1]))
    return float(x), None


def compare_with_laser(added_mass_result: AddedMassResult,
                       laser_parameters: Mapping[str, Any]) -> list[Finding]:
    """One finding 'added-mass-disagrees' per parameter both give (Bl, Mms, Cms), graded green/yellow/red.

    laser_parameters: a parameter table (name -> ParameterValue), or name ->
    (value, std) or value, in SI units.
    """
    findings = []
    for name in COMPARED:
        a, sa = _value_std(added_mass_result.parameters.get(name))
        b, sb = _value_std(laser_parameters.get(name))
        if a is None or b is None or b == 0:
            continue
        diff = abs(a - b)
        percent = 100.0 * diff / abs(b)
        combined = np.hypot(sa or 0.0, sb or 0.0)
        sigmas = float(diff / combined) if combined > 0 else None
        agree = percent <= AGREE_PERCENT or (sigmas is not None and sigmas <= AGREE_SIGMA)
        disagree = percent > DISAGREE_PERCENT and (sigmas is None or sigmas > DISAGREE_SIGMA)
        severity = "green" if agree else "red" if disagree else "yellow"
        _, display, scale = _units(name)
        how = f"{sigmas:.1f} combined sigmas" if sigmas is not None else "no uncertainty known"
        message = (f"{name}: added mass ({added_mass_result.method}) {a * scale:.4g} {display}, laser "
                   f"{b * scale:.4g} {display}: {percent:.1f} % apart, {how}")
        findings.append(Finding(code="added-mass-disagrees", severity=severity, parameter=name, message=message,
                                sigmas=sigmas, percent=percent))
    return findings
