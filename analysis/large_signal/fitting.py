"""The state the large-signal identification's searches share (identify.py): data, offsets, delays, weights.

FitState keeps each recording's regressors (columns.py) at its present rest
offset and laser delay, the lines' weights (weights.py) and the noise part
of the normal equations (bias compensation), and solves the weighted least
squares for any choice of orders and nuisance parameters (solve.py). The
searches it offers: the nuisance (tau2, lambda) by variable projection, the
laser delays, and the rest offsets from the static force balance.
"""
from __future__ import annotations

import dataclasses
from typing import Sequence

import numpy as np
import scipy.optimize

from analysis.large_signal.columns import ELECTRICAL, MECHANICAL, Columns, Nuisance, Orders, build_columns, stacked
from analysis.large_signal.data import LargeSignalError, RecordingData
from analysis.large_signal.solve import Block, Solution, solution, solve, solve_normal
from analysis.large_signal.weights import misfit_variance, noise_variance

DELAY_LIMIT_S = 1e-3
DELAY_GRID_S = 50e-6       # the coarse scan's step: the valleys of chi^2 are ~280 us wide (1.76 kHz's period / 2)
DELAY_SCAN_S = 25e-6       # the step by which the search walks downhill to a bracket
DELAY_TOLERANCE_S = 2e-7
LAMBDA_MAX = 0.8
TAU2_RANGE_S = (1e-6, 1e-2)
# How closely the searches pin tau2 (in log10) and lambda. The coefficients' covariance (covariance.py) holds
# their uncertainty as that of the joint optimum; a search stopped short of it moves the coefficients along
# with it (Le(0), R2 and RE trade off against tau2), an error no band holds. At 4e-3 (1 % in tau2, ~100 times
# tau2's own sigma at the bench's noise) tau2 came out -1.7e-4 low on average, Le(0) -1.4 sigma low, and Le(x)'s
# 2-sigma band held the truth at 80 % of the points; at 1e-6 (a few more solves) at 93 % (docs/large-signal.md).
TAU2_TOLERANCE_LOG10 = 1e-6
LAMBDA_TOLERANCE = 1e-6
MECHANICAL_ONLY = ("Mms", "Rms", "Kms", "Rv", "creep")
NUISANCE_DEPENDENT = ("R2", "L2", "creep")     # columns.Columns.with_nuisance makes these


