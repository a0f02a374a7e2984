"""Where the physics is missing: the site localisation.

For each of the six sites of docs/physics.md section 8, the current model gets a
smooth, flexible complex correction there (analysis.diagnosis.site_correction) and is
refitted with it, its own parameters free. A site's correction is judged by
how much misfit it removes, paid for by its effective number of parameters:

    delta_bic = chi^2(with the correction) - chi^2(current) + edf * ln n

and the sites are ranked by the same criterion with each channel's misfit at
its own scale, the BIC of a model whose noise level per channel is unknown
(the profile likelihood, -2 ln L = m_c ln(chi^2_c / m_c) for the m_c values of
channel c):

    score = sum over Z, Hx of m_c * ln(chi^2_c(with) / chi^2_c(current)) + edf * ln n

At the noise floor (chi^2_c near m_c) this is delta_bic; far from it a
channel counts by the share of its misfit removed, not by its size. Z
carries far the larger chi^2 (its noise is smaller against its size), and a
factor on the measured current can reshape any Z: ranked by delta_bic, a
site that cured Z alone outranked one that cures both channels.

Where the current fit's residual is concentrated (a mode, a dip), the
correction gets dense knots there (analysis.diagnosis.site_correction), so
it can follow a resonance; edf counts them.

edf is the trace of the correction's hat matrix: a roughness penalty
(second differences of the spline coefficients) and a small ridge keep the
correction smooth and pull a coefficient the data do not see back to zero,
so a site that cannot act on part of the band (the compliance far above fs)
pays for less than its knots.

Each line's model depends on the correction only through h at that line, so
the Jacobian columns of all the spline coefficients come from one extra
model evaluation (h shifted by a constant): a site fit costs about as much
as one refit of the model.

What Z and Hx can tell apart, and what they cannot, is in docs/diagnosis.md.
"""
from __future__ import annotations

import dataclasses
import threading
from concurrent.futures import Executor
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from analysis.diagnosis.chance import within_chance
from analysis.diagnosis.site_algebra import effective_dof, h_std, linearised_start
from analysis.diagnosis.site_correction import SiteCorrection, coefficient_names, misfit_spans, site_correction
from analysis.effects.base import Site
from analysis.fit.least_squares import FitCancelled, FitData, FitResult, channel_sigmas
from analysis.model.composed import Model
from analysis.model.lumped import resonance_frequency

SITES = (Site.BLOCKED, Site.FORCE_FACTOR, Site.MECHANICAL, Site.COMPLIANCE, Site.CURRENT, Site.DISPLACEMENT)
ROUGHNESS_WEIGHT = 1.0       # on second differences of the coefficients, in noise units per unit of h
RIDGE_WEIGHT = 3.0           # on the coefficients themselves
MAX_EVALUATIONS = 150        # Jacobians: each costs one model evaluation per parameter of the model, plus one
CORRECTION_POINTS = 120      # where the correction is reported
DERIVATIVE_STEP = 1e-7       # the shift of h (and the relative step of the model's parameters)
COMPLIANCE_TOP_OVER_FS = 2.0
DETERMINED_RATIO = 3.0
# Two sites whose corrections leave chi^2 closer than this (in units of the misfit the best one leaves)
# explain the data equally well: the data cannot tell them apart.
TIE_CHI2 = 10.0
TOLERANCE = 1e-4             # relative change of chi^2 and of the parameters: a ranking needs no more
# The correction replaces what the model already has at its site: the base elements there and the
# effects there are held at the current fit (the correction can take on any change of theirs, and
# left free they would trade against it with no end, which stalls the fit). The compliance's creep
# law stays free: its correction is held constant above 2 fs, where the law goes on shaping it.
# The channel each sense site's factor acts on alone.
SENSED_CHANNEL = {Site.CURRENT: "impedance", Site.DISPLACEMENT: "displacement"}
SITE_ELEMENTS = {Site.BLOCKED: ("RE", "LE"), Site.FORCE_FACTOR: ("Bl",), Site.MECHANICAL: ("RES",),
                 Site.COMPLIANCE: ("LCES",), Site.CURRENT: (), Site.DISPLACEMENT: ("Bl",)}


