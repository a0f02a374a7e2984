"""Where each serial laser's delay search starts: the small-signal step's linear model, placed from the data.

The large-signal identification searches each recording's laser delay on a
grid of +-DELAY_LIMIT_S (1 ms, fitting.py), which a USB serial link's
latency (1 - 25 ms, with jitter) leaves far behind. Every step of a plan is
a measurement of its own, aligned by its own host times, so each carries a
delay of its own; what they share is the driver. So:

1. the small-signal step (the recording at the lowest voltage) gives the
   linear model: Z fitted with the electrical effects of the linear analysis;
2. each recording's Hx against that model with Bl = 1 is exp(-s tau) / Bl
   (analysis/laser_delay.py), searched over -10 ... +40 ms;
3. its search starts there when the data place it, else from the small-signal
   step's delay (and from 0 when neither is placed: the trust verdict then
   says so, trust.py).

The linear model is only the start: it misses the large-signal physics (a
few degrees of Hx's phase at high levels, ~0.1 ms), which the +-1 ms search
around it then takes up.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from analysis.effects import DEFAULT_EFFECTS, Site, get_effect
from analysis.fit.least_squares import FitData, fit_model
from analysis.laser_delay import DelaySearch, find_delay
from analysis.large_signal.data import RecordingData
from analysis.model.composed import Model
from analysis.spectra import period_spectra, transfer_from_periods


def delay_centres(data: Sequence[RecordingData]) -> list[float]:
    """Each recording's laser delay start (s; 0 where the laser is on the audio's clock): module doc."""
    serial = [k for k, d in enumerate(data) if d.laser_delay_possible]
    centres = [0.0] * len(data)
    if not serial:
        return centres
    reference = min(serial, key=lambda k: float(np.sqrt(np.mean(data[k].mean("u") ** 2))))
    model = Model(tuple(get_effect(i) for i in DEFAULT_EFFECTS), with_displacement=True)
    values = _linear_values(data[reference], model)
    if values is None:
        return centres
    searches = {k: _search(data[k], model, values) for k in serial}
    fallback = searches[reference].delay_s if searches[reference].placed else 0.0
    for k, search in searches.items():
        centres[k] = search.delay_s if search.placed else fallback
    return centres


def _lines(d: RecordingData) -> np.ndarray:
    return d.excited_bins[d.excited_bins <= d.mechanical_bins[-1]]


def _transfer(d: RecordingData, numerator: np.ndarray, denominator: np.ndarray, bins: np.ndarray, name: str,
              unit: str):
    num, den = (period_spectra(a)[:, bins] for a in (numerator, denominator))
    return transfer_from_periods(name, unit, num, den, bins, d.bin_width)


def _linear_values(small: RecordingData, model: Model) -> dict[str, float] | None:
    """The linear model's values from the small-signal step's Z (Bl = 1: Hx's scale is left to the ratio)."""
    impedance = _transfer(small, small.u, small.i, small.excited_bins, "impedance", "ohm")
    keep = np.isfinite(impedance.value) & np.isfinite(impedance.std) & (impedance.std > 0)
    if keep.sum() < 8:
        return None
    impedance = impedance.restricted(keep)
    electrical = Model(tuple(e for e in model.effects if e.site is not Site.DISPLACEMENT), with_displacement=False)
    try:
        z_fit = fit_model(FitData(impedance), electrical)
    except (ValueError, ArithmeticError):
        return None
    start = {p.name: p.default for p in model.param_specs}
    return {**start, **z_fit.values, "Bl": 1.0, "tau_x": 0.0}


def _search(d: RecordingData, model: Model, values: dict[str, float]) -> DelaySearch:
    bins = _lines(d)
    hx = _transfer(d, d.x, d.u, bins, "displacement", "m/V")
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = hx.value / model.displacement(2j * np.pi * hx.freqs, values)
        weight = np.abs(hx.value / hx.std) ** 2
    return find_delay(hx.freqs, ratio, weight)
