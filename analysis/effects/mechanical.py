"""The mechanical impedance beyond s*Mms + Rms + Kms/s: the cone's air load and damping that grows with frequency.

Both add to Zm; the model's admittance is Y = Zm / Bl^2, so a term in kg/s enters as term / Bl^2
(air-load, which needs Bl and so the laser), or relative to Rms = Bl^2 / RES (damping, which does not).
"""
from __future__ import annotations

import functools

import numpy as np

from analysis.effects.base import Effect, ParamSpec, Site
from analysis.model.lumped import C_SOUND, RHO, resonance_frequency

AIR_CATEGORY = "air-load"
DAMPING_CATEGORY = "damping"
# The piston radius the fit starts from: a 6-inch cone's. The fit converges to the radius of a 2-inch to an
# 18-inch cone from there (the radiation impedance changes smoothly and monotonically with a).
START_RADIUS = 0.06


def piston_radiation_impedance(w: np.ndarray, a: float) -> np.ndarray:
    """Zr = rho*c*pi*a^2 * [R1(2ka) + j*X1(2ka)] (kg/s), one side of a rigid piston in an infinite baffle.

    R1(x) = 1 - 2*J1(x)/x, X1(x) = 2*H1(x)/x (J1 Bessel, H1 Struve, both of order one); Beranek,
    'Acoustics', ch. 5; Kinsler et al., 'Fundamentals of Acoustics', sec. 7.5.
    """
    from scipy.special import j1     # here, not at the top: `qa stats` reads these effects' units, not their model
    x = np.maximum(2.0 * np.asarray(w, dtype=float) * a / C_SOUND, 1e-12)
    return RHO * C_SOUND * np.pi * a * a * ((1.0 - 2.0 * j1(x) / x) + 1j * (4.0 * x / (3.0 * np.pi) + _x1_excess(x)))


# The last radiation impedance worked out, by its radius and lines: a fit's Jacobian moves one parameter at a
# time, so the radius is the same in most evaluations (with 14 parameters varying, in 13 of 15), and the
# Bessel and Struve terms cost more than the rest of the model. One entry per process is enough: a fit
# evaluates its model on the same lines from start to end. A tuple is replaced whole, so threads are safe.
_last_radiation: tuple[float, bytes, np.ndarray] | None = None


def _radiation_impedance(w: np.ndarray, a: float) -> np.ndarray:
    """piston_radiation_impedance(w, a), from the last call when it had the same radius and lines (read-only)."""
    global _last_radiation
    key = w.dtype.str.encode() + w.tobytes()
    last = _last_radiation
    if last is not None and last[0] == a and last[1] == key:
        return last[2]
    zr = piston_radiation_impedance(w, a)
    zr.flags.writeable = False
    _last_radiation = (a, key, zr)
    return zr


# scipy's Struve function costs about 4 us a point, twenty times the rest of the model: X1 beyond its
# low-frequency slope, X1(x) - 4x/(3*pi), is tabulated once on a fine logarithmic grid (interpolated to
# better than 1e-6 of itself), with its series below the grid and the exact function above it.
_TABLE_X = (1e-2, 3e3, 20000)


@functools.cache
def _x1_excess_table() -> tuple[np.ndarray, np.ndarray]:
    from scipy.special import struve
    x = np.geomspace(*_TABLE_X)
    return np.log(x), 2.0 * struve(1, x) / x - 4.0 * x / (3.0 * np.pi)


def build_tables() -> None:
    """Build the Struve term's table now rather than at the first evaluation (the pool's fork server does)."""
    _x1_excess_table()


def _x1_excess(x: np.ndarray) -> np.ndarray:
    """X1(x) - 4x/(3*pi), X1(x) = 2*H1(x)/x: -4x^3/(45*pi) + 4x^5/(1575*pi) - ... at small x."""
    log_x, table = _x1_excess_table()
    out = np.interp(np.log(x), log_x, table)
    small = x < _TABLE_X[0]
    out[small] = 4.0 / np.pi * (-x[small] ** 3 / 45.0 + x[small] ** 5 / 1575.0)
    large = x > _TABLE_X[1]
    if large.any():
        from scipy.special import struve
        out[large] = 2.0 * struve(1, x[large]) / x[large] - 4.0 * x[large] / (3.0 * np.pi)
    return out


def air_mass(a: float) -> float:
    """The low-frequency air mass on one side of a baffled piston: 8*rho*a^3/3 (kg)."""
    return 8.0 * RHO * a**3 / 3.0


class AirLoad(Effect):
    """Zm += Zr(w) - s*8*rho*a^3/3, Zr = rho*c*pi*a^2*[R1(2ka) + j*X1(2ka)] (one side, infinite baffle).

    The air mass at low frequencies is part of Mms (Thiele-Small's and the paper's Table I moving mass),
    so only what changes with frequency is added: the radiation resistance, rising as
    rho*c*pi*a^2*(ka)^2/2 at low ka towards rho*c*pi*a^2, and the air mass falling from 8*rho*a^3/3 to
    nothing above ka of about 2. In the model's admittance: Y += (Zr - s*8*rho*a^3/3) / Bl^2.
    """

    @property
    def needs_bl(self) -> bool:
        return True

    def response(self, s, p):
        a = p["a_rad"]
        w = np.abs(s)
        return (_radiation_impedance(w, a) - s * air_mass(a)) / p["Bl"] ** 2

    def guess(self, ctx):
        return {"a_rad": START_RADIUS}