@dataclass(frozen=True)
class SiteResult:
    site: Site
    chi2: float
    chi2_by_channel: dict[str, float]
    chi2_red: dict[str, float]
    delta_bic: float
    edf: float
    freqs: np.ndarray             # where the correction is given (log-spaced over the band)
    correction: np.ndarray        # complex: what it adds (electrical, mechanical) or the factor (the others)
    unit: str                     # "ohm", "kg/s" (or "Rms" without the laser's Bl), "1" for a factor
    acts_as: str                  # what the values are, in words ("added to the blocked impedance Ze", ...)
    success: bool
    # The standard error of the correction at each of `freqs` (of its real and of its imaginary part):
    # where it is large, the data do not see the correction and its shape there means nothing.
    correction_std: np.ndarray | None = None
    score: float | None = None    # the ranking's: delta_bic with each channel at its own misfit's scale

    @property
    def rank_key(self) -> float:
        return self.delta_bic if self.score is None else self.score

    @property
    def determined(self) -> np.ndarray:
        """Where the data determine the correction: its standard error below a third of its size there."""
        if self.correction_std is None:
            return np.ones(len(self.freqs), dtype=bool)
        size = np.abs(self.correction - (1.0 if self.unit == "1" else 0.0))
        return self.correction_std < np.maximum(size / DETERMINED_RATIO, 1e-300)

    @property
    def key(self) -> str:
        return self.site.key

    def as_json(self) -> dict:
        return {"site": self.key, "delta_bic": float(self.delta_bic), "score": float(self.rank_key),
                "edf": float(self.edf),
                "chi2_red": {k: float(v) for k, v in self.chi2_red.items()},
                "correction": {"f": self.freqs.tolist(), "magnitude": np.abs(self.correction).tolist(),
                               "phase_deg": np.degrees(np.angle(self.correction)).tolist(),
                               "unit": self.unit, "acts_as": self.acts_as,
                               "determined": self.determined.tolist()}}


def usable_sites(model: Model) -> tuple[Site, ...]:
    """Without the laser, the displacement site has nothing to act on."""
    return tuple(s for s in SITES if s is not Site.DISPLACEMENT or model.with_displacement)


def _band(data: FitData) -> tuple[float, float]:
    freqs = [data.impedance.freqs] + ([data.displacement.freqs] if data.displacement is not None else [])
    return float(min(f.min() for f in freqs)), float(max(f.max() for f in freqs))


