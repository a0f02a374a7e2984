"""Drift: did the system change between the first and the last periods?

Each analysed period is transformed; at the well-measured excited lines
(SNR >= x_line_snr_db) each period gives

    voltage:               e_p = U_p                  (the generator's level)
    current, displacement: e_p = Y_p - H U_p,  H = mean(Y) / mean(U)
                           (the change of the driver, not of the level that drove it)

The first k and the last k periods (k = drift_periods, at most half of them)
are compared:

    delta^2 = sum |mean_last(e) - mean_first(e)|^2 / sum |mean(Y)|^2     relative rms change
    noise^2 = sum (2/k) s^2 / sum |mean(Y)|^2,  s^2 = sum_p |e_p+1 - e_p|^2 / (2 (P-1))
    drift   = sqrt(max(delta^2 - noise^2, 0))

s^2 is the noise of one period from successive differences (von Neumann):
the scatter about the mean would count the drift itself as noise (a steady
drift over P periods adds (P^2-1)/12 steps^2 to it, one step^2 to this).
Reported when delta^2 > drift_significance * noise^2 and drift is above
drift_yellow (typically a voice coil warming up: RE rises; a suspension
warming up: fs falls; a laser mount that creeps). With 2 periods drift cannot
be told from noise and is never reported.
"""
from __future__ import annotations

import numpy as np

from analysis.recording.format import Recording
from analysis.spectra import Spectra, period_spectra
from analysis.thresholds import ValidityThresholds
from analysis.validity.findings import DRIFT, Finding, Severity, graded
from analysis.validity.spectral import line_snr_db

_REMEDY = {
    "voltage": "let the amplifier warm up (more settle periods) and check its level is steady",
    "current": "the driver changed during the measurement (voice coil warming?): use more settle periods, "
               "a lower level, or fewer periods",
    "displacement": "the displacement changed during the measurement: check the laser's mount and the driver's "
                    "fixing; use more settle periods",
}


def drift_findings(recording: Recording, spectra: Spectra,
                   th: ValidityThresholds) -> dict[str, tuple[list[Finding], float]]:
    """Per channel of the spectra: the drift finding (if any) and the measured drift (fraction, NaN if unknown)."""
    p = spectra.n_periods
    k = min(th.drift_periods, p // 2)
    excited = spectra.excited_bins
    if k < 1 or p < 3:
        return {name: ([], float("nan")) for name in spectra.channels}
    per_period = {name: spectra.excited_per_period[name] if name in spectra.excited_per_period
                  else period_spectra(recording.periods(name))[:, excited] for name in spectra.channels}
    u_mean = spectra.channels["voltage"].mean[excited]
    out = {}
    for name, spec in spectra.channels.items():
        y = spec.mean[excited]
        e = per_period[name]
        if name != "voltage":
            with np.errstate(divide="ignore", invalid="ignore"):
                h = y / u_mean
            e = e - np.where(np.isfinite(h), h, 0.0) * per_period["voltage"]
        good = line_snr_db(y, spec.var_mean[excited], th.noise_pool_lines) >= th.x_line_snr_db
        signal = float(np.sum(np.abs(y[good]) ** 2))
        if not good.any() or signal <= 0:
            out[name] = ([], float("nan"))
            continue
        e = e[:, good]
        diff = e[-k:].mean(axis=0) - e[:k].mean(axis=0)
        step = np.diff(e, axis=0)
        var_single = np.sum(step.real**2 + step.imag**2, axis=0) / (2.0 * (p - 1))
        delta2 = float(np.sum(np.abs(diff) ** 2)) / signal
        noise2 = float(np.sum(2.0 / k * var_single)) / signal
        drift = float(np.sqrt(max(delta2 - noise2, 0.0)))
        severity = graded(drift, th.drift_yellow, th.drift_red, below=False)
        if severity is Severity.GREEN or delta2 <= th.drift_significance * noise2:
            out[name] = ([], drift)
            continue
        what = "level" if name == "voltage" else f"{name} per volt"
        out[name] = ([Finding(
            name, DRIFT, severity,
            f"{name}: the {what} changed by {drift:.2%} (rms over {int(good.sum())} lines) between the first and "
            f"the last {k} periods; noise alone would give {np.sqrt(noise2):.2%} (limits: yellow "
            f"{th.drift_yellow:.1%}, red {th.drift_red:.1%})", _REMEDY[name], drift)], drift)
    return out