air_load = AirLoad(
    id="air-load",
    category=AIR_CATEGORY,
    title="Air load of the cone (a baffled piston's radiation impedance)",
    site=Site.MECHANICAL,
    params=(ParamSpec("a_rad", "m", "mm", 1e3, 0.003, 0.6, START_RADIUS, "effective radius of the radiating piston",
                      typical=(0.008, 0.3)),),
    physics=("The cone pushes air: at low frequencies a layer of air moves with it (a mass, counted in Mms), "
             "and as the wavelength shrinks to the cone's size that air mass falls away while sound is radiated "
             "(a resistance rising as f^2 towards rho*c*Sd). Both change Zm above a few hundred hertz."),
    signature=("Residual above about c/(2*pi*a) (a kHz for a 6-inch cone): |Hx| above the model by the mass the "
               "air no longer adds, with a phase lag from the radiation resistance; the motional part of Z "
               "shows the same damping."),
    typical="a = sqrt(Sd/pi): 1.5 to 20 cm (paper's driver: Sd 133 cm^2, a 6.5 cm); air mass 8*rho*a^3/3, 0.1 to 25 g",
    reference=("L. L. Beranek, 'Acoustics' (McGraw-Hill, 1954; ASA 1986), ch. 5, the piston in an infinite "
               "baffle; L. E. Kinsler, A. R. Frey, A. B. Coppens, J. V. Sanders, 'Fundamentals of Acoustics', "
               "4th ed., Wiley, 2000, sec. 7.5"),
    notes=("Mms keeps its meaning: the total moving mass at low frequencies, air load included, as Thiele-Small "
           "and the paper's Table I use it; the effect adds only the part that changes with frequency. One side "
           "in an infinite baffle: a driver in free air radiates from both sides without a baffle, which the fit "
           "takes up in a (a is then an effective radius, compare it with sqrt(Sd/pi)). Needs the laser (Bl) to "
           "turn kg/s into the model's units."),
)


class PowerLawDamping(Effect):
    """Rms(w) = Rms * [1 + r_v*((w/ws)^n_v - 1)], ws = 2*pi*fs: Zm += Rms*r_v*((w/ws)^n_v - 1).

    Rms (= Bl^2 / RES) keeps its meaning as the resistance at fs; n_v = 1 is Thorborg's resistance
    proportional to frequency, n_v = 1/2 the viscous boundary layer (Stokes: the layer of air dragged
    along a wall thins as 1/sqrt(f)). In the model's admittance: Y += r_v*((w/ws)^n_v - 1) / RES.
    """

    def response(self, s, p):
        ws = 2.0 * np.pi * resonance_frequency(p)
        return p["r_v"] * ((np.abs(s) / ws) ** p["n_v"] - 1.0) / p["RES"]

    def guess(self, ctx):
        return {"r_v": 0.2, "n_v": 0.5}


damping_power = PowerLawDamping(
    id="damping-power",
    category=DAMPING_CATEGORY,
    title="Mechanical resistance rising with frequency (viscous losses, power law)",
    site=Site.MECHANICAL,
    params=(ParamSpec("r_v", "1", "-", 1.0, -0.95, 20.0, 0.2,
                      "rise of Rms, relative to its value at fs, where (w/ws)^n_v = 2", typical=(0.01, 3.0)),
            ParamSpec("n_v", "1", "-", 1.0, 0.05, 3.0, 0.5, "exponent of the frequency dependence",
                      typical=(0.2, 1.5))),
    physics=("Air forced through the spider's weave, past the surround and through the vents of the motor "
             "rubs on the walls it flows along; the viscous layer thins as frequency rises, so the damping grows "
             "(as sqrt(f) for a boundary layer, closer to f in a suspension's material)."),
    signature=("Residual around and above fs: the resonance is damped more on its upper side than on its lower "
               "(an asymmetric Re(Z) peak and a phase of Hx that falls too slowly above fs), which a constant Rms "
               "cannot follow."),
    typical="r_v 0.1 to 2 (Rms doubling within a decade above fs or slower), n_v 0.3 to 1",
    reference=("K. Thorborg, A. D. Unruh, C. J. Struck, 'An improved electrical equivalent circuit model for "
               "dynamic moving coil transducers', AES 122nd Convention, paper 7069, 2007 (Rms proportional to "
               "frequency); 'Frequency dependence of the loudspeaker suspension (a follow up)', AES e-Library 16970"),
    notes=("Needs no Bl: the change is relative to Rms. Below fs the resistance falls as well (to Rms*(1 - r_v) at "
           "DC), which is what a power law does; r_v near 0 leaves n_v undetermined, and the flags say so."),
)
