"""The large-signal result as text for a technician: customary units, values to what their uncertainty supports."""
from __future__ import annotations

import math

import numpy as np

from analysis.large_signal.curves import compliance_of
from analysis.large_signal.identify import describe_orders
from analysis.large_signal.result import LargeSignalResult
from analysis.level_series import concise

POINTS_MM = (-8.0, -6.0, -4.0, -3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0)


def format_large_signal(result: LargeSignalResult) -> str:
    model, ident, d = result.model, result.identification, result.derived
    lo, hi = model.x_range
    name = result.driver.get("name") or "the driver"
    lines = [f"large-signal parameters of {name}, from {len(result.fits)} recording(s); "
             f"x measured from {lo * 1e3:+.2f} to {hi * 1e3:+.2f} mm (positive: outwards)",
             f"curves (orders chosen by BIC): {describe_orders(ident.orders)}", ""]
    if result.verdict == "red":
        # Before any number: a result whose laser delay was not found is not a measurement (trust.py).
        lines += ["NOT TO BE TRUSTED: the laser's delay was not found; the values below are not a measurement "
                  "(see the first lines under \"to read with care\")", ""]
    bl, kms, le = model.Bl, model.Kms, model.Le
    lines.append("at rest:  Bl(0) " + _value(bl, 0.0, 1.0, "T·m") + "   Kms(0) " + _value(kms, 0.0, 1e-3, "N/mm")
                 + "   Le(0) " + _value(le, 0.0, 1e3, "mH"))
    scalars = model.scalars
    lines.append(f"          RE {concise(scalars['RE'].value, scalars['RE'].std)} Ω   Mms "
                 f"{concise(scalars['Mms'].value * 1e3, scalars['Mms'].std * 1e3)} g   Rms "
                 f"{concise(scalars['Rms'].value, scalars['Rms'].std)} kg/s   L2(0) {model.L20 * 1e3:.4f} mH, "
                 f"R2 {concise(scalars['R2'].value, scalars['R2'].std)} Ω")
    lines += ["", f"{'x mm':>7}{'Bl T·m':>16}{'Kms N/mm':>16}{'Cms mm/N':>12}{'Le mH':>16}"]
    for x_mm in (p for p in POINTS_MM if lo * 1e3 <= p <= hi * 1e3):
        x = x_mm * 1e-3
        cms = compliance_of(kms, np.array([x]))[0]
        lines.append(f"{x_mm:>7.1f}{_value(bl, x, 1.0):>16}{_value(kms, x, 1e-3):>16}{cms * 1e3:>12.4f}"
                     f"{_value(le, x, 1e3):>16}")
    lines += ["", f"coil rest offset: {d.coil_advice()}",
              f"stiffness asymmetry: {d.asymmetry_percent:+.1f} % (Kms at ±{d.asymmetry_at_m * 1e3:.2f} mm)"]
    for limit in d.limits.values():
        if limit.value is None:
            continue
        text = f"more than {limit.value * 1e3:.2f} mm (beyond the measured range)" if limit.beyond_range else \
            f"{limit.value * 1e3:.2f} mm" + (f" ± {limit.std * 1e3:.2f}" if math.isfinite(limit.std) and
                                              limit.std * 1e3 >= 0.005 else "") + f" ({limit.side} side)"
        lines.append(f"{limit.name} ({limit.criterion}): {text}")
    terms = []
    if ident.orders.le_i:
        terms.append("Le(i)")
    if ident.orders.rms_v:
        terms.append("Rms(v)")
    if ident.orders.l2:
        terms.append("L2(x)")
    if ident.orders.creep:
        terms.append(f"creep (lambda {model.lam:.3f})")
    lines += ["", "terms the data support besides the curves: " + (", ".join(terms) or "none")]
    chi2 = ident.solution.chi2_by_equation
    lines.append("fit: reduced chi^2 " + ", ".join(f"{eq} {c / max(n, 1):.2f}" for eq, (c, n) in chi2.items()))
    # The weights count a misfit as noise (weights.misfit_variance); against the noise alone it shows (trust.py).
    alone = {eq: max(r[eq] for r in ident.noise_chi2_red) for eq in ident.noise_chi2_red[0]}
    lines.append("     against the lines' noise alone (largest of the recordings): "
                 + ", ".join(f"{eq} {value:.3g}" for eq, value in alone.items()))
    for k, fit in enumerate(result.fits):
        if fit.failed:
            lines.append(f"  {fit.label}: {fit.failed}")
            continue
        parts = []
        if ident.data[k].laser_delay_possible:
            parts.append(f"laser delay {concise(ident.delays[k] * 1e6, ident.delays_std[k] * 1e6)} us")
        for channel in fit.channels.values():
            if math.isfinite(channel.measured_db):
                parts.append(f"{channel.channel} distortion {channel.measured_db:.1f} dB measured, "
                             f"{channel.predicted_db:.1f} dB predicted ({channel.explained_percent:.0f} % explained)")
            else:
                parts.append(f"{channel.channel} distortion at the noise (predicted {channel.predicted_db:.1f} dB)")
        lines.append(f"  {fit.label} ({fit.drive_rms_v:.3g} V): " + "; ".join(parts))
    for p in result.predictions:
        lines += ["", f"predicted at {p['level_rms_v']:g} V RMS:"]
        if p.get("failed"):
            lines.append(f"  {p['failed']}")
            continue
        mt = p["multitone"]
        lines.append(f"  multitone: peak {mt['peak_displacement_m'] * 1e3:.2f} mm, current distortion "
                     f"{_db(mt['current']['predicted_db'])}, displacement {_db(mt['displacement']['predicted_db'])}")
        if "sine" in p:
            s = p["sine"]
            lines.append(f"  sine {s['frequency_hz']:.1f} Hz: current H2 {_db(s['current'].get('H2_db'))} "
                         f"H3 {_db(s['current'].get('H3_db'))}, displacement H2 "
                         f"{_db(s['displacement'].get('H2_db'))} H3 {_db(s['displacement'].get('H3_db'))}")
        if "two_tones" in p:
            t = p["two_tones"]
            lines.append(f"  two tones {t['f1_hz']:.1f} + {t['f2_hz']:.1f} Hz: current IMD2 "
                         f"{_db(t['current']['IMD2_db'])} IMD3 {_db(t['current']['IMD3_db'])}")
    if result.flags:
        lines += ["", "to read with care:"] + [f"  - {flag}" for flag in result.flags]
    return "\n".join(lines)


def _value(curve, x: float, scale: float, unit: str = "") -> str:
    value = float(curve(np.array([x]))[0]) * scale
    sigma = float(curve.sigma(np.array([x]))[0]) * abs(scale)
    return concise(value, sigma) + (f" {unit}" if unit else "")


def _db(value) -> str:
    return "n/a" if value is None else f"{value:.1f} dB"
