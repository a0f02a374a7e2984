"""Fitting imported curves: Z (and Hx) read from other tools' files.

Real data are not pure lumped models, so each channel is fitted over its own
frequency range (FitRange):

- f_min, f_max bound both channels (default: everything in the files). Raise
  f_min where the measurement itself fails (a sweep starting at 5 Hz has
  nothing below it) and lower f_max where the blocked-impedance model stops
  describing the coil.
- z_f_max bounds Z only (default: everything, but Z_MAX_OVER_FS * fs for magnitude-only curves with Hx,
  below).
- hx_f_max bounds Hx only (default HX_MAX_OVER_FS * fs, fs read off the
  impedance peak): above a few times fs the cone stops moving as a piston
  (breakup) and a laser on one spot no longer sees the lumped model's x,
  while Bl, which Hx is there to give, is fixed by the lines around and
  below fs.

Magnitude-only curves with Hx (a Klippel LPM export: |Z| and |Hx|) are fitted by default
(default_choices) with the alternating two steps (analysis.fit.alternating), the causal log creep with
every loss at fs in RES (analysis.effects.creep_at_fs) beside lr2, and Z up to Z_MAX_OVER_FS * fs: there
the blocked impedance lr2 still holds, while above it the coil's eddy currents, which no catalogue form
follows over decades, would decide the motional parameters through the many high lines. Measured on
LPM-like exports of four realistic drivers (docs/identification.md): every one of RE, fs, Qts, Qes, Qms,
Bl, Mms and Cms within 3 %, where the joint fit of lr2 and creep-log over the whole export is 5-27 % off.

Imported curves carry no per-line noise estimate of their own: each line's
noise is estimated from the curve's local scatter (analysis.curves.noise, on
every line of the file, before the lines are thinned), so that chi^2 is in
units of that noise as for a recording, and the reduced chi^2, BIC, the
diagnosis's verdict and its sites mean the same. The parameter
uncertainties are scaled by sqrt(reduced chi^2) when it exceeds 1 (the
Birge ratio), as for recordings. Magnitude-only curves (no phase) work the
same way, with one real number per line instead of two.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np

from analysis.curves.noise import describe_noise, with_estimated_noise
from analysis.curves.passivity import judged_not_a_driver, passivity_findings
from analysis.curves.misfit import judged_misfit
from analysis.curves.plausible_numbers import judged_plausible
from analysis.derived import ParameterValue, parameter_table
from analysis.effects import Effect, parse_effects
from analysis.effects.base import ParamSpec
from analysis.errors import LinparError
from analysis.fit.bands import HX_MAX_OVER_FS    # the piston band's top for Hx, as for recordings
from analysis.fit.error import fit_error_percent, rms_relative_residual
from analysis.fit.least_squares import ASSUMED_RELATIVE_STD, FitData, FitError, FitResult, component_sigma
from analysis.fit.startvalues import start_context
from analysis.fit.methods import DEFAULT_METHOD, fit_with
from analysis.model.composed import Model
from analysis.pipeline import model_json
from analysis.spectra import TransferFunction
from analysis.validity.imported_curves import ImportedCurves
from analysis.validity.result import ResultValidity

Z_MAX_OVER_FS = 5.0
# The other Z bands whose fits the model part of magnitude-only curves spans (analysis.fit.model_uncertainty):
# every one describes its lines about as well, and the data cannot say which band's blocked impedance is right.
OTHER_Z_BANDS_OVER_FS = (3.0, 10.0)
# The defaults for magnitude-only curves with Hx (module doc).
MAGNITUDE_ONLY_METHOD = "alternating"
MAGNITUDE_ONLY_EFFECTS = "lr2,creep-log-causal-fs"
# Linearly spaced exports (0.5 Hz or 1 Hz steps up to kHz) put nearly every line
# in the top decade, where the blocked-impedance model is weakest: thinned to
# this many lines per decade, each decade counts alike, as in a log-spaced
# .zma (35 per octave is about 116 per decade).
LINES_PER_DECADE = 100
VALIDITY_NOTE = ("imported curves: no per-line noise of their own, no validity checks of the signals (judged only: "
                 "whether the curve and its numbers can be a driver's)")
UNCERTAINTY_NOTE = ("imported curves carry no noise estimate of their own: each line's noise is estimated from the "
                    "curve's local scatter (a quadratic over 7 neighbouring lines, pooled over 15), and the "
                    "uncertainties are scaled by sqrt(reduced chi^2) where the model misses by more than that noise; "
                    "a curve smoothed by the tool that exported it looks less noisy than it was")
# Below this many lines per decade a curve changes too much from line to line for its local scatter
# to be its noise: the estimate is then too high (an upper bound), and the notes say so.
MIN_LINES_PER_DECADE_FOR_NOISE = 60


class CurveFitError(LinparError, ValueError):
    """The curves cannot be fitted as asked (e.g. too few lines in the chosen range)."""


@dataclass(frozen=True, kw_only=True)
class FitRange:
    """Frequency limits in Hz; None means no limit (hx_f_max None: HX_MAX_OVER_FS * fs)."""

    f_min: float | None = None
    f_max: float | None = None
    hx_f_max: float | None = None
    per_decade: int | None = LINES_PER_DECADE     # None: every line
    z_f_max: float | None = None
    z_max_over_fs: float | None = None              # bounds Z at this many times fs (read off the peak)

    def select(self, tf: TransferFunction, upper: float | None) -> TransferFunction:
        keep = log_thinned(tf.freqs, self.per_decade)
        if self.f_min is not None:
            keep &= tf.freqs >= self.f_min
        for limit in (self.f_max, upper):
            if limit is not None:
                keep &= tf.freqs <= limit
        if keep.sum() < 5:
            raise CurveFitError(f"only {int(keep.sum())} {tf.name} lines between {self.f_min or tf.freqs[0]:g} and "
                             f"{min(x for x in (self.f_max, upper, tf.freqs[-1]) if x is not None):g} Hz: "
                             "widen the frequency range")
        return tf.restricted(keep)


def log_thinned(freqs: np.ndarray, per_decade: int | None) -> np.ndarray:
    """Mask of the measured lines nearest to a log grid of `per_decade` points (no interpolation)."""
    keep = np.zeros(len(freqs), dtype=bool)
    log_f = np.log10(freqs)
    decades = log_f[-1] - log_f[0] if len(freqs) > 1 else 0.0
    # Data already near log spacing (a .zma) are left whole: thinning would only drop lines.
    if per_decade is None or len(freqs) <= 1.5 * per_decade * max(decades, 1.0):
        keep[:] = True
        return keep
    grid = np.arange(log_f[0], log_f[-1] + 0.5 / per_decade, 1.0 / per_decade)
    nearest = np.clip(np.searchsorted(log_f, grid), 1, len(freqs) - 1)
    nearest -= (grid - log_f[nearest - 1]) < (log_f[nearest] - grid)
    keep[nearest] = True
    return keep


@dataclass(frozen=True, kw_only=True)
class CurveAnalysis:
    """Imported curves' fit: `report()` is the text `linpar analyze --impedance ...` prints, `as_json()` its JSON."""

    fit: FitResult
    parameters: dict[str, ParameterValue]
    sd_m2: float | None
    ranges: dict[str, tuple[float, float]]       # the band each channel was fitted over
    validity: ResultValidity
    notes: tuple[str, ...] = ()
    data: FitData | None = None                  # what was fitted (the model part's refits fit it again)
    # Magnitude-only curves: a model part even when the misfit is small (no phase to show what the model misses),
    # spanning the fits over the other Z bands too.
    model_part_always: bool = False
    other_bands: tuple[FitData, ...] = ()
    # The model part of the uncertainties once estimated (analysis.fit.model_uncertainty.with_estimated).
    model_part: object | None = None
    # The GUI's and the report's: the files read (the impedance file first), and each channel's fitted curve of
    # the tool that exported them (a Klippel export's "Fitted" column), overlaid on linpar's (analysis.curves.reference).
    files: tuple[Path, ...] = ()
    references: Mapping[str, TransferFunction] = field(default_factory=dict)

    @property
    def source(self) -> Path | None:
        """The impedance file: what the pages that show a recording's name show for imported curves."""
        return self.files[0] if self.files else None

    @property
    def model(self) -> Model:
        return self.fit.model

    def report(self) -> str:
        from analysis.result_text import format_curve_result
        return format_curve_result(self)

    def as_json(self) -> dict:
        return curve_json(self)


