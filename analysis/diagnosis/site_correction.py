"""A smooth, flexible complex correction at one site of the model: what the site localisation fits.

The correction is a complex function of frequency,

    h(f) = sum_k (a_k + j*b_k) * B_k(ln f)

with cubic B-splines B_k on knots evenly spaced in ln f over the measured
band (KNOTS_PER_DECADE), and denser (DENSE_KNOTS_PER_DECADE) where the current
fit's residual is concentrated: there the correction can follow a resonance
and an antiresonance (a cone mode of Q 5-10 spans a tenth of a decade), which
six knots a decade smooth away. The extra knots are paid for: the ranking
counts the correction's effective number of parameters. It enters the model the way an effect at that site
does (docs/physics.md section 8), in a form that is smooth for the physics
expected there:

    electrical     Ze + RE0 * h          ohms added to the blocked impedance (RE0: RE of the fit it starts from)
    force-factor   Bl * (1 + h)          in the force and the back-EMF alike
    mechanical     Zm + Rms0 * h         kg/s added to the mechanical impedance (Y += h / RES0)
    compliance     Cms * (1 + h)
    current        the measured I * (1 + h)     so Z is divided by it
    displacement   the measured X * (1 + h)     so Hx is multiplied by it

It is an Effect like any other (its parameters are the a_k and b_k), so the
model composes it with the catalogue's effects at the same sites.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BSpline

from analysis.effects.base import Effect, ParamSpec, Site
from analysis.fit.least_squares import FitResult

KNOTS_PER_DECADE = 6.0
DENSE_KNOTS_PER_DECADE = 30.0
SPLINE_DEGREE = 3
CATEGORY = "site-correction"
COEFFICIENT_BOUND = 1e3
# Dense knots where the residual is concentrated: lines above this many
# times their channel's mean chi^2 share, spans widened by this factor either side, at most this much of the band.
CONCENTRATED = 3.0
MAX_HOT_SHARE = 0.4
SPAN_MARGIN = 1.15
MAX_DENSE_DECADES = 1.0


def spline_knots(f_lo: float, f_hi: float, per_decade: float = KNOTS_PER_DECADE,
                 dense: tuple[tuple[float, float], ...] = ()) -> np.ndarray:
    """Clamped cubic B-spline knots in ln f, evenly spaced from f_lo to f_hi, and DENSE_KNOTS_PER_DECADE
    inside each of the `dense` spans (f_a, f_b)."""
    lo, hi = np.log(f_lo), np.log(f_hi)
    intervals = max(2, int(np.ceil((hi - lo) / np.log(10.0) * per_decade)))
    inner = np.linspace(lo, hi, intervals + 1)
    extra = []
    for f_a, f_b in dense:
        a, b = max(np.log(f_a), lo), min(np.log(f_b), hi)
        if b > a:
            n = max(2, int(np.ceil((b - a) / np.log(10.0) * DENSE_KNOTS_PER_DECADE)))
            extra.append(np.linspace(a, b, n + 1))
    if extra:
        inner = np.concatenate([inner] + extra)
        inner.sort()
        # Knots closer than a third of the dense spacing add nothing but ill-conditioning.
        gap = np.log(10.0) / DENSE_KNOTS_PER_DECADE / 3.0
        keep = np.concatenate([[True], np.diff(inner) > gap])
        keep[-1] = True
        inner = inner[keep]
        if len(inner) > 2 and inner[-1] - inner[-2] <= gap:
            inner = np.delete(inner, -2)
    return np.concatenate([[lo] * SPLINE_DEGREE, inner, [hi] * SPLINE_DEGREE])


def spline_design(knots: np.ndarray, freqs: np.ndarray) -> np.ndarray:
    """(lines x basis functions) values of the B-splines at ln f, clipped to the knots' span."""
    x = np.clip(np.log(freqs), knots[0], knots[-1])
    return BSpline.design_matrix(x, knots, SPLINE_DEGREE).toarray()


def coefficient_names(n: int) -> tuple[tuple[str, str], ...]:
    return _NAMES[n]


class _Names(dict):
    def __missing__(self, n: int) -> tuple[tuple[str, str], ...]:
        names = self[n] = tuple((f"h{k}_re", f"h{k}_im") for k in range(n))
        return names


_NAMES = _Names()


