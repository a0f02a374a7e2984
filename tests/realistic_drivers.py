"""Recordings like a real driver's: several physics at once, none in the catalogue's exact form, known truth.

Every test before these used recordings the model describes exactly, up to one missing effect. A real
driver has all of these at once, and none in a textbook's exact form:

- a semi-inductance beside a small series inductance: the eddy currents of the pole piece as a ladder of
  four R-L branches with corners spread over two decades (no lr2, lr3, leach or wright);
- a causal creep law: the suspension's compliance relaxes through six Kelvin-Voigt-like stages with time
  constants from 0.3 ms to 3 s (a spectrum of relaxation times; the catalogue's creep laws have one or
  a closed-form log);
- damping that rises with frequency, as ln(1 + f/fs) (not damping-power's power law);
- the piston's air load on both sides of the cone (two baffled pistons);
- a cone mode: the outer part of the cone (mass m2) rides on the inner part through a spring and a damper,
  resonating near 1-2 kHz, and the laser's spot sees part of its motion;
- eddy currents that take part of Bl above a corner: a loss growing as s well below it (the eddy
  currents' field is proportional to its rate of change there), through a sqrt(s) stretch (the skin
  depth) to its full size well above (not bl-eddy's first order).

The truth is what a user means by the lumped values: RE the coil's DC resistance, Bl at low frequency,
Mms the whole moving mass at fs (the cone's, the outer ring's that moves with it below the mode, and the
air's on both sides), Kms the real part of the suspension's stiffness at fs.

The noise is a real rig's: 0.1 mV and 0.1 mA rms on the voltage and current (a 16-bit card at a few volts
full scale, through a 0.1 ohm sense), 50 nm rms on a triangulation laser.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from analysis.effects.mechanical import air_mass, piston_radiation_impedance
from analysis.synthesis import ChannelNoise, synthesize_recording
from tests.builders import multitone

__all__ = ["REALISTIC", "REAL_RIG_NOISE", "RealisticDriver", "realistic_recording"]

REAL_RIG_NOISE = ChannelNoise(voltage=1e-4, current=1e-4, displacement=5e-8)


@dataclass(frozen=True)
class RealisticDriver:
    """A driver whose Z and Hx follow the physics of the module doc (SI units throughout)."""

    name: str
    RE: float
    LE: float                     # the small series inductance, H
    ladder: tuple[tuple[float, float], ...]   # (L, R) of each eddy-current branch, H and ohm
    Bl: float                     # at low frequency
    Mmd: float                    # the cone's moving mass without the outer ring and the air, kg
    Kms: float                    # the suspension's stiffness at fs (real part), N/m
    Rms: float                    # the damping at fs, rising as ln(1 + f/fs)
    radius: float                 # the piston's, m
    creep: float                  # the compliance's relaxation per decade (about), a fraction
    ring_mass: float              # the outer part of the cone, kg
    mode_hz: float                # its resonance on the inner part
    mode_q: float
    spot: float                   # how much of the ring's motion the laser's spot sees (0: only the coil's)
    bl_loss: float                # the part of Bl the eddy currents take at high frequency
    bl_corner_hz: float
    with_displacement: bool = field(default=True)

    @property
    def Mms(self) -> float:
        return self.Mmd + self.ring_mass + 2.0 * air_mass(self.radius)

    @property
    def fs(self) -> float:
        return float(np.sqrt(self.Kms / self.Mms) / (2.0 * np.pi))

    @property
    def sd_m2(self) -> float:
        return float(np.pi * self.radius**2)

    @property
    def truth(self) -> dict[str, float]:
        return {"RE": self.RE, "Bl": self.Bl, "Mms": self.Mms, "Kms": self.Kms, "fs": self.fs}

    def _compliance(self, s: np.ndarray) -> np.ndarray:
        """C(s): six relaxation stages, 0.3 ms to 3 s, scaled so that Re(1/C) = Kms at fs."""
        taus = np.logspace(np.log10(3e-4), np.log10(3.0), 6)
        # Each stage adds creep * ln(10) / (stages per decade) of compliance below its corner: about
        # `creep` per decade in all, as a log law would, but causal and of a finite spectrum.
        weight = self.creep * np.log(10.0) / (len(taus) / 4.0)
        shape = 1.0 + sum(weight / (1.0 + s * tau) for tau in taus)
        ws = 2j * np.pi * self.fs
        at_fs = 1.0 + sum(weight / (1.0 + ws * tau) for tau in taus)
        stiffness_at_fs = (1.0 / at_fs).real
        return shape * stiffness_at_fs / self.Kms

    def _ring(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The outer ring's mechanical impedance seen by the inner cone, and its velocity over the inner's."""
        k2 = self.ring_mass * (2.0 * np.pi * self.mode_hz) ** 2
        r2 = np.sqrt(k2 * self.ring_mass) / self.mode_q
        spring = k2 / s + r2
        return s * self.ring_mass * spring / (s * self.ring_mass + spring), spring / (s * self.ring_mass + spring)

    def _parts(self, s: np.ndarray):
        f = np.abs(s) / (2.0 * np.pi)
        ze = self.RE + s * self.LE + sum(s * L * R / (s * L + R) for L, R in self.ladder)
        damping = self.Rms * (1.0 + 0.5 * np.log1p(f / self.fs)) / (1.0 + 0.5 * np.log(2.0))
        ring, ring_motion = self._ring(s)
        zm = (s * self.Mmd + damping + 1.0 / (s * self._compliance(s)) + ring
              + 2.0 * piston_radiation_impedance(np.abs(s), self.radius))
        u = s / (2j * np.pi * self.bl_corner_hz)
        bl = self.Bl * (1.0 - self.bl_loss * u / (1.0 + np.sqrt(u) + u))
        return ze, zm, bl, ring_motion

    def impedance(self, s: np.ndarray, values=None) -> np.ndarray:
        ze, zm, bl, _ = self._parts(s)
        return ze + bl**2 / zm

    def displacement(self, s: np.ndarray, values=None) -> np.ndarray:
        ze, zm, bl, ring_motion = self._parts(s)
        velocity_per_volt = bl / (zm * ze + bl**2)
        return velocity_per_volt / s * (1.0 - self.spot + self.spot * ring_motion)


