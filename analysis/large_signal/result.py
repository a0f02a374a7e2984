"""The large-signal result of one driver's recordings: curves, derived limits, validity, predictions, JSON.

    large_signal(recordings or paths, max_order, thresholds, predict=...) -> LargeSignalResult

The JSON (``as_json``) is the contract of `linpar large-signal --json`:
"x_unit", "curves" (polynomials in ascending powers of x in m, with their
1-sigma, covariance and covered range), "offset_m", "limits", "model" (the
fit's chi^2, the orders, the terms and constants), "validity" (the range,
each recording's residuals and distortion explained, and the flags a user
must read) and "distortion" (the predictions asked for).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import numpy as np

from analysis.large_signal.data import LargeSignalError, recording_data
from analysis.large_signal.distortion import RecordingFit, harmonics, intermodulation, multitone_prediction, \
    recording_fit
from analysis.large_signal.identify import MAX_ORDER, Identification, describe_orders, identify
from analysis.large_signal.limits import Derived, LimitThresholds, derived
from analysis.large_signal.model import LargeSignalModel, model_of
from analysis.large_signal.simulate import SimulationDiverged
from analysis.large_signal.stepping import VOLTAGE_DISTORTION_DB, clipped_inputs, distortion_db
from analysis.large_signal.trust import delay_doubtful, delay_not_found, delays_found, verdict
from analysis.recording.format import Recording, read_recording
from analysis.session import recording_header

# Flags: a misfit this many times the noise; explained distortion below this; a band wider than this at the edges.
CHI2_RED_DOUBTFUL = 2.0
EXPLAINED_DOUBTFUL = 50.0
EDGE_SIGMA_DOUBTFUL = 0.05


@dataclass(frozen=True, slots=True)
class Prediction:
    """What to predict besides the recordings: a level (V RMS), and a sine / two tones at it."""

    level_rms_v: float
    sine_hz: float | None = None
    two_tones_hz: tuple[float, float] | None = None


@dataclass(frozen=True, slots=True, eq=False)
class LargeSignalResult:
    model: LargeSignalModel
    identification: Identification
    derived: Derived
    thresholds: LimitThresholds
    fits: tuple[RecordingFit, ...]
    flags: tuple[str, ...]
    predictions: tuple[dict, ...]
    driver: dict
    header: dict = field(default_factory=dict)     # traceability (analysis.session) of the first recording

    @property
    def verdict(self) -> str:
        """red: not to be trusted (a laser delay not found, trust.py); yellow: flags to read; green: none."""
        return verdict(self.identification, self.flags)

    def as_json(self) -> dict:
        ident, model = self.identification, self.model
        chi2 = {eq: value / max(n, 1) for eq, (value, n) in ident.solution.chi2_by_equation.items()}
        chi2["total"] = ident.solution.chi2_red
        curves = {name: curve.as_json() for name, curve in model.curves.items()}
        orders = ident.orders
        terms = {"Le_i": {"present": orders.le_i > 0, "q1_h_per_a": _scalar(model, "q1"),
                          "q2_h_per_a2": _scalar(model, "q2")},
                 "Rms_v": {"present": orders.rms_v, "r_kg_s_per_m2": _scalar(model, "r")},
                 "creep": {"present": orders.creep, "lambda": model.lam if orders.creep else None,
                           "kappa_n_per_m": _scalar(model, "kappa")},
                 "L2_x": {"present": orders.l2 > 0}}
        parameters = {name: {"value": s.value, "std": _finite(s.std)} for name, s in model.scalars.items()
                      if name in ("RE", "R2", "Mms", "Rms")}
        parameters["L2"] = {"value": model.L20, "std": None}
        parameters["tau2"] = {"value": model.tau2, "std": None}
        recordings = []
        found = delays_found(ident)
        for k, fit in enumerate(self.fits):
            entry = fit.as_json()
            entry.update({"offset_m": ident.offsets[k], "offset_std_m": _finite(ident.offsets_std[k]),
                          "laser_delay_s": ident.delays[k],
                          "laser_delay_std_s": ident.delays_std[k] if ident.data[k].laser_delay_possible else None,
                          "laser_delay_at_limit": ident.delay_at_limit(k),
                          "laser_delay_search_centre_s": ident.delay_centres[k],
                          "laser_delay_found": found[k],
                          "noise_chi2_red": dict(ident.noise_chi2_red[k]),
                          "peak_displacement_m": _peak(ident, k)})
            recordings.append(entry)
        return {
            "x_unit": "m",
            "curves": curves,
            "offset_m": self.derived.offset_m,
            "limits": {name: limit.as_json() for name, limit in self.derived.limits.items()},
            "derived": self.derived.as_json(),
            "model": {"chi2_red": chi2, "aic": ident.solution.aic, "bic": ident.solution.bic,
                      "n_data": ident.solution.n_data, "n_parameters": ident.solution.n_params,
                      "orders": {"Bl": orders.bl, "Kms": orders.kms, "Le": orders.le, "L2": orders.l2},
                      "description": describe_orders(orders), "terms": terms, "parameters": parameters},
            "validity": {"verdict": self.verdict, "x_range_m": list(model.x_range), "recordings": recordings,
                         "flags": list(self.flags)},
            "distortion": {"predictions": list(self.predictions)},
            "thresholds": {"bl_ratio": self.thresholds.bl_ratio,
                           "compliance_ratio": self.thresholds.compliance_ratio,
                           "le_change": self.thresholds.le_change},
            "driver": self.driver,
        }


def large_signal(items: Sequence[Recording | str | Path], max_order: int = MAX_ORDER,
                 thresholds: LimitThresholds = LimitThresholds(), predictions: Sequence[Prediction] = ()
                 ) -> LargeSignalResult:
    """Identify, derive, judge and predict from recordings of one driver (LargeSignalError: one line)."""
    recordings = [item if isinstance(item, Recording) else read_recording(item) for item in items]
    if not recordings:
        raise LargeSignalError("a large-signal identification needs at least one recording")
    driver = _one_driver(recordings)
    data = [recording_data(r, _label(r, k)) for k, r in enumerate(recordings)]
    ident = identify(data, max_order)
    model = model_of(ident)
    limits = derived(model, thresholds)
    fits = tuple(recording_fit(model, d, ident.offsets[k], ident.delays[k], ident.voltage_residual_percent[k])
                 for k, d in enumerate(data))
    done = [_prediction(model, data, p) for p in predictions]
    flags = _flags(model, ident, limits, fits) + [p["failed"] for p in done if p.get("failed")]
    for recording, d, fit in zip(recordings, data, fits):
        clipped = clipped_inputs(recording)
        if clipped:
            flags.append(f"{d.label}: the {' and '.join(clipped)} input reached its converter's full scale: the "
                         f"curves are wrong where it clipped; lower the sense gain or the level and measure again")
        distorted = distortion_db(np.fft.rfft(d.u, axis=1), d.excited_bins)
        if distorted >= VOLTAGE_DISTORTION_DB:
            flags.append(f"{d.label}: the voltage itself is distorted ({distorted:.0f} dB): the amplifier or the "
                         f"sound card limits at {fit.drive_rms_v:.3g} V (the curves rest on the voltage measured)")
    return LargeSignalResult(model, ident, limits, thresholds, fits, tuple(flags), tuple(done), driver,
                             recording_header(recordings[0]))


def _prediction(model: LargeSignalModel, data, p: Prediction) -> dict:
    """Distortion predicted at a level: the largest recording's multitone scaled, and a sine / two tones."""
    loudest = max(data, key=lambda d: float(np.std(d.mean("u"))))
    out: dict = {"level_rms_v": p.level_rms_v}
    try:
        out["multitone"] = multitone_prediction(model, loudest, p.level_rms_v)
        if p.sine_hz is not None:
            out["sine"] = harmonics(model, p.sine_hz, p.level_rms_v, loudest.sample_rate)
        if p.two_tones_hz is not None:
            out["two_tones"] = intermodulation(model, *p.two_tones_hz, p.level_rms_v, loudest.sample_rate)
    except SimulationDiverged as exc:
        out["failed"] = f"prediction at {p.level_rms_v:g} V: {exc}"
    return out