@dataclass(frozen=True)
class SiteCorrection(Effect):
    """A smooth complex correction at one site; see the module docstring for how each site takes it."""

    knots: np.ndarray = field(default_factory=lambda: np.zeros(0), compare=False)
    scale: float = 1.0                   # RE0 (electrical) or 1/RES0 (mechanical); unused elsewhere
    offset: float = 0.0                  # added to h at every line: how analysis.diagnosis.sites differentiates
    _designs: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def n_basis(self) -> int:
        return len(self.knots) - SPLINE_DEGREE - 1

    def design(self, freqs: np.ndarray) -> np.ndarray:
        key = (len(freqs), float(freqs[0]), float(freqs[-1]))    # the fit evaluates the same lines again and again
        matrix = self._designs.get(key)
        if matrix is None:
            matrix = self._designs[key] = spline_design(self.knots, freqs)
        return matrix

    def h(self, freqs: np.ndarray, p) -> np.ndarray:
        coef = np.array([p[re] for re, _ in self.pairs]) + 1j * np.array([p[im] for _, im in self.pairs])
        # numpy's own loop, not BLAS: on a busy 2-core machine OpenBLAS's threads made this product of a few
        # thousand numbers cost 70 ms (the site fits spent most of their time here).
        return np.einsum("ij,j->i", self.design(freqs), coef) + self.offset

    @property
    def pairs(self) -> tuple[tuple[str, str], ...]:
        return _NAMES[self.n_basis]

    def response(self, s, p):
        h = self.h(np.abs(s) / (2.0 * np.pi), p)
        if self.site is Site.BLOCKED or self.site is Site.MECHANICAL:
            return self.scale * h
        if self.site is Site.CURRENT:
            return 1.0 / (1.0 + h)       # the model's current-site factor multiplies Z = U / I
        return 1.0 + h

    def shown(self, freqs: np.ndarray, p) -> tuple[np.ndarray, str, str, float]:
        """(values, unit, what they are, scale): the correction as the site takes it.

        The additive sites give what they add, in ohm (Ze) or kg/s (Zm; in units
        of Rms without the laser, which alone gives Bl); the others the factor.
        The values are 1 + h (a factor) or scale * h (what is added).
        """
        h = self.h(freqs, p)
        if self.site is Site.BLOCKED:
            return self.scale * h, "ohm", "added to the blocked impedance Ze", self.scale
        if self.site is Site.MECHANICAL:
            if "Bl" in p:       # Y = Zm / Bl^2, and the correction adds scale * h to Y
                kg_per_s = self.scale * p["Bl"] ** 2
                return kg_per_s * h, "kg/s", "added to the mechanical impedance Zm", kg_per_s
            return h, "Rms", "added to the mechanical impedance Zm, in units of Rms", 1.0
        return 1.0 + h, "1", FACTOR_WORDS[self.site], 1.0


FACTOR_WORDS = {Site.FORCE_FACTOR: "factor on Bl", Site.COMPLIANCE: "factor on the compliance",
                Site.CURRENT: "factor on the measured current", Site.DISPLACEMENT: "factor on the measured displacement"}


def site_correction(site: Site, f_lo: float, f_hi: float, scale: float = 1.0,
                    dense: tuple[tuple[float, float], ...] = ()) -> SiteCorrection:
    knots = spline_knots(f_lo, f_hi, dense=dense)
    n = len(knots) - SPLINE_DEGREE - 1
    params = tuple(ParamSpec(name, "1", "-", 1.0, -COEFFICIENT_BOUND, COEFFICIENT_BOUND, 0.0,
                             f"spline coefficient of the {site.key} correction")
                   for pair in coefficient_names(n) for name in pair)
    return SiteCorrection(
        id=f"correction-{site.key}", category=CATEGORY, title=f"Smooth correction at the {site.key} site",
        site=site, params=params, physics="", signature="", typical="", reference="",
        knots=knots, scale=scale)


def misfit_spans(current: FitResult, f_lo: float, f_hi: float) -> tuple[tuple[float, float], ...]:
    """Where the current fit's residual is concentrated: the spans (f_a, f_b) that get dense knots.

    A line counts when it carries more than CONCENTRATED times its channel's mean share of that channel's
    chi^2 and stands above the noise (|r| > 3 sigma); neighbouring lines form a span, widened by
    SPAN_MARGIN either side. A misfit spread over most of the band is no resonance: no spans then.
    """
    flagged = []
    for ch in current.channels.values():
        r2 = np.abs(ch.normalized_residual) ** 2
        if not np.any(r2 > 0):
            continue
        hot = (r2 > CONCENTRATED * np.mean(r2)) & (r2 > 9.0)
        if hot.mean() > MAX_HOT_SHARE:
            continue
        flagged += [float(f) for f in ch.freqs[hot]]
    if not flagged:
        return ()
    spans: list[list[float]] = []
    for f in sorted(flagged):
        if spans and f <= spans[-1][1] * SPAN_MARGIN ** 2:
            spans[-1][1] = f
        else:
            spans.append([f, f])
    widened = [(max(a / SPAN_MARGIN, f_lo), min(b * SPAN_MARGIN, f_hi)) for a, b in spans]
    # The widest spans first, up to MAX_DENSE_DECADES in all: dense knots everywhere would be a finer spline.
    kept, total = [], 0.0
    for a, b in sorted(widened, key=lambda ab: -np.log10(ab[1] / ab[0])):
        width = np.log10(b / a)
        if total + width <= MAX_DENSE_DECADES:
            kept.append((a, b))
            total += width
    return tuple(sorted(kept))