def _ladder(total_h: float) -> tuple[tuple[float, float], ...]:
    """Four branches, corners R/L over two decades (about 300 Hz to 30 kHz), the inductance shared falling."""
    corners = np.logspace(np.log10(300.0), np.log10(30e3), 4)
    shares = np.array([0.4, 0.3, 0.2, 0.1]) * total_h
    return tuple((float(L), float(L * 2.0 * np.pi * fc)) for L, fc in zip(shares, corners))


REALISTIC: dict[str, RealisticDriver] = {
    # An 8" woofer: fs ~ 37 Hz.
    "woofer": RealisticDriver("woofer", RE=5.6, LE=0.12e-3, ladder=_ladder(1.1e-3), Bl=9.2, Mmd=24e-3,
                              Kms=1.7e3, Rms=1.4, radius=0.085, creep=0.15, ring_mass=4e-3, mode_hz=1500.0,
                              mode_q=4.0, spot=0.3, bl_loss=0.06, bl_corner_hz=400.0),
    # A 4" midrange: fs ~ 95 Hz.
    "midrange": RealisticDriver("midrange", RE=3.3, LE=0.05e-3, ladder=_ladder(0.35e-3), Bl=4.6, Mmd=4.0e-3,
                                Kms=2.0e3, Rms=0.9, radius=0.04, creep=0.2, ring_mass=1.2e-3, mode_hz=1900.0,
                                mode_q=3.0, spot=0.4, bl_loss=0.04, bl_corner_hz=800.0),
    # A 12" subwoofer: fs ~ 18 Hz.
    "subwoofer": RealisticDriver("subwoofer", RE=3.5, LE=0.3e-3, ladder=_ladder(2.5e-3), Bl=15.5,
                                 Mmd=170e-3, Kms=2.6e3, Rms=3.0, radius=0.11, creep=0.12, ring_mass=18e-3,
                                 mode_hz=1100.0, mode_q=5.0, spot=0.3, bl_loss=0.08, bl_corner_hz=250.0),
}


def realistic_recording(name: str, seed: int = 0, noise: ChannelNoise = REAL_RIG_NOISE, mt=None):
    """A recording of REALISTIC[name] with the tests' standard multitone (8 periods after one to settle)."""
    driver = REALISTIC[name]
    mt = mt or multitone()
    return synthesize_recording(driver, {}, mt.waveform, mt.excited_bins, mt.sample_rate, 8, 1, noise,
                                seed=seed, driver={"name": f"realistic {name}", "sd_m2": driver.sd_m2})