def magnitude_only(impedance: TransferFunction, hx: TransferFunction | None) -> bool:
    """True for |Z| and |Hx| without phase (a Klippel LPM export): the case the module doc's defaults are for."""
    return hx is not None and not (impedance.has_phase and hx.has_phase)


def default_choices(impedance: TransferFunction, hx: TransferFunction | None, effects, method: str | None,
                    f_range: FitRange | None) -> tuple[object, str, FitRange, list[str]]:
    """(effects, method, range, notes): what the user left open filled in as the module doc says."""
    f_range = f_range or FitRange()
    notes = []
    if not magnitude_only(impedance, hx):
        return effects, method or DEFAULT_METHOD, f_range, notes
    if effects is None:
        effects = MAGNITUDE_ONLY_EFFECTS
        notes.append(f"magnitude-only curves: the model {MAGNITUDE_ONLY_EFFECTS} (the causal creep, every loss at "
                     "fs in RES)")
    if method is not None:          # a method by name: its fit over the whole range, as before
        return effects, method, f_range, notes
    method = MAGNITUDE_ONLY_METHOD
    notes.append("magnitude-only curves: fitted by the alternating two steps (Z for the electrical and motional "
                 "parameters, Hx for Bl and the creep, repeated until they agree)")
    if f_range.f_max is None and f_range.z_f_max is None and f_range.z_max_over_fs is None:
        f_range = dataclasses.replace(f_range, z_max_over_fs=Z_MAX_OVER_FS)
    return effects, method, f_range, notes