class _SiteProblem:
    """The least-squares problem of one site: the model's parameters (relative to the current fit) and the
    correction's coefficients; residual in noise units, then the penalty rows."""

    def __init__(self, data: FitData, current: FitResult, correction: SiteCorrection):
        self.data = data
        self.correction = correction
        self.model = current.model.with_effects(current.model.effects + (correction,))
        self.use_x = self.model.with_displacement
        self.sigmas = channel_sigmas(data, self.use_x)
        self.channels = [data.impedance] + ([data.displacement] if self.use_x else [])
        self.s = [2j * np.pi * tf.freqs for tf in self.channels]
        self.designs = [correction.design(tf.freqs) for tf in self.channels]
        self.fixed = dict(current.values)
        held = set(SITE_ELEMENTS[correction.site])
        if correction.site is not Site.COMPLIANCE:     # its correction stops at 2 fs: the creep law goes on above
            held |= {name for e in current.model.effects if e.site is correction.site for name in e.param_names}
        self.names = [n for n in current.varying if n not in held]
        # Each parameter moves from its current value in steps of its own size: p = p0 + x * |p0|.
        self.origin = np.array([current.values[n] for n in self.names])
        self.scale = np.maximum(np.abs(self.origin), 1e-30)
        specs = {s.name: s for s in self.model.param_specs}
        self.lower = (np.array([specs[n].min for n in self.names]) - self.origin) / self.scale
        self.upper = (np.array([specs[n].max for n in self.names]) - self.origin) / self.scale
        self.pairs = coefficient_names(correction.n_basis)
        self.k = len(self.names)
        self.n_basis = len(self.pairs)
        d2 = np.diff(np.eye(self.n_basis), 2, axis=0)
        self.penalty = np.vstack([ROUGHNESS_WEIGHT * d2, RIDGE_WEIGHT * np.eye(self.n_basis)])
        self.n_data = sum((2 if tf.has_phase else 1) * len(tf.freqs) for tf in self.channels)

    def values(self, x: np.ndarray) -> dict[str, float]:
        p = dict(self.fixed)
        # Levenberg-Marquardt knows no bounds: the model sees the parameters clipped to theirs.
        p.update(zip(self.names, self.origin + np.clip(x[: self.k], self.lower, self.upper) * self.scale))
        a, b = x[self.k: self.k + self.n_basis], x[self.k + self.n_basis:]
        for (re, im), va, vb in zip(self.pairs, a, b):
            p[re], p[im] = va, vb
        return p

    def predictions(self, p: dict[str, float], model: Model | None = None) -> list[np.ndarray]:
        model = model or self.model
        if self.use_x and self.data.same_lines:
            return list(model.responses(self.s[0], p))
        out = [model.impedance(self.s[0], p)]
        if self.use_x:
            out.append(model.displacement(self.s[1], p))
        return out

    def _data_residual(self, predictions: list[np.ndarray]) -> np.ndarray:
        parts = []
        for tf, pred, name in zip(self.channels, predictions, ("impedance", "displacement")):
            sigma = self.sigmas[name]
            if tf.has_phase:
                r = (pred - tf.value) / sigma
                parts += [r.real, r.imag]
            else:
                parts.append((np.abs(pred) - tf.value.real) / sigma)
        r = np.concatenate(parts)
        return np.nan_to_num(r, nan=1e12, posinf=1e12, neginf=-1e12)

    def residual(self, x: np.ndarray) -> np.ndarray:
        coef = x[self.k:]
        # einsum, not BLAS (see site_algebra.gram): a product this small costs BLAS's threads far more than the work.
        pen = np.concatenate([np.einsum("ij,j->i", self.penalty, coef[: self.n_basis]),
                              np.einsum("ij,j->i", self.penalty, coef[self.n_basis:])])
        return np.concatenate([self._data_residual(self.predictions(self.values(x))), pen])

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        p = self.values(x)
        base = self.predictions(p)
        r0 = self._data_residual(base)
        J = np.zeros((len(r0) + 2 * len(self.penalty), len(x)))
        for i in range(self.k):               # the model's parameters: forward differences
            step = DERIVATIVE_STEP * max(abs(x[i]), 1.0)
            xi = x.copy()
            xi[i] += step
            J[: len(r0), i] = (self._data_residual(self.predictions(self.values(xi))) - r0) / step
        # The coefficients: d(prediction)/dh per line from one shifted evaluation, then through the splines.
        shifted = self.model.with_effects(self.model.effects[:-1] + (
            dataclasses.replace(self.correction, offset=DERIVATIVE_STEP),))
        rows, start = [], 0
        for tf, pred, moved, design, name in zip(self.channels, base, self.predictions(p, shifted), self.designs,
                                                 ("impedance", "displacement")):
            dh = ((moved - pred) / DERIVATIVE_STEP / self.sigmas[name])[:, None] * design
            if tf.has_phase:
                rows.append((np.hstack([dh.real, -dh.imag]), np.hstack([dh.imag, dh.real])))
            else:
                unit = np.conj(pred) / np.maximum(np.abs(pred), 1e-300)
                rows.append((np.hstack([(unit[:, None] * dh).real, (1j * unit[:, None] * dh).real]),))
        J[: len(r0), self.k:] = np.nan_to_num(np.vstack([part for parts in rows for part in parts]))
        n_pen = len(self.penalty)
        J[len(r0): len(r0) + n_pen, self.k: self.k + self.n_basis] = self.penalty
        J[len(r0) + n_pen:, self.k + self.n_basis:] = self.penalty
        return J


def fit_site(data: FitData, current: FitResult, site: Site) -> SiteResult:
    """The current model with a smooth correction at `site`, refitted with its own parameters free."""
    f_lo, f_hi = _band(data)
    values = current.values
    scale = values["RE"] if site is Site.BLOCKED else (1.0 / values["RES"] if site is Site.MECHANICAL else 1.0)
    if site is Site.COMPLIANCE:
        # Above a few fs the stiffness is spent (at 2 fs it is a quarter of the mass's reactance): a
        # compliance that changes there cannot show, so its correction is held constant above.
        f_hi = float(np.clip(COMPLIANCE_TOP_OVER_FS * resonance_frequency(values), 2.0 * f_lo, f_hi))
    dense = misfit_spans(current, f_lo, f_hi)
    problem = _SiteProblem(data, current, site_correction(site, f_lo, f_hi, scale, dense))
    x0 = linearised_start(problem)
    # MINPACK's Levenberg-Marquardt: its own QR, no threaded LAPACK call per step (on a busy machine
    # OpenBLAS threads made 'trf' 15x slower), and like the model's fits it starts from the current fit.
    result = least_squares(problem.residual, x0, jac=problem.jacobian, method="lm", x_scale="jac",
                           ftol=TOLERANCE, xtol=TOLERANCE, max_nfev=MAX_EVALUATIONS)
    p = problem.values(result.x)
    predictions = problem.predictions(p)
    chi2_by_channel = {}
    for tf, pred, name in zip(problem.channels, predictions, ("impedance", "displacement")):
        r = (pred - tf.value) / problem.sigmas[name] if tf.has_phase else \
            (np.abs(pred) - tf.value.real) / problem.sigmas[name]
        chi2_by_channel[name] = (float(np.sum(np.abs(r) ** 2)), (2 if tf.has_phase else 1) * len(tf.freqs))
    chi2 = sum(c for c, _ in chi2_by_channel.values())
    edf = effective_dof(result.jac, problem.k, problem.n_data)
    n = problem.n_data
    k = problem.k + edf
    chi2_red = {name: c / max(m - k * m / n, 1.0) for name, (c, m) in chi2_by_channel.items()}
    freqs = np.geomspace(*_band(data), CORRECTION_POINTS)
    shown, unit, acts_as, scale = problem.correction.shown(freqs, p)
    std = scale * h_std(result.jac, problem, freqs, max(1.0, chi2 / max(n - k, 1.0)))
    score = edf * np.log(n) + sum(m * share for name, share, m in _log_shares_left(site, current, chi2_by_channel))
    return SiteResult(site, chi2, {name: c for name, (c, _) in chi2_by_channel.items()}, chi2_red,
                      chi2 - current.chi2 + edf * np.log(n), edf, freqs, shown, unit, acts_as, bool(result.status > 0),
                      std, float(score))


