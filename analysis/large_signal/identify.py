"""Identify Bl(x), Kms(x), Le(x) (and L2(x), Le(i), Rms(v), creep) from recordings of one driver.

The equations (columns.py) are linear in every coefficient once x is
measured, so the identification is a weighted least squares, wrapped in
three small searches for what they are not linear in:

1. the rest position of each recording: a laser measures a distance with an
   arbitrary offset (the serial laser's stream has its mean removed), and
   under drive the cone's mean moves off its rest position (an asymmetric
   Kms(x) or Bl(x) pushes it). x = x_measured + d, with d such that the
   period's mean force vanishes: mean[Bl(x) i + reluctance - Rms(v) v^2 v -
   Kms(x) x] = 0 (the static balance: the mass, the damping and the creep
   average to zero over a period; creep is taken as absent at DC, where the
   log law diverges). The polynomials are thus centred on the rest position
   by construction: Kms(x) x vanishes at x = 0;
2. the laser's delay, for a serial laser on a clock of its own (the
   alignment leaves the link's latency, up to tens of ms through a USB
   adapter; tens of microseconds left would be 2 degrees at 100 Hz, which
   the mechanical equation would misread as damping): searched +-1 ms
   around where the small-signal step's linear model places it
   (delay_start.py);
3. tau2 = L2 / R2 and creep's lambda: variable projection (the least squares
   solved for the rest at each try, scipy's bounded minimiser over these).

The weights come from the scatter between periods (solve.py): a first
solution from the electrical equation alone (weights from the voltage's and
the current's own noise), then the mechanical one with Bl(x) from it, then
every line's weight from the per-period error of that solution, refined
twice, and on until the laser delays settle (_settle; a serial laser's
delays first scanned with the weights of the noise alone). The orders are then chosen by BIC (each term's order in turn, twice
over), among 0 .. max_order for Bl, Kms and Le, 0 .. 4 for L2(x), and with or
without Le(i), Rms(v) and creep: a term is kept where the data support it.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from analysis.large_signal.columns import ELECTRICAL, Nuisance, Orders
from analysis.large_signal.covariance import covariance
from analysis.large_signal.data import LargeSignalError, RecordingData
from analysis.large_signal.delay_start import delay_centres
from analysis.large_signal.fitting import DELAY_TOLERANCE_S, FitState, delay_at_limit
from analysis.large_signal.solve import Solution, solve

MAX_ORDER = 6
HIGHEST_ORDER = 8          # what --order may ask for: beyond, the powers of x are too alike to tell apart
MAX_L2_ORDER = 4
_REFINEMENTS = 2
_MAX_PASSES = 8
DELAY_SETTLED_S = 1e-6       # a laser delay that moves less in a pass has settled (~0.2 degree at 1.76 kHz)


@dataclass(frozen=True, slots=True, eq=False)
class Identification:
    """The raw outcome: coefficients in scaled units (columns.py), their covariance and the fit's bookkeeping."""

    orders: Orders
    names: tuple[tuple[str, int], ...]
    theta: np.ndarray
    cov: np.ndarray                 # scaled by chi^2_red when above 1
    solution: Solution
    nuisance: Nuisance
    x_scale: float
    offsets: tuple[float, ...]      # m, added to each recording's measured x (the rest position)
    offsets_std: tuple[float, ...]
    delays: tuple[float, ...]       # s, the laser's delay taken out of each recording
    delays_std: tuple[float, ...]   # s, their 1-sigma (0 where none was searched): the noise's and the search's
    data: tuple[RecordingData, ...]
    delay_centres: tuple[float, ...]  # s, where each delay search was centred (delay_start.py)
    weights: tuple[tuple[np.ndarray, np.ndarray], ...]
    bic_table: tuple[tuple[str, float], ...]     # the orders tried and their BIC, for the report
    voltage_residual_percent: tuple[float, ...]  # the electrical equation's rms misfit re the voltage, per recording
    noise_chi2_red: tuple[dict, ...]  # per recording, equation -> mean |residual|^2 / its noise alone (noise_misfit)

    def delay_at_limit(self, k: int) -> bool:
        """Whether recording k's laser delay sits on the search's limit (the true one may lie beyond it)."""
        return self.data[k].laser_delay_possible and delay_at_limit(self.delays[k], self.delay_centres[k])

    def value(self, name: str, power: int = 0) -> float:
        return float(self.theta[self.names.index((name, power))]) if (name, power) in self.names else 0.0

    def block(self, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(powers, coefficients, covariance) of one group of coefficients."""
        idx = [k for k, (n, _) in enumerate(self.names) if n == name]
        powers = np.array([self.names[k][1] for k in idx], dtype=int)
        return powers, self.theta[idx], self.cov[np.ix_(idx, idx)]


def identify(data: Sequence[RecordingData], max_order: int = MAX_ORDER) -> Identification:
    """The large-signal model of the recordings' driver (module doc); LargeSignalError when it cannot be found."""
    if not data:
        raise LargeSignalError("a large-signal identification needs at least one recording")
    if not (isinstance(max_order, int) and 0 <= max_order <= HIGHEST_ORDER):
        raise LargeSignalError(f"order {max_order!r}: expected a whole number from 0 to {HIGHEST_ORDER}")
    top = Orders(bl=max_order, kms=max_order, le=max_order, l2=min(max_order, MAX_L2_ORDER), le_i=2, rms_v=True,
                 creep=True)
    fit = FitState(data, top, delay_centres(data))
    fit.initial_weights()
    nu = Nuisance()
    theta = fit.mechanical_start(top, nu, solve(fit.blocks(top, nu, only=ELECTRICAL)).theta)
    nu = _with_ws(nu, top, theta)
    if fit.has_laser_delays:
        # The coarse scan weighs each line by its noise alone: with the misfit of the zero-delay start counted
        # as noise, the lines that tell the delay would weigh least, and the scan's minima stayed near 0
        # (25-60 us short on the JACK rig, Kms(0) then up to +1.2 %).
        fit.update_weights(top, nu, theta, misfit=False)
        nu = fit.nuisance(top, nu)
        fit.scan_delays(top, nu)
        theta = fit.solve(top, nu).theta
    nu, theta = _settle(fit, top, nu, theta, _REFINEMENTS)
    orders, table = _select_orders(fit, top, nu)
    nu = nu if orders.creep else dataclasses.replace(nu, lam=0.0)
    nu, _ = _settle(fit, orders, nu, fit.solve(orders, nu).theta, 1, new_ws=False)
    final = fit.solve(orders, nu)
    cov, delays_std = covariance(fit, orders, nu, final)
    scale = max(final.chi2_red, 1.0)
    return Identification(orders, tuple(orders.names()), final.theta, cov * scale, final, nu, fit.x_scale,
                          tuple(fit.offsets), tuple(fit.offsets_std), tuple(fit.delays),
                          tuple(_delay_std(std * np.sqrt(scale), d) for std, d in zip(delays_std, fit.data)),
                          tuple(fit.data), tuple(fit.centres),
                          tuple(fit.weights), tuple(table),
                          tuple(fit.voltage_residual_percent(orders, nu, final.theta)),
                          tuple(fit.noise_misfit(orders, nu, final.theta)))


def _delay_std(statistical: float, data: RecordingData) -> float:
    """A searched delay's 1-sigma: the noise's (a few ns with sharp lines) and the search's resolution (Brent to
    DELAY_TOLERANCE_S, taken as uniform) in quadrature."""
    if not data.laser_delay_possible:
        return 0.0
    return float(np.hypot(statistical, DELAY_TOLERANCE_S / np.sqrt(3.0)))


def _settle(fit: FitState, orders: Orders, nu: Nuisance, theta: np.ndarray, passes: int,
            new_ws: bool = True) -> tuple[Nuisance, np.ndarray]:
    """Weights, tau2 and lambda, laser delays, rest offsets and coefficients in turn: ``passes`` times, then on
    while a laser delay still moves (each depends on the others: a delay read with weights from another delay
    stops short of its own), at most _MAX_PASSES."""
    for done in range(1, _MAX_PASSES + 1):
        fit.update_weights(orders, nu, theta)
        nu = fit.nuisance(orders, nu)       # first: tau2 far off would pull the delay with it
        moved = fit.refine_delays(orders, nu)
        fit.fit_offsets(orders, nu, fit.solve(orders, nu).theta)
        theta = fit.solve(orders, nu).theta
        if new_ws:
            nu = _with_ws(nu, orders, theta)
        if done >= passes and moved < DELAY_SETTLED_S:
            break
    return nu, theta


def describe_orders(orders: Orders) -> str:
    extra = [f"L2(x) {orders.l2}" if orders.l2 else "", f"Le(i) {orders.le_i}" if orders.le_i else "",
             "Rms(v)" if orders.rms_v else "", "creep" if orders.creep else ""]
    return ", ".join([f"Bl {orders.bl}", f"Kms {orders.kms}", f"Le {orders.le}"] + [e for e in extra if e])


def _select_orders(fit: FitState, top: Orders, nu: Nuisance) -> tuple[Orders, list[tuple[str, float]]]:
    """Each term's order in turn to its lowest BIC, the others held; twice over, or until nothing changes."""
    current = top
    best = fit.solve(current, nu).bic
    table = [(describe_orders(current), best)]
    choices = (("bl", range(top.bl + 1)), ("kms", range(top.kms + 1)), ("le", range(top.le + 1)),
               ("l2", range(top.l2 + 1)), ("le_i", range(top.le_i + 1)), ("rms_v", (False, True)),
               ("creep", (False, True)))
    for _ in range(2):
        changed = False
        for name, options in choices:
            for option in options:
                trial = dataclasses.replace(current, **{name: option})
                if trial == current:
                    continue
                bic = fit.solve(trial, nu if trial.creep else dataclasses.replace(nu, lam=0.0)).bic
                table.append((describe_orders(trial), bic))
                if bic < best:
                    best, current, changed = bic, trial, True
        if not changed:
            break
    return current, table


def _with_ws(nu: Nuisance, orders: Orders, theta: np.ndarray) -> Nuisance:
    """Creep's reference: the small-signal resonance sqrt(Kms(0) / Mms) of the latest solution."""
    names = orders.names()
    k0, mms = theta[names.index(("Kms", 0))], theta[names.index(("Mms", 0))]
    if k0 > 0 and mms > 0:
        return dataclasses.replace(nu, ws=float(np.sqrt(k0 / mms)))
    return nu