class FitState:
    """The state the searches share: the data, their offsets and delays, the columns and the weights."""

    def __init__(self, data: Sequence[RecordingData], max_orders: Orders, delay_centres: Sequence[float] = ()):
        self.data = list(data)
        self.max_orders = max_orders
        centred = [d.mean("x") - d.mean("x").mean() for d in self.data]
        self.x_scale = max(float(np.max(np.abs(x))) for x in centred)
        if not self.x_scale > 0:
            raise LargeSignalError("the displacement does not move: no curve can be identified")
        self.offsets = [0.0] * len(self.data)
        self.offsets_std = [0.0] * len(self.data)
        # Where each delay search is centred (delay_start.py: a serial link's latency, found from the data).
        self.centres = [float(c) for c in delay_centres] if len(delay_centres) else [0.0] * len(self.data)
        self.delays = list(self.centres)
        self._grams: dict = {}
        self.mean_cols: list[Columns] = [self.columns(k, False) for k in range(len(self.data))]
        self.weights: list[tuple[np.ndarray, np.ndarray]] = []
        self.max_names = max_orders.names()
        self._fixed = [n for n in self.max_names if n[0] not in NUISANCE_DEPENDENT]
        self.corrections: list[dict] = []
        self.misfits: list[tuple[np.ndarray, np.ndarray]] = []

    def columns(self, k: int, periods: bool) -> Columns:
        return build_columns(self.data[k], self.offsets[k], self.delays[k], self.x_scale, self.max_orders, periods)

    def rebuild(self, k: int) -> None:
        self.mean_cols[k] = self.columns(k, False)
        self._grams = {key: value for key, value in self._grams.items() if key[0] != k}

    def set_weights(self, weights: list[tuple[np.ndarray, np.ndarray]]) -> None:
        self.weights = weights
        self._grams = {}

    def blocks(self, orders: Orders, nu: Nuisance, only: str | None = None) -> list[Block]:
        names = orders.names()
        out = []
        for k, cols in enumerate(self.mean_cols):
            phi_e, phi_m = stacked(cols, names, nu)
            w_e, w_m = self.weights[k]
            if only in (None, ELECTRICAL):
                out.append(Block(phi_e, cols.target_e, w_e, ELECTRICAL, k))
            if only in (None, MECHANICAL):
                out.append(Block(phi_m, np.zeros(phi_m.shape[0], dtype=complex), w_m, MECHANICAL, k))
        return out

    def solve(self, orders: Orders, nu: Nuisance) -> Solution:
        """The weighted least squares at these orders and nuisance (the same as solve(self.blocks(...))).

        The inner products of the columns that do not depend on the nuisance
        are kept between calls (until the weights or the columns change): the
        searches then pay only for the few columns they move.
        """
        names = orders.names()
        fixed = [self._fixed.index(n) for n in names if n[0] not in NUISANCE_DEPENDENT]
        moving = [n for n in names if n[0] in NUISANCE_DEPENDENT]
        order = [k for k, n in enumerate(names) if n[0] not in NUISANCE_DEPENDENT] + \
                [k for k, n in enumerate(names) if n[0] in NUISANCE_DEPENDENT]
        p = len(names)
        gram, rhs = np.zeros((p, p)), np.zeros(p)
        parts = []
        for k, cols in enumerate(self.mean_cols):
            columns = cols.with_nuisance(nu)
            for eq, target, weight in ((ELECTRICAL, cols.target_e, self.weights[k][0]),
                                       (MECHANICAL, None, self.weights[k][1])):
                table = columns[0] if eq == ELECTRICAL else columns[1]
                if target is None:
                    target = np.zeros(table[names[0]].shape, dtype=complex)
                f_all, wf_h, g_ff, r_f = self._gram(k, eq, table, target, weight)
                d = np.stack([table[n] for n in moving], axis=-1) if moving else np.zeros((target.size, 0))
                wd = d * weight[:, None]
                g = np.block([[g_ff[np.ix_(fixed, fixed)], (wf_h @ d).real[fixed]],
                              [np.zeros((len(moving), len(fixed))), (wd.conj().T @ d).real]])
                g[len(fixed):, :len(fixed)] = g[:len(fixed), len(fixed):].T
                r = np.concatenate([r_f[fixed], (wd.conj().T @ target).real])
                gram[np.ix_(order, order)] += g
                rhs[order] += r
                parts.append((eq, target, weight, f_all, d))
        if self.corrections:
            index = [self.max_names.index(n) for n in names]
            noise_gram, noise_rhs = np.zeros_like(gram), np.zeros_like(rhs)
            for correction in self.corrections:
                for c_gram, c_rhs in correction.values():
                    noise_gram += c_gram[np.ix_(index, index)]
                    noise_rhs += c_rhs[index]
            theta, inverse = solve_normal(gram, rhs, noise_gram, noise_rhs)
        else:
            theta, inverse = solve_normal(gram, rhs)
        cov = inverse @ gram @ inverse
        by_order = theta[order]
        n_fixed = len(fixed)
        theta_fixed = np.zeros(len(self._fixed))      # the fixed columns' coefficients, unselected ones 0
        theta_fixed[fixed] = by_order[:n_fixed]
        out = solution(theta, cov, [(eq, target - f @ theta_fixed - d @ by_order[n_fixed:], weight)
                                    for eq, target, weight, f, d in parts])
        return dataclasses.replace(out, inverse=inverse)

    def _gram(self, k: int, eq: str, table: dict, target: np.ndarray, weight: np.ndarray):
        key = (k, eq)
        if key not in self._grams:
            f = np.stack([table[n] for n in self._fixed], axis=-1)
            wf_h = np.ascontiguousarray((f * weight[:, None]).conj().T)
            self._grams[key] = (f, wf_h, (wf_h @ f).real, (wf_h @ target).real)
        return self._grams[key]

    # --- the weights ------------------------------------------------------------------------------------------

    def initial_weights(self) -> None:
        """From the voltage's and the current's own noise: 1 / (var U + |Z|^2 var I) on the electrical lines,
        |Z| interpolated between the excited lines."""
        weights = []
        for d in self.data:
            u = np.fft.rfft(d.u, axis=-1)
            i = np.fft.rfft(d.i, axis=-1)
            lines = d.excited_bins
            z_lines = np.abs(u[:, lines].mean(axis=0)) / np.maximum(np.abs(i[:, lines].mean(axis=0)), 1e-300)
            z = np.interp(d.electrical_bins, lines, z_lines)
            eb = d.electrical_bins
            w_e = 2.0 / (noise_variance(u[:, eb]) + z**2 * noise_variance(i[:, eb]))
            weights.append((w_e, np.zeros(d.mechanical_bins.size)))
        self.set_weights(weights)

    def mechanical_start(self, orders: Orders, nu: Nuisance, theta_e: np.ndarray) -> np.ndarray:
        """The mechanical coefficients with Bl(x), Le(x) and L2(x) fixed at the electrical solution's."""
        names = orders.names()
        free = [k for k, (n, _) in enumerate(names) if n in MECHANICAL_ONLY]
        fixed = [k for k in range(len(names)) if k not in free]
        blocks = []
        for k, cols in enumerate(self.mean_cols):
            _, phi_m = stacked(cols, names, nu)
            d = self.data[k]
            force_noise = noise_variance(np.fft.rfft(d.i, axis=-1)[:, d.mechanical_bins])
            w_m = 2.0 / (force_noise * max(abs(theta_e[names.index(("Bl", 0))]), 1e-6) ** 2)
            blocks.append(Block(phi_m[:, free], -phi_m[:, fixed] @ theta_e[fixed], w_m, MECHANICAL, k))
        theta = theta_e.copy()
        theta[free] = solve(blocks).theta
        return theta

    def update_weights(self, orders: Orders, nu: Nuisance, theta: np.ndarray, misfit: bool = True) -> None:
        """Each line's weight: 2 / (its noise + the misfit the model leaves around it), see misfit_variance;
        2 / its noise alone without ``misfit``."""
        names = orders.names()
        weights, misfits, periods = [], [], []
        for k, d in enumerate(self.data):
            per_period = self.columns(k, True)
            periods.append(per_period)
            phi_e, phi_m = stacked(per_period, names, nu)
            noise_e = noise_variance(per_period.target_e - phi_e @ theta)
            noise_m = noise_variance(-(phi_m @ theta))
            mean_e, mean_m = stacked(self.mean_cols[k], names, nu)
            misfit_e = misfit_variance(self.mean_cols[k].target_e - mean_e @ theta, noise_e, d.electrical_bins)
            misfit_m = misfit_variance(-(mean_m @ theta), noise_m, d.mechanical_bins)
            if not misfit:
                misfit_e, misfit_m = np.zeros_like(noise_e), np.zeros_like(noise_m)
            # Each real and imaginary part carries half of a line's complex variance.
            weights.append((2.0 / (noise_e + misfit_e), 2.0 / (noise_m + misfit_m)))
            misfits.append((misfit_e, misfit_m))
        self.set_weights(weights)
        self.misfits = misfits
        self.corrections = [self._noise_correction(k, nu, per_period) for k, per_period in enumerate(periods)]

    def _noise_correction(self, k: int, nu: Nuisance, cols: Columns) -> dict:
        """The part of the normal equations that the regressors' own noise makes (bias compensation).

        The regressors are made of measured x and i, so their noise enters
        Phi^H W Phi squared: the estimate shrinks towards zero (regression
        dilution; here, x's noise rising into v as f). Each period's
        regressors scatter about the mean period's by that noise; the scatter
        divided by P (P - 1) is its covariance in the mean period, and is
        taken out of Phi^H W Phi and Phi^H W y (bias-compensated least
        squares). The covariance of the result is then the sandwich
        G_c^-1 G G_c^-1 (solve).
        """
        names = self.max_names
        p = cols.target_e.shape[0]
        out = {}
        for eq, weight, phi, target in zip((ELECTRICAL, MECHANICAL), self.weights[k], stacked(cols, names, nu),
                                           (cols.target_e, None)):
            dev = (phi - phi.mean(axis=0)).reshape(-1, len(names))        # every period's lines, one after another
            weighted_h = (dev * np.tile(weight, p)[:, None]).conj().T
            gram = (weighted_h @ dev).real / (p * (p - 1))
            rhs = np.zeros(len(names))
            if target is not None:
                rhs = (weighted_h @ (target - target.mean(axis=0)).ravel()).real / (p * (p - 1))
            out[eq] = (gram, rhs)
        return out

    def voltage_residual_percent(self, orders: Orders, nu: Nuisance, theta: np.ndarray) -> list[float]:
        """The electrical equation's rms misfit in % of the voltage's, per recording (over its lines)."""
        out = []
        for cols in self.mean_cols:
            phi_e, _ = stacked(cols, orders.names(), nu)
            r = cols.target_e - phi_e @ theta
            out.append(float(100.0 * np.sqrt(np.sum(np.abs(r) ** 2) / np.sum(np.abs(cols.target_e) ** 2))))
        return out

    def noise_misfit(self, orders: Orders, nu: Nuisance, theta: np.ndarray) -> list[dict[str, float]]:
        """Per recording, each equation's mean |residual|^2 over its lines in units of the lines' noise alone
        (the scatter between periods, without the misfit the weights count as noise): ~1 where the model
        explains the data, far above where it does not. A laser delay in a wrong valley leaves the back-EMF
        unexplained by a Bl(x) near 0, which the misfit-weighted chi^2 hides by counting the misfit as noise
        (chi^2_red 0.5 at a link latency of 2 ms, 1e9 against the noise alone)."""
        names = orders.names()
        out = []
        for k in range(len(self.data)):
            periods = self.columns(k, True)
            per_e, per_m = stacked(periods, names, nu)
            mean_e, mean_m = stacked(self.mean_cols[k], names, nu)
            ratios = {}
            for eq, residual, noise in (
                    (ELECTRICAL, self.mean_cols[k].target_e - mean_e @ theta,
                     noise_variance(periods.target_e - per_e @ theta)),
                    (MECHANICAL, -(mean_m @ theta), noise_variance(-(per_m @ theta)))):
                ratios[eq] = float(np.mean((residual.real**2 + residual.imag**2) / noise))
            out.append(ratios)
        return out

    # --- the searches -----------------------------------------------------------------------------------------

    def nuisance(self, orders: Orders, nu: Nuisance) -> Nuisance:
        """tau2 and lambda by variable projection (lambda only with creep in the model): bounded Brent
        searches, one parameter at a time (they hardly interact: tau2 lives above 1 kHz, creep below fs)."""
        def along(field: str, bounds: tuple[float, float], xatol: float, log: bool) -> None:
            nonlocal nu

            def chi2(value):
                return self.solve(orders, dataclasses.replace(nu, **{field: 10.0**value if log else value})).chi2
            best = scipy.optimize.minimize_scalar(chi2, bounds=bounds, method="bounded", options={"xatol": xatol})
            nu = dataclasses.replace(nu, **{field: 10.0**best.x if log else float(best.x)})

        rounds = 2 if orders.creep else 1
        for _ in range(rounds):
            along("tau2", tuple(np.log10(TAU2_RANGE_S)), TAU2_TOLERANCE_LOG10, True)
            if orders.creep:
                along("lam", (0.0, _lambda_limit(self.data, nu.ws)), LAMBDA_TOLERANCE, False)
        return nu if orders.creep else dataclasses.replace(nu, lam=0.0)

    @property
    def has_laser_delays(self) -> bool:
        return any(d.laser_delay_possible for d in self.data)

    def scan_delays(self, orders: Orders, nu: Nuisance) -> None:
        """Each serial laser's delay to the least chi^2 on a grid over +-DELAY_LIMIT_S around its centre
        (DELAY_GRID_S apart): chi^2 against the delay is not unimodal over that range (the lines of x turn
        through whole cycles), so the grid finds the valley that refine_delays then searches."""
        grid = np.arange(-DELAY_LIMIT_S, DELAY_LIMIT_S + DELAY_GRID_S / 2, DELAY_GRID_S)
        for k in self._delayed():
            chi2 = self._chi2_at_delay(k, orders, nu)
            self.delays[k] = self.centres[k] + float(grid[int(np.argmin([chi2(self.centres[k] + t)
                                                                          for t in grid]))])
            self.rebuild(k)

    def refine_delays(self, orders: Orders, nu: Nuisance) -> float:
        """Each serial laser's delay to the least chi^2 of the valley it is in (_valley_minimum); the largest
        change, s."""
        moved = 0.0
        for k in self._delayed():
            before = self.delays[k]
            self.delays[k] = _valley_minimum(self._chi2_at_delay(k, orders, nu), before, self.centres[k])
            self.rebuild(k)
            moved = max(moved, abs(self.delays[k] - before))
        return moved

    def _delayed(self) -> list[int]:
        return [k for k, d in enumerate(self.data) if d.laser_delay_possible]

    def _chi2_at_delay(self, k: int, orders: Orders, nu: Nuisance):
        def chi2(delay: float) -> float:
            self.delays[k] = float(delay)
            self.rebuild(k)
            return self.solve(orders, nu).chi2
        return chi2

    def fit_offsets(self, orders: Orders, nu: Nuisance, theta: np.ndarray) -> None:
        """Each recording's rest position from its static force balance (module doc); its 1-sigma from the
        scatter of that balance between periods."""
        names = orders.names()
        for k, d in enumerate(self.data):
            cols = self.mean_cols[k]
            i_mean = d.mean("i")

            def mean_force(shift, x=cols.x_time, i=i_mean):
                return np.mean(static_force(x + shift, i, names, theta, self.x_scale, nu, d.sample_rate), axis=-1)
            shift = 0.0
            for _ in range(8):
                f0 = mean_force(shift)
                slope = (mean_force(shift + 1e-6 * self.x_scale) - f0) / (1e-6 * self.x_scale)
                if slope == 0:
                    break
                step = -f0 / slope
                shift += float(np.clip(step, -0.2 * self.x_scale, 0.2 * self.x_scale))
                if abs(step) < 1e-6 * self.x_scale:
                    break
            per_period = self.columns(k, True)
            forces = mean_force(shift, per_period.x_time, d.i)
            var = np.var(forces, ddof=1) / forces.size if forces.size > 1 else np.inf
            self.offsets[k] += shift
            self.offsets_std[k] = float(np.sqrt(var) / abs(slope)) if slope else float("inf")
            self.rebuild(k)