def _flags(model: LargeSignalModel, ident: Identification, limits: Derived, fits) -> list[str]:
    # First: a laser delay not found makes every other line moot (the curves are not a measurement).
    flags = [reason for reason in (delay_not_found(ident, k) for k in range(len(ident.data))) if reason]
    flags += [reason for reason in (delay_doubtful(ident, k) for k in range(len(ident.data))) if reason]
    lo, hi = model.x_range
    if ident.solution.chi2_red > CHI2_RED_DOUBTFUL:
        flags.append(f"the model leaves a misfit {ident.solution.chi2_red:.1f} times the noise: the curves are "
                     f"approximate and their bands widened by it; the driver may have physics the model lacks")
    x = np.linspace(lo, hi, 201)
    for name in ("Bl", "Kms", "Le"):
        curve = model.curves[name]
        values = curve(x)
        if np.any(values <= 0):
            flags.append(f"{name}(x) is not positive at {x[np.argmax(values <= 0)] * 1e3:+.2f} mm within the "
                         f"measured range: the identification failed there")
            continue
        edge = curve.sigma(np.array([lo, hi])) / np.abs(curve(np.array([lo, hi])))
        if np.max(edge) > EDGE_SIGMA_DOUBTFUL:
            flags.append(f"{name}(x) is uncertain at the edges of the measured range (±{np.max(edge) * 100:.0f} %)")
    for name, limit in limits.limits.items():
        if limit.beyond_range:
            flags.append(f"{name} lies beyond the measured range (more than {limit.value * 1e3:.2f} mm on the "
                         f"{limit.side} side): measure at a higher level to find it")
    if limits.offset_at_edge:
        flags.append("Bl(x) has its maximum at an edge of the measured range: the offset is a bound, not a value")
    for fit in fits:
        if fit.failed:
            flags.append(f"{fit.label}: {fit.failed}")
            continue
        current = fit.channels["current"]
        if math.isfinite(current.explained_percent) and current.explained_percent < EXPLAINED_DOUBTFUL:
            flags.append(f"{fit.label}: the model explains only {current.explained_percent:.0f} % of the current's "
                         f"distortion (physics the model lacks, or a distorting amplifier)")
    return flags


def _one_driver(recordings: Sequence[Recording]) -> dict:
    names = {str(r.driver.get("name")) for r in recordings if r.driver and r.driver.get("name")}
    serials = {str(r.driver.get("serial")) for r in recordings if r.driver and r.driver.get("serial")}
    if len(names) > 1 or len(serials) > 1:
        what = ", ".join(sorted(names | serials))
        raise LargeSignalError(f"the recordings are of different drivers ({what}): give recordings of one driver")
    return dict(recordings[0].driver or {})


def _label(recording: Recording, k: int) -> str:
    return recording.source.name if recording.source is not None else f"recording {k + 1}"


def _peak(ident: Identification, k: int) -> float:
    x = ident.data[k].mean("x")
    return float(np.max(np.abs(x - x.mean())))


def _scalar(model: LargeSignalModel, name: str) -> dict | None:
    s = model.scalars.get(name)
    return None if s is None else {"value": s.value, "std": _finite(s.std)}


def _finite(value) -> float | None:
    return float(value) if value is not None and math.isfinite(value) else None
