"""Joint weighted least-squares fit of Z and Hx on their complex values.

Every line is weighted by its own standard uncertainty, so the residual of
each line is in units of its noise: when the model is right and the noise
estimate honest, the reduced chi^2 of each channel is about 1.

With known per-line uncertainties, -2 ln L = chi^2 + const, so

    AIC = chi^2 + 2k        BIC = chi^2 + k ln n

(n real data points, k varying parameters): differences of these between
models fitted to the same data are what the model lab ranks by. Curves
imported without a noise estimate use the unknown-variance forms,
n ln(chi^2/n) in place of chi^2.

Standard errors come from the Jacobian at the optimum (MINPACK's, analysis.fit.bounded_leastsq),
scaled by sqrt(max(1, reduced chi^2)) (the Birge ratio) so that a model
that does not fit never claims the precision of one that does.
"""
from __future__ import annotations

import functools
import threading
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from analysis.effects.base import Site
from analysis.errors import LinparError
from analysis.fit.bounded_leastsq import LeastSquaresResult, Start, bounded_leastsq
from analysis.fit.covariance import jacobian, normal_inverse
from analysis.fit.stall import StallWatch
from analysis.fit.startvalues import linear_gain, start_context
from analysis.model.composed import Model
from analysis.spectra import Spectra, TransferFunction

# A line's uncertainty never counts as less than this fraction of its value:
# noise-free (simulated) data would otherwise get infinite weights.
RELATIVE_STD_FLOOR = 1e-9
CHANNELS = ("impedance", "displacement")
EVALUATIONS_PER_PARAMETER = 300


class FitError(LinparError, RuntimeError):
    """The fit could not run (too few lines, cancelled, no convergence)."""


class FitCancelled(FitError):
    pass


# eq=False: with its arrays, == raised for any two that were not the same object; so no __eq__ and __hash__ are
# generated at every start (Python 3.11 execs each dataclass method).
@dataclass(frozen=True, eq=False)
class FitData:
    """What the fit sees: Z and optionally Hx at their lines, with per-line uncertainties."""

    impedance: TransferFunction
    displacement: TransferFunction | None = None

    @classmethod
    def from_spectra(cls, spectra: Spectra) -> "FitData":
        return cls(_usable(spectra.impedance), _usable(spectra.displacement) if spectra.displacement else None)

    def channel(self, name: str) -> TransferFunction | None:
        return self.impedance if name == "impedance" else self.displacement

    @functools.cached_property
    def s(self) -> dict[str, np.ndarray]:
        """s = 2j*pi*f at each channel's lines, worked out once: a fit evaluates its model there thousands of
        times (and the model remembers its effects' responses at lines it has seen: analysis.model.response_memo)."""
        return {name: 2j * np.pi * tf.freqs for name, tf in (("impedance", self.impedance),
                                                             ("displacement", self.displacement)) if tf is not None}

    @functools.cached_property
    def same_lines(self) -> bool:
        """Both channels at the same lines (the usual case): the model is then evaluated once for both."""
        x = self.displacement
        return x is not None and np.array_equal(x.freqs, self.impedance.freqs)


def _usable(tf: TransferFunction) -> TransferFunction:
    keep = np.isfinite(tf.value) & (tf.freqs > 0)
    if tf.noise_known:
        keep &= np.isfinite(tf.std)
    return tf.restricted(keep)


@dataclass(frozen=True, kw_only=True, eq=False)     # eq=False: as FitData
class ChannelFit:
    """One channel's fit: its lines, what was measured and modelled there, and its chi^2."""

    name: str
    freqs: np.ndarray
    measured: np.ndarray
    model: np.ndarray
    std: np.ndarray
    chi2: float
    n_points: int             # real numbers: 2 per complex line, 1 per magnitude-only line
    chi2_red: float
    has_phase: bool = True

    @property
    def normalized_residual(self) -> np.ndarray:
        """(model - measured) per line in units of each component's standard deviation.

        Complex (real and imaginary parts) when the phase was measured; real
        (on the magnitude) for magnitude-only data.
        """
        if not self.has_phase:
            return (np.abs(self.model) - self.measured) / (self.std / np.sqrt(2.0))
        return (self.model - self.measured) / (self.std / np.sqrt(2.0))


