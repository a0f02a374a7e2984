"""Real-like drivers: several physics at once, none of them in the catalogue's exact form.

A real woofer's recording misses the default model in several places at
once. Each shape here is a physical law the catalogue approximates but
does not hold in this form, so a fit can only come close:

- a cone mode whose coupling has hysteretic (structural) damping, k2 (1 + j eta),
  not the catalogue's viscous r2; the laser spot on the outer cone sees it too;
- damping that rises with frequency as a saturating law, not a power law;
- the radiation load of a baffled piston (its mass and resistance, both
  frequency dependent), not the catalogue's fixed air mass;
- eddy currents in the pole as a diffusion (tanh sqrt) law, not an LR ladder;
- creep as a Cole-Cole relaxation of the compliance.

`real_like_recording` writes one with 65,536-sample periods, the recording a
diagnosis of a woofer measured in earnest sees.
"""
from __future__ import annotations

import numpy as np
from scipy.special import j1, struve

from analysis.effects.base import Site
from analysis.effects.mechanical import air_mass
from analysis.model import Model
from analysis.synthesis import synthesize_recording
from tests.builders import PAPER, TYPICAL_NOISE, multitone
from tests.odd_physics import OddEffect

__all__ = ["REAL_LIKE", "real_like_recording", "real_like_effects", "real_like_truth", "structural_cone_mode"]

RHO_C = 1.204 * 343.0            # air's characteristic impedance, kg/(m^2 s)
SD = 0.0133                      # m^2, the paper driver's cone area
RADIUS = np.sqrt(SD / np.pi)


def _effect(site: Site, name: str, what: str, shape) -> OddEffect:
    return OddEffect(id=f"real-{name}", category=f"real-{name}", title=what, site=site, params=(),
                     physics=what, signature="", typical="", reference="none: written for the tests", shape=shape)


def _cone_mode(f, p, f2=1800.0, eta=0.1, mu2=0.03):
    """Y added by an outer cone mass m2 = mu2 Mms on a coupling stiffness with loss factor eta."""
    s = 2j * np.pi * f
    m2 = mu2 * p["CMES"] * p["Bl"] ** 2
    k2 = m2 * (2 * np.pi * f2) ** 2 * (1 + 1j * eta)
    z2 = 1.0 / (s / k2 + 1.0 / (s * m2))
    return (z2 - s * m2) / p["Bl"] ** 2


def _spot(f, p, f2=1800.0, eta=0.2):
    """The spot on the outer cone: a base-excited oscillator with structural damping."""
    w2 = (2 * np.pi * f2) ** 2 * (1 + 1j * eta)
    return w2 / (w2 - (2 * np.pi * f) ** 2)


def _rising_damping(f, p, share=0.3, f_knee=250.0):
    """Rms grows by `share` of itself towards high frequencies, half of it at f_knee."""
    rms = p["Bl"] ** 2 / p["RES"]
    return share * rms * (f / f_knee) / (1 + f / f_knee) / p["Bl"] ** 2


def _radiation(f, p):
    """A baffled piston's load on both sides: rho c Sd (R1(2ka) + j X1(2ka)), Bessel and Struve functions."""
    x = 2 * (2 * np.pi * f / 343.0 * RADIUS)
    z = RHO_C * SD * ((1 - 2 * j1(x) / x) + 1j * 2 * struve(1, x) / x)
    return 2 * z / p["Bl"] ** 2


def _eddy(f, p, l2=0.2e-3, tau=2.0e-4):
    """The pole's eddy currents by diffusion: s L2 tanh(sqrt(s tau)) / sqrt(s tau)."""
    s = 2j * np.pi * f
    q = np.sqrt(s * tau)
    return s * l2 * np.tanh(q) / q


def _cole_cole(f, p, delta=0.05, tau=1.0 / (2 * np.pi * 3.0), alpha=0.35):
    """Cms relaxes as a Cole-Cole law; 1 at high frequencies, 1 + delta in the static limit."""
    return 1.0 + delta / (1.0 + (2j * np.pi * f * tau) ** (1.0 - alpha))


REAL_LIKE = {
    "cone-mode": _effect(Site.MECHANICAL, "cone", "a cone mode at 1.8 kHz, structural damping", _cone_mode),
    "cone-spot": _effect(Site.DISPLACEMENT, "spot", "the laser spot riding the cone mode", _spot),
    "rising-damping": _effect(Site.MECHANICAL, "damping", "damping rising 30 % with frequency", _rising_damping),
    "radiation": _effect(Site.MECHANICAL, "air", "a baffled piston's radiation load", _radiation),
    "eddy": _effect(Site.BLOCKED, "eddy", "eddy currents in the pole, a diffusion law", _eddy),
    "creep": _effect(Site.COMPLIANCE, "creep", "creep as a Cole-Cole relaxation", _cole_cole),
}


def structural_cone_mode(f2: float, eta: float, mu2: float, f_spot: float, eta_spot: float
                         ) -> tuple[OddEffect, OddEffect]:
    """A cone mode with structural damping (in Z and at the coil) and the laser spot's own mode above it."""
    def cone(f, p):
        return _cone_mode(f, p, f2=f2, eta=eta, mu2=mu2)

    def spot(f, p):
        return _spot(f, p, f2=f_spot, eta=eta_spot)
    return (_effect(Site.MECHANICAL, "cone", f"a cone mode at {f2:g} Hz, structural damping {eta:g}", cone),
            _effect(Site.DISPLACEMENT, "spot", f"the laser spot's own mode at {f_spot:g} Hz", spot))


def real_like_effects(names=tuple(REAL_LIKE)) -> tuple[OddEffect, ...]:
    return tuple(REAL_LIKE[name] for name in names)


def real_like_recording(names=tuple(REAL_LIKE), seed: int = 5, period_samples: int = 65536, n_periods: int = 8):
    """The paper driver with the named physics (all by default), periods of `period_samples`."""
    mt = multitone(period_samples=period_samples)
    model = Model(real_like_effects(names))
    return synthesize_recording(model, dict(PAPER.parameters), mt.waveform, mt.excited_bins, mt.sample_rate,
                                n_periods, 1, TYPICAL_NOISE, seed=seed,
                                driver={"name": "synthetic, real-like", "sd_m2": SD})


def real_like_truth(names=tuple(REAL_LIKE)) -> dict[str, float]:
    """What a user means by the lumped values of `real_like_recording(names)`: RE and Bl as synthesized, Mms the
    cone's with the air's on both sides (the radiation load at low frequencies), Kms the real part of the creeping
    suspension's stiffness at fs, and fs where that stiffness and Mms resonate."""
    p = PAPER.parameters
    mms = p["CMES"] * p["Bl"] ** 2 + (2.0 * air_mass(RADIUS) if "radiation" in names else 0.0)
    static = p["Bl"] ** 2 / p["LCES"]
    fs = float(np.sqrt(static / mms) / (2.0 * np.pi))
    for _ in range(20):         # Kms(fs) and fs depend on each other; the creep's slope makes this converge fast
        kms = static * (float(np.real(1.0 / _cole_cole(np.array([fs]), p))[0]) if "creep" in names else 1.0)
        fs = float(np.sqrt(kms / mms) / (2.0 * np.pi))
    return {"RE": p["RE"], "Bl": p["Bl"], "Mms": mms, "Kms": kms, "fs": fs}