def fit_curves(impedance: TransferFunction, hx: TransferFunction | None = None,
               effects: Sequence[Effect] | str | None = None, sd_m2: float | None = None,
               f_range: FitRange | None = None, notes: Sequence[str] = (), method: str | None = None
               ) -> CurveAnalysis:
    """Fit the model (effects; default lr2,creep-log) to imported Z and optional Hx curves, by `method`
    (analysis.fit.methods; None: joint, but magnitude-only curves get the module doc's defaults)."""
    effects, method, f_range, chosen = default_choices(impedance, hx, effects, method, f_range)
    if effects is None or isinstance(effects, str):
        effects = parse_effects(effects)
    data, notes = curve_data(impedance, hx, f_range, list(notes) + chosen)
    z, x = data.impedance, data.displacement
    model = Model(tuple(effects), with_displacement=x is not None)
    fit = fit_with(method, data, model)
    if chosen:
        fit = _admissible(fit, data, notes)
    fit, held = covariance_with_bounds(fit, lambda v: weighted_residual(model, v, data))
    if held:
        notes.append("on a bound, held for the uncertainties: " + ", ".join(held))
    ranges = {tf.name: (float(tf.freqs[0]), float(tf.freqs[-1])) for tf in (z, x) if tf is not None}
    validity = curve_validity(fit, ranges, [tf for tf in (z, x) if tf is not None], notes)
    other_bands = ()
    if f_range.z_f_max is None and f_range.z_max_over_fs is not None:
        other_bands = tuple(curve_data(impedance, hx, dataclasses.replace(f_range, z_max_over_fs=k))[0]
                            for k in OTHER_Z_BANDS_OVER_FS if k != f_range.z_max_over_fs)
    parameters = parameter_table(fit, sd_m2)
    found = passivity_findings(impedance)       # a curve no driver can give: red, its parameters withheld
    if found:
        validity, parameters = judged_not_a_driver(validity, parameters, found)
    else:                                       # numbers no driver has: judged as a recording's
        validity = judged_misfit(judged_plausible(validity, parameters, sd_m2))
    return CurveAnalysis(fit=fit, parameters=parameters, sd_m2=sd_m2, ranges=ranges,
                         validity=validity, notes=tuple(notes), data=data,
                         model_part_always=magnitude_only(impedance, hx), other_bands=other_bands)