def static_force(x: np.ndarray, i: np.ndarray, names, theta: np.ndarray, x_scale: float, nu: Nuisance,
                 sample_rate: float) -> np.ndarray:
    """Bl(x) i + 1/2 Le'(x) i^2 + 1/2 L2'(x) i2^2 - r v^3 - Kms(x) x, sample by sample (its mean is the balance)."""
    n = x.shape[-1]
    xn = x / x_scale
    s = 2j * np.pi * np.arange(n // 2 + 1) * sample_rate / n
    f = np.zeros_like(x)
    i2 = v = None
    for value, (name, j) in zip(theta, names):
        if name == "Bl":
            f += value * xn**j * i
        elif name == "Kms":
            f -= value * xn**j * x
        elif name == "Le" and j:
            f += value * j / (2.0 * x_scale) * xn ** (j - 1) * i * i
        elif name == "L2":
            if i2 is None:
                i2 = np.fft.irfft(np.fft.rfft(i, axis=-1) / (1.0 + s * nu.tau2), n, axis=-1)
            f += value * j / (2.0 * x_scale) * xn ** (j - 1) * i2 * i2
        elif name == "Rv":
            if v is None:
                v = np.fft.irfft(np.fft.rfft(x, axis=-1) * s, n, axis=-1)
            f -= value * v**3
    return f


def _valley_minimum(chi2, start: float, centre: float = 0.0) -> float:
    """The least chi^2 of the valley ``start`` lies in: downhill a scan step at a time until a step either side
    is higher (a true bracket, so the bounded Brent search inside it cannot stop on an edge: held to one step
    around the scan's best, it did, and the coefficients took up the phase error left), then Brent to
    DELAY_TOLERANCE_S. Within +-DELAY_LIMIT_S of ``centre``: a minimum on that limit is reported as such
    (delay_at_limit)."""
    lo_limit, hi_limit = centre - DELAY_LIMIT_S, centre + DELAY_LIMIT_S

    def at(t: float) -> float:
        return chi2(float(np.clip(t, lo_limit, hi_limit)))
    centre, here = start, at(start)
    for _ in range(int(2 * DELAY_LIMIT_S / DELAY_SCAN_S) + 1):
        low, high = max(centre - DELAY_SCAN_S, lo_limit), min(centre + DELAY_SCAN_S, hi_limit)
        below, above = at(low), at(high)
        if below < here and below <= above and low < centre:
            centre, here = low, below
        elif above < here and high > centre:
            centre, here = high, above
        else:
            break
    best = scipy.optimize.minimize_scalar(chi2, bounds=(low, high), method="bounded",
                                          options={"xatol": DELAY_TOLERANCE_S})
    return float(best.x) if best.fun <= here else centre


def delay_at_limit(delay_s: float, centre: float = 0.0) -> bool:
    """Whether a searched delay sits on the search's limit around its centre (the true one may lie beyond it)."""
    return abs(delay_s - centre) > DELAY_LIMIT_S - 2 * DELAY_TOLERANCE_S


def _lambda_limit(data: Sequence[RecordingData], ws: float) -> float:
    """The largest lambda for which c(s) = 1 - lambda log10(w / ws) stays above 0.2 on every mechanical line."""
    top = max(d.mechanical_bins[-1] * d.bin_width for d in data)
    decades = np.log10(2 * np.pi * top / ws)
    return float(min(LAMBDA_MAX, 0.8 / decades)) if decades > 0 else LAMBDA_MAX