@dataclass(frozen=True, kw_only=True, eq=False)     # eq=False: as FitData
class FitResult:
    """A fitted model: its values and standard errors, their covariance, each channel's fit and chi^2."""

    model: Model
    values: dict[str, float]
    stderr: dict[str, float | None]
    varying: tuple[str, ...]
    covar: np.ndarray | None          # of the varying parameters, in `varying` order, Birge-scaled
    channels: dict[str, ChannelFit]
    chi2: float
    n_data: int
    success: bool
    message: str
    nfev: int
    noise_known: bool = True      # False: weights are relative, uncertainties come from the scatter
    method: str = "joint"         # how it was identified (analysis.fit.methods)

    @property
    def n_varying(self) -> int:
        return len(self.varying)

    @property
    def chi2_red(self) -> float:
        return self.chi2 / max(self.n_data - self.n_varying, 1)

    @property
    def _neg2_log_likelihood(self) -> float:
        """chi^2 with known noise; n ln(chi^2 / n) when the noise level is unknown (imported curves)."""
        if self.noise_known:
            return self.chi2
        return self.n_data * np.log(max(self.chi2, 1e-300) / self.n_data)

    @property
    def aic(self) -> float:
        return self._neg2_log_likelihood + 2 * self.n_varying

    @property
    def bic(self) -> float:
        return self._neg2_log_likelihood + self.n_varying * np.log(self.n_data)

    def chi2_red_by_channel(self) -> dict[str, float]:
        return {name: ch.chi2_red for name, ch in self.channels.items()}

    def correlation(self) -> np.ndarray | None:
        if self.covar is None:
            return None
        d = np.sqrt(np.diag(self.covar))
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.covar / np.outer(d, d)

    def report(self, min_correl: float | None = None) -> str:
        """The fit report, as lmfit's fit_report: statistics, parameters with sigma, correlations with
        |r| >= min_correl (default analysis.fit.report.MIN_CORREL), parameters on a bound."""
        from analysis.fit.report import MIN_CORREL, fit_report_json, fit_report_text
        return fit_report_text(fit_report_json(self, MIN_CORREL if min_correl is None else min_correl))


# Curves without a noise estimate (imported ones get one from their local
# scatter, analysis.curves.noise; the added-mass fits do without) are weighted
# relatively: every line as if it carried this relative uncertainty. Their
# parameter uncertainties are then scaled by the scatter of the residual.
ASSUMED_RELATIVE_STD = 0.01


def component_sigma(tf: TransferFunction) -> np.ndarray:
    """Standard deviation of each real component (real, imaginary or magnitude) of a line."""
    if not tf.noise_known:
        return ASSUMED_RELATIVE_STD * np.abs(tf.value) / np.sqrt(2.0)
    return np.maximum(tf.std, RELATIVE_STD_FLOOR * np.abs(tf.value)) / np.sqrt(2.0)


def _channel_residual(model_values: np.ndarray, tf: TransferFunction, sigma: np.ndarray) -> list[np.ndarray]:
    if not tf.has_phase:
        return [(np.abs(model_values) - tf.value.real) / sigma]
    r = (model_values - tf.value) / sigma
    return [r.real, r.imag]


def _residual_vector(model: Model, p: Mapping[str, float], data: FitData, use_x: bool,
                     sigmas: dict[str, np.ndarray], use_z: bool = True) -> np.ndarray:
    z = data.impedance
    if use_x and use_z and data.same_lines:    # both channels from one pass through the model
        Z, Hx = model.responses(data.s["impedance"], p)
        return np.concatenate(_channel_residual(Z, z, sigmas["impedance"])
                              + _channel_residual(Hx, data.displacement, sigmas["displacement"]))
    parts = _channel_residual(model.impedance(data.s["impedance"], p), z, sigmas["impedance"]) if use_z else []
    if use_x:
        x = data.displacement
        parts += _channel_residual(model.displacement(data.s["displacement"], p), x, sigmas["displacement"])
    return np.concatenate(parts)


def _start(model: Model, values: Mapping[str, float], fixed: set[str]) -> Start:
    """Every parameter of `model` from `values` (clipped into its bounds); all but `fixed` vary."""
    return Start.of({spec.name: values[spec.name] for spec in model.param_specs},
                    {spec.name: (spec.min, spec.max) for spec in model.param_specs}, fixed)