def _log_shares_left(site: Site, current: FitResult, chi2_by_channel: dict[str, tuple[float, int]]
                     ) -> list[tuple[str, float, int]]:
    """(channel, ln of the share of its chi^2 the correction leaves, its number of values): the ranking's terms.

    A factor on one channel's sense (the current's for Z, the laser's for Hx) can reshape that channel into
    anything, so how much of it the factor removes says nothing of whether the sense is at fault. What does
    is the other channel: freed of the sensed channel's misfit, the model's parameters should explain it
    too. So a sense site's own channel counts for no more than the other channel's share, unless the other
    channel is then within chance of its noise (then the sense alone explains the recording).
    Without this, a laser factor that took Hx to its noise and left Z at a reduced chi^2 of 1.4e5 outranked
    the mechanical site on a damping bump with a DC block on the current sense (physics at the mechanical
    and current sites).
    """
    terms = [(name, float(np.log(max(c, 1e-300) / max(current.channels[name].chi2, 1e-300))), m)
             for name, (c, m) in chi2_by_channel.items()]
    own = SENSED_CHANNEL.get(site)
    other = [(share, name) for name, share, _ in terms if name != own]
    if own is None or len(terms) < 2 or within_chance(*chi2_by_channel[other[0][1]]):
        return terms
    return [(name, max(share, other[0][0]) if name == own else share, m) for name, share, m in terms]


def tied_sites(sites: tuple[SiteResult, ...]) -> list[SiteResult]:
    """The sites (after the best) whose correction explains the data as well as the best one's does.

    With the impedance alone every site but the displacement acts on Z only, and any of them can
    make Z anything: they are all tied, whatever their chi^2 (which differs by how smoothly each
    correction follows the misfit, not by what the data say).
    """
    if not sites:
        return []
    best = sites[0]
    if "displacement" not in best.chi2_red:
        return list(sites[1:])
    scale = max(1.0, max(best.chi2_red.values(), default=1.0))
    return [s for s in sites[1:] if s.chi2 - best.chi2 <= TIE_CHI2 * scale]


def first_among_tied(sites: tuple[SiteResult, ...], preferred: set[Site]) -> tuple[SiteResult, ...]:
    """The sites with, among those the data cannot tell from the best, one of `preferred` first.

    The diagnosis prefers the sites of the effects its path took: when the misfit left is one the data
    cannot place, the likeliest cause is that an effect found is of a form close to, but not exactly,
    the physics (a diffusion law of eddy currents left by bl-eddy's first-order fall).
    """
    if not sites or sites[0].site in preferred:
        return sites
    chosen = next((s for s in tied_sites(sites) if s.site in preferred), None)
    if chosen is None:
        return sites
    return (chosen,) + tuple(s for s in sites if s is not chosen)


def localise(data: FitData, current: FitResult, executor: Executor | None = None,
             sites: tuple[Site, ...] | None = None, known: dict[Site, SiteResult] | None = None,
             cancel: threading.Event | None = None) -> tuple[SiteResult, ...]:
    """The sites' corrections (every usable site by default), best (lowest score) first.

    `known`: results already computed for `current` (the diagnosis computes some on its way).
    """
    known = known or {}
    wanted = [s for s in (sites or usable_sites(current.model)) if s not in known]
    if executor is not None:
        futures = [executor.submit(fit_site, data, current, site) for site in wanted]
        fitted = [f.result() for f in futures]
    else:
        fitted = []
        for site in wanted:
            if cancel is not None and cancel.is_set():
                raise FitCancelled("site localisation cancelled")
            fitted.append(fit_site(data, current, site))
    return tuple(sorted(list(known.values()) + fitted, key=lambda r: r.rank_key))
