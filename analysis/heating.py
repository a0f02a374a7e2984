"""Voice-coil heating during the measurement: RE period by period, the temperature rise, and its effects.

The drive warms the coil; its resistance follows the copper's temperature,

    RE(T) = RE(T0) * (1 + alpha * (T - T0)),     alpha = 0.393 %/K for copper (0.403 %/K for aluminium)

so RE drifts from period to period. The averaged spectra see the mean RE (to first order: the fit's RE
is the coil's resistance at its mean temperature over the measurement); what the drift does is inflate
the noise estimate, which comes from the scatter between periods. The validity check sees it as the
current channel's drift finding, and the diagnosis as a reduced chi^2 far below 1 (noise-inflated).

Each period's RE comes straight from its own impedance: dZ/dRE = 1 at every line (Z = RE + the rest),
so with Z_k = U_k / I_k the period's shift is the noise-weighted mean of Re(Z_k - Z) over the lines,

    dRE_k = sum_l w_l Re(Z_k,l - Z_l) / sum_l w_l,     w_l = 1 / var(Z_l),

and a straight line through dRE_k gives RE at the first and the last period, and the rise
dT = (RE_last / RE_first - 1) / alpha. Taking each period's shift out leaves the scatter that is noise:
U_k - dRE_k*I_k in place of U_k (so that U/I is Z at the mean RE), and X_k*(1 + dRE_k/Z) in place of
X_k (Hx = ZR / (Z*Bl*s) is inversely proportional to Z, and RE changes nothing else in it). The spectra
then carry an honest noise estimate, and the fit's uncertainties and chi^2 mean what they say again.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from analysis.recording.format import Recording
from analysis.spectra import Spectra, displacement_noise_factor, period_spectra, transfer_from_periods

COPPER_PER_K = 0.00393
# The rise must stand this many standard errors above zero (and above MIN_RISE_K) to be reported and
# taken out of the noise.
SIGNIFICANCE = 5.0
MIN_RISE_K = 0.2


@dataclass(frozen=True)
class CoilHeating:
    re_periods: np.ndarray     # ohm: RE of each analysed period (the fit's RE plus the period's shift)
    re_first: float            # ohm, from the straight line through them
    re_last: float
    rise_k: float              # the coil's temperature rise over the measurement (copper), K
    rise_std_k: float
    re_fit: float              # the fit's RE: the coil at its mean temperature

    @property
    def significant(self) -> bool:
        return self.rise_k > MIN_RISE_K and abs(self.rise_k) > SIGNIFICANCE * self.rise_std_k

    @property
    def relative_change(self) -> float:
        return self.re_last / self.re_first - 1.0

    def words(self) -> str:
        return (f"the voice coil warmed by {self.rise_k:.1f} K during the measurement (RE {self.re_first:.4g} -> "
                f"{self.re_last:.4g} ohm, {100 * self.relative_change:+.2f} %, copper 0.393 %/K): RE, Qes and Qts "
                f"are those of the coil at its mean temperature, Qes and Qts {100 * self.relative_change:+.2f} % "
                "higher at the end than at the start; the drift was taken out of the noise estimate")

    def as_json(self) -> dict:
        return {"rise_k": self.rise_k, "rise_std_k": self.rise_std_k, "re_first_ohm": self.re_first,
                "re_last_ohm": self.re_last, "re_fit_ohm": self.re_fit, "re_periods_ohm": self.re_periods.tolist(),
                "significant": self.significant, "temperature_coefficient_per_k": COPPER_PER_K,
                "text": self.words() if self.significant else ""}


def _per_period(recording: Recording, spectra: Spectra) -> dict[str, np.ndarray]:
    excited = spectra.excited_bins
    out = {name: period_spectra(recording.periods(name))[:, excited]
           for name in ("voltage", "current", "displacement") if name in spectra.channels}
    return out


def _shifts(u: np.ndarray, i: np.ndarray, z: np.ndarray, std: np.ndarray) -> np.ndarray:
    """dRE_k: the noise-weighted mean of Re(Z_k - Z) over the lines, per period (P)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        zk = u / i
        w = 1.0 / std**2
    ok = np.all(np.isfinite(zk), axis=0) & np.isfinite(w) & (w > 0)
    if not ok.any():
        return np.zeros(u.shape[0])
    w = w[ok] / w[ok].sum()
    return (zk[:, ok] - z[ok]).real @ w


def coil_heating(recording: Recording, spectra: Spectra, re_fit: float) -> CoilHeating | None:
    """RE period by period and the temperature rise; None with fewer than 3 periods (no line to draw)."""
    periods = _per_period(recording, spectra)
    p = periods["voltage"].shape[0]
    if p < 3:
        return None
    z = spectra.impedance
    # One period's variance of Z is P times that of the mean.
    shifts = _shifts(periods["voltage"], periods["current"], z.value, z.std * np.sqrt(p))
    # Measured from the averaged Z, the shifts have a mean of second order (the average of U/Z_k is not U over
    # the average Z_k); the fit's RE is the mean one, so the shifts are taken about their own mean.
    shifts = shifts - np.mean(shifts)
    k = np.arange(p) - (p - 1) / 2.0
    slope = float(np.dot(k, shifts) / np.dot(k, k))
    scatter = shifts - slope * k
    slope_std = float(np.sqrt(np.sum(scatter**2) / max(p - 2, 1) / np.dot(k, k)))
    first = re_fit - slope * (p - 1) / 2.0
    last = re_fit + slope * (p - 1) / 2.0
    span = slope * (p - 1)
    return CoilHeating(re_fit + shifts, first, last, span / first / COPPER_PER_K,
                       slope_std * (p - 1) / first / COPPER_PER_K, re_fit)


def without_heating(recording: Recording, spectra: Spectra, heating: CoilHeating) -> Spectra:
    """The spectra with each period's RE shift taken out of its current and displacement: the noise is noise."""
    periods = _per_period(recording, spectra)
    shift = (heating.re_periods - heating.re_fit)[:, None]
    u, i = periods["voltage"], periods["current"]
    excited = spectra.excited_bins
    impedance = transfer_from_periods("impedance", "ohm", u - shift * i, i, excited, spectra.bin_width)
    displacement = spectra.displacement
    if displacement is not None and "displacement" in periods:
        in_band = np.isin(excited, displacement.bins)
        x = periods["displacement"] * (1.0 + shift / impedance.value[in_band])
        displacement = transfer_from_periods("displacement", "m/V", x, u[:, in_band], displacement.bins,
                                             spectra.bin_width, displacement_noise_factor(recording))
    return dataclasses.replace(spectra, impedance=impedance, displacement=displacement)