def _admissible(fit: FitResult, data: FitData, notes: list[str]) -> FitResult:
    """The default model's fit, or, when it is no driver's (analysis.fit.model_uncertainty.degenerate: a base
    parameter on a bound, or the blocked impedance taking RE's place at the lowest line), the best fit among the
    model's alternatives that is one. Seen on magnitude-only curves of a driver with a strong lossless creep
    (lambda 0.38): the causal law's fit put RE on its bound and R2 in its place."""
    from analysis.fit.model_uncertainty import alternative_models, degenerate
    if not degenerate(fit, data):
        return fit
    others = []
    for model in alternative_models(fit.model):
        try:
            other = fit_with(fit.method, data, model)
        except FitError:
            continue
        if math.isfinite(other.chi2) and not degenerate(other, data):
            others.append(other)
    if not others:
        notes.append("the default model's fit ended on a bound or with RE taken by the blocked impedance, and no "
                     "alternative model did better: check the values marked on a bound")
        return fit
    best = min(others, key=lambda f: f.chi2)
    notes.append(f"the default model {'+'.join(fit.model.effect_ids)} ended on a bound or with RE taken by the "
                 f"blocked impedance: fitted with {'+'.join(best.model.effect_ids)} instead")
    return best


def curve_data(impedance: TransferFunction, hx: TransferFunction | None = None,
               f_range: FitRange | None = None, notes: Sequence[str] = ()) -> tuple[FitData, list[str]]:
    """The lines of imported curves that the fit sees, with each line's noise, and notes on how they were chosen."""
    f_range = f_range or FitRange()
    notes = list(notes)
    impedance, hx = (None if tf is None else _with_noise(tf, notes) for tf in (impedance, hx))
    z_max = f_range.z_f_max
    if z_max is None and f_range.z_max_over_fs is not None:
        fs = start_context(f_range.select(impedance, None)).fs
        z_max = f_range.z_max_over_fs * fs
        notes.append(f"Z fitted up to {z_max:.4g} Hz ({f_range.z_max_over_fs:g} x fs = {fs:.4g} Hz from the impedance "
                     "peak): above it the blocked impedance's form no longer holds")
    z = f_range.select(impedance, z_max)
    x = None
    if hx is not None:
        hx_max = f_range.hx_f_max
        if hx_max is None:
            fs = start_context(z).fs
            hx_max = HX_MAX_OVER_FS * fs
            notes.append(f"Hx fitted up to {hx_max:.4g} Hz ({HX_MAX_OVER_FS:g} x fs = {fs:.4g} Hz from the "
                         "impedance peak): above it the cone need not move as a piston")
        x = f_range.select(hx, hx_max)
    return FitData(z, x), notes


def _with_noise(tf: TransferFunction, notes: list[str]) -> TransferFunction:
    if tf.noise_known:
        return tf
    out = with_estimated_noise(tf)
    decades = np.log10(tf.freqs[-1] / tf.freqs[0]) if len(tf.freqs) > 1 else 0.0
    note = f"noise from the local scatter: {describe_noise(out)}"
    if decades > 0 and len(tf.freqs) / decades < MIN_LINES_PER_DECADE_FOR_NOISE:
        note += (f" ({len(tf.freqs) / decades:.0f} lines per decade: too coarse for the local scatter to be "
                 "the noise alone, so this is an upper bound)")
    notes.append(note)
    return out


def curve_validity(fit: FitResult, ranges: Mapping[str, tuple[float, float]],
                   curves: Sequence[TransferFunction], notes: Sequence[str]) -> ResultValidity:
    """The validity of imported curves: nothing checked, and how far to trust the numbers."""
    return ResultValidity(fit_error_percent=fit_error_percent(fit), imported=ImportedCurves(
        note=VALIDITY_NOTE, uncertainties=UNCERTAINTY_NOTE, rms_relative_residual=rms_relative_residual(fit),
        magnitude_only=tuple(tf.name for tf in curves if not tf.has_phase), ranges_hz=ranges, notes=tuple(notes)))


def curve_json(result: CurveAnalysis) -> dict:
    """The same shape as `linpar analyze --json` on a recording."""
    return {
        "parameters": {name: p.as_json() for name, p in result.parameters.items()},
        "model": model_json(result.fit),
        "validity": result.validity.as_json(),
    }