def _minimize(model, start: Start, data, use_x, sigmas, cancel,
              per_parameter: int = EVALUATIONS_PER_PARAMETER, use_z: bool = True) -> LeastSquaresResult:
    def residual(values):
        r = _residual_vector(model, values, data, use_x, sigmas, use_z)
        # A parameter set where the model is undefined is simply very bad:
        # a fixed size keeps MINPACK's bookkeeping intact.
        return r if np.isfinite(r).all() else np.nan_to_num(r, nan=1e12, posinf=1e12, neginf=-1e12)

    watch = StallWatch(len(start.varying))

    def iteration(values, resid):
        if cancel is not None and cancel.is_set():
            return True      # ends the fit
        return watch.seen(values, resid)

    # MINPACK's own default budget is 200*(k+1) evaluations; a well-posed fit
    # here needs far fewer. A candidate whose parameters are nearly degenerate
    # would otherwise wander for many thousands.
    result = bounded_leastsq(residual, start, xtol=1e-12, ftol=1e-12,
                             max_nfev=per_parameter * (len(start.varying) + 1), iter_cb=iteration)
    if cancel is not None and cancel.is_set():
        raise FitCancelled("fit cancelled")
    # Stopped where it had stopped improving (analysis.fit.stall): polished from its best point.
    return watch.polished(residual, start, result)


def start_values(model: Model, data: FitData) -> dict[str, float]:
    ctx = start_context(data.impedance)
    values = ctx.base_values()
    if model.with_displacement:
        values["Bl"] = 1.0
    for effect in model.effects:
        values.update(effect.guess(ctx))
    return values


def channel_sigmas(data: FitData, use_x: bool) -> dict[str, np.ndarray]:
    if use_x and data.displacement is None:
        raise FitError("the model needs Hx but the data have no displacement channel")
    sigmas = {"impedance": component_sigma(data.impedance)}
    if use_x:
        sigmas["displacement"] = component_sigma(data.displacement)
    return sigmas


def screen_fit(data: FitData, model: Model, start: Mapping[str, float], vary: set[str],
               per_parameter: int = 20) -> FitResult:
    """A short fit of `vary` alone, the rest held at `start`: ranks start points cheaply."""
    use_x = model.with_displacement
    sigmas = channel_sigmas(data, use_x)
    values = {**start_values(model, data), **{k: v for k, v in start.items()}}
    values = {spec.name: values[spec.name] for spec in model.param_specs}
    result = _minimize(model, _start(model, values, set(values) - vary), data, use_x, sigmas, None, per_parameter)
    return _result(model, result, data, use_x, sigmas, result.nfev)


def fit_model(data: FitData, model: Model, start: Mapping[str, float] | None = None,
              cancel: threading.Event | None = None, per_parameter: int = EVALUATIONS_PER_PARAMETER) -> FitResult:
    """Fit `model` to `data`. `start` (e.g. the previous model's result) overrides start values.

    per_parameter: the budget of model evaluations per varying parameter (and one) of each stage.
    """
    use_x = model.with_displacement
    sigmas = channel_sigmas(data, use_x)

    values = start_values(model, data)
    warm = dict(start or {})
    values.update({k: v for k, v in warm.items() if k in values})
    _check_effects(model, data, values)
    nfev = 0
    displacement_only = {s.name for e in model.effects if e.site is Site.DISPLACEMENT for s in e.params}
    compliance = {s.name for e in model.effects if e.site is Site.COMPLIANCE for s in e.params}
    cold = {name for name in values if name not in warm}

    # Stage 1: Z alone. Creep barely shows in Z: hold it until Hx joins in.
    fixed = {"Bl"} | displacement_only | (compliance & cold if use_x else set())
    if cold - fixed:
        r = _minimize(model, _start(model, values, fixed | (set(values) - cold)), data, False, sigmas, cancel,
                      per_parameter)
        values = dict(r.values)
        nfev += r.nfev
        if compliance & cold and not use_x:
            r = _minimize(model, _start(model, values, set()), data, False, sigmas, cancel, per_parameter)
            values = dict(r.values)
            nfev += r.nfev
    # Stage 2: Bl is a pure gain on Hx: solve for it linearly.
    if use_x and "Bl" in cold:
        x = data.displacement
        g = model.displacement(2j * np.pi * x.freqs, {**values, "Bl": 1.0})
        inv_bl = linear_gain(g if x.has_phase else np.abs(g), x.value, sigmas["displacement"])
        values["Bl"] = abs(1.0 / inv_bl) if inv_bl != 0 else 1.0
    # Stage 3: everything together.
    result = _minimize(model, _start(model, values, set()), data, use_x, sigmas, cancel, per_parameter)
    if result.covar is None:
        # MINPACK gives no covariance when a parameter ends on a bound (the bound
        # transform has zero slope there): hold those at the bound, refit the rest.
        held = _at_bounds(model, result)
        if held:
            nfev += result.nfev
            result = _minimize(model, _start(model, result.values, held), data, use_x, sigmas, cancel,
                               per_parameter)
    if result.covar is None:        # MINPACK stopped without one ("tolerance too small"): from the Jacobian
        return _with_jacobian_covariance(model, result, data, use_x, sigmas, nfev + result.nfev)
    return _result(model, result, data, use_x, sigmas, nfev + result.nfev)