def weighted_residual(model: Model, values: Mapping[str, float], data: FitData) -> np.ndarray:
    """The fit's residual, each line in units of its noise, as analysis.fit.least_squares builds it."""
    parts = []
    for tf, evaluate in ((data.impedance, model.impedance), (data.displacement, model.displacement)):
        if tf is None or (tf is data.displacement and not model.with_displacement):
            continue
        predicted = evaluate(2j * np.pi * tf.freqs, values)
        sigma = component_sigma(tf)
        if not tf.has_phase:
            parts.append((np.abs(predicted) - tf.value.real) / sigma)
        else:
            r = (predicted - tf.value) / sigma
            parts += [r.real, r.imag]
    return np.concatenate(parts)


def relative_residual(model_values: np.ndarray, tf: TransferFunction) -> list[np.ndarray]:
    """The residual with relative weights (ASSUMED_RELATIVE_STD per line): the added-mass fits use it."""
    sigma = ASSUMED_RELATIVE_STD * np.abs(tf.value) / np.sqrt(2.0)
    if not tf.has_phase:
        return [(np.abs(model_values) - tf.value.real) / sigma]
    r = (model_values - tf.value) / sigma
    return [r.real, r.imag]


def at_bound(value: float, spec: ParamSpec) -> bool:
    return spec.on_bound(value)


def jacobian_covariance(residual: Callable[[dict], np.ndarray], values: Mapping[str, float],
                        names: Sequence[str], specs: Mapping[str, ParamSpec], noise_known: bool = False
                        ) -> np.ndarray | None:
    """Covariance of `names` from a central-difference Jacobian, scaled by the reduced chi^2.

    The scaling is lmfit's scale_covar, right for relative weights whose
    absolute size is unknown; with known (or estimated) noise it is the
    Birge ratio, never below 1, as analysis.fit.least_squares does. None when the Jacobian
    is rank deficient (a parameter the data do not determine).
    """
    base = dict(values)
    r0 = residual(base)
    columns = []
    for name in names:
        v, spec = base[name], specs[name]
        h = 1e-6 * max(abs(v), abs(spec.default) * 1e-3, 1e-30)
        hi, lo = min(v + h, spec.max), max(v - h, spec.min)
        r_hi = residual({**base, name: hi})
        r_lo = residual({**base, name: lo})
        columns.append((r_hi - r_lo) / (hi - lo))
    J = np.column_stack(columns)
    dof = max(len(r0) - len(names), 1)
    chi2_red = float(r0 @ r0) / dof
    if noise_known:
        chi2_red = max(chi2_red, 1.0)
    # Parameters span twenty decades (CMES ~1e-4 F, RES ~1e2 ohm): scale each
    # column to unit norm so that the condition number speaks of the data only.
    norms = np.linalg.norm(J, axis=0)
    if not np.all(np.isfinite(J)) or np.any(norms == 0):
        return None
    try:
        jtj = (J / norms).T @ (J / norms)
        if np.linalg.cond(jtj) > 1e12:
            return None
        return np.linalg.inv(jtj) / np.outer(norms, norms) * chi2_red
    except np.linalg.LinAlgError:
        return None


def covariance_with_bounds(fit: FitResult, residual: Callable[[dict], np.ndarray]) -> tuple[FitResult, list[str]]:
    """The fit with a covariance even when a parameter ended on a bound.

    lmfit gives none then (its bound transform has zero slope there). The
    parameters on a bound are held at it and the covariance of the others
    is taken from the Jacobian; the held ones get no standard error.
    """
    complete = fit.covar is not None and all(fit.stderr.get(n) is not None for n in fit.varying)
    if complete:
        return fit, []
    specs = {s.name: s for s in fit.model.param_specs}
    held = [n for n in fit.varying if at_bound(fit.values[n], specs[n])]
    free = [n for n in fit.varying if n not in held]
    sub = jacobian_covariance(residual, fit.values, free, specs, fit.noise_known) if free else None
    if sub is None:
        return fit, held
    index = [fit.varying.index(n) for n in free]
    covar = np.zeros((len(fit.varying), len(fit.varying)))
    covar[np.ix_(index, index)] = sub
    stderr = {n: None for n in fit.values}
    for n, i in zip(free, range(len(free))):
        stderr[n] = float(np.sqrt(sub[i, i])) if sub[i, i] >= 0 else None
    return dataclasses.replace(fit, covar=covar, stderr=stderr), held