def _with_jacobian_covariance(model, result: LeastSquaresResult, data, use_x, sigmas, nfev) -> FitResult:
    values = result.values
    specs = {s.name: s for s in model.param_specs}
    free = tuple(n for n in result.varying if not specs[n].on_bound(values[n]))
    J = jacobian(lambda p: _residual_vector(model, p, data, use_x, sigmas), values, free, specs)
    return result_of(model, values, free, normal_inverse(J), data, use_x, sigmas, bool(result.success),
                     str(result.message), int(nfev))


def _check_effects(model: Model, data: FitData, values: Mapping[str, float]) -> None:
    """Each effect finite at the fitted lines with its start values (an effect file's formula may not be)."""
    freqs = [data.impedance.freqs] + ([data.displacement.freqs] if model.with_displacement else [])
    s = 2j * np.pi * np.unique(np.concatenate(freqs))
    for effect in model.effects:
        effect.check_finite(s, values, "the fitted lines")


def _at_bounds(model: Model, result: LeastSquaresResult) -> set[str]:
    held = set()
    for name in result.varying:
        value, spec = result.values[name], model.spec(name)
        scale = max(abs(value), abs(spec.default), 1e-30)
        if min(value - spec.min, spec.max - value) <= 1e-6 * scale:
            held.add(name)
    return held


def _result(model, result: LeastSquaresResult, data, use_x, sigmas, nfev) -> FitResult:
    covar = None if result.covar is None else np.asarray(result.covar)
    return result_of(model, dict(result.values), result.varying, covar, data, use_x, sigmas, bool(result.success),
                     str(result.message), int(nfev))


def result_of(model: Model, values: dict[str, float], varying: tuple[str, ...], covar: np.ndarray | None,
              data: FitData, use_x: bool, sigmas: dict[str, np.ndarray], success: bool, message: str, nfev: int,
              birge_scaled: bool = False, method: str = "joint") -> FitResult:
    """The FitResult of `values`: each channel's chi^2, and the covariance Birge-scaled (unless it already is)."""
    channels: dict[str, ChannelFit] = {}
    n_total = 0
    for name in CHANNELS[: 2 if use_x else 1]:
        tf = data.channel(name)
        s = 2j * np.pi * tf.freqs
        model_values = model.impedance(s, values) if name == "impedance" else model.displacement(s, values)
        parts = _channel_residual(model_values, tf, sigmas[name])
        chi2 = float(sum(np.sum(part**2) for part in parts))
        n_points = len(parts) * len(tf.freqs)
        channels[name] = ChannelFit(name=name, freqs=tf.freqs, measured=tf.value, model=model_values,
                                    std=sigmas[name] * np.sqrt(2.0), chi2=chi2, n_points=n_points, chi2_red=0.0,
                                    has_phase=tf.has_phase)
        n_total += n_points
    k = len(varying)
    chi2 = sum(ch.chi2 for ch in channels.values())
    # Parameters are shared out to channels by their share of the data.
    for name, ch in channels.items():
        dof = max(ch.n_points - k * ch.n_points / n_total, 1.0)
        channels[name] = ChannelFit(name=ch.name, freqs=ch.freqs, measured=ch.measured, model=ch.model, std=ch.std,
                                    chi2=ch.chi2, n_points=ch.n_points, chi2_red=ch.chi2 / dof,
                                    has_phase=ch.has_phase)
    chi2_red = chi2 / max(n_total - k, 1)
    noise_known = all(data.channel(name).noise_known for name in channels)
    # Known noise: the Birge ratio, never below 1. Unknown noise: the residual's
    # own scatter sets the scale (as lmfit's scale_covar does).
    birge = 1.0 if birge_scaled else max(1.0, chi2_red) if noise_known else chi2_red
    covar = None if covar is None else covar * birge
    stderr: dict[str, float | None] = {n: None for n in values}
    if covar is not None:
        for i, name in enumerate(varying):
            stderr[name] = float(np.sqrt(covar[i, i])) if covar[i, i] >= 0 else None
    return FitResult(model=model, values=values, stderr=stderr, varying=varying, covar=covar, channels=channels,
                     chi2=chi2, n_data=n_total, success=success, message=message, nfev=nfev, noise_known=noise_known,
                     method=method)
