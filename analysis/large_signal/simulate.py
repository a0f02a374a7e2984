"""The periodic steady state of the large-signal model (model.py) for a periodic voltage: harmonic balance.

The model is split into its small-signal part about the rest position and
what the nonlinearity adds (the same split as the nonlinear simulator's,
instruments/simulation/nonlinear_driver.py, but solved for the periodic
steady state in the frequency domain instead of stepped in time):

    Ze(s) I + Bl0 s X = U - Ne          Ze = RE + s Le0 + R2 s tau2 / (1 + s tau2)
    Zm(s) X - Bl0 I   = Nm              Zm = Mms s^2 + Rms s + K(s)   (K with creep; K0 at DC)

    Ne = F[(Bl(x) - Bl0) v] + s F[(Le(x) - Le0) i + q1 i^2 + q2 i^3] + H(s) s F[(L2(x) - L2(0)) i2]
    Nm = F[(Bl(x) - Bl0) i + 1/2 Le'(x) i^2 + 1/2 L2'(x) i2^2 - r v^3 - (Kms(x) - K0) x]
    i2 = H(s) (i - s/R2 F[(L2(x) - L2(0)) i2]),  H = 1 / (1 + s tau2)

Ne and Nm are evaluated in the time domain from the current iterate, the
two linear equations solved line by line, and the iteration accelerated by
Anderson mixing (Walker & Ni 2011): a few tens of iterations at the
distortion levels the curves are measured at. The DC line is solved too:
the cone's mean shift under drive (creep absent at DC, as identify.py's
static balance assumes).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.errors import LinparError
from analysis.large_signal.model import LargeSignalModel

MAX_ITERATIONS = 200
TOLERANCE = 1e-10
_ANDERSON_DEPTH = 6


class SimulationDiverged(LinparError, ArithmeticError):
    """The iteration did not settle: the level is beyond what the curves can describe."""


@dataclass(frozen=True, slots=True, eq=False)
class SteadyState:
    sample_rate: float
    voltage: np.ndarray        # one period, V
    current: np.ndarray        # A
    displacement: np.ndarray   # m, from the rest position (its mean is the shift under drive)
    iterations: int


def steady_state(model: LargeSignalModel, voltage: np.ndarray, sample_rate: float) -> SteadyState:
    """One period of i and x for one period of u (SimulationDiverged if it does not settle)."""
    u = np.asarray(voltage, dtype=np.float64)
    n = u.size
    s = 2j * np.pi * np.arange(n // 2 + 1) * sample_rate / n
    bl0, le0 = model.Bl.coefficients[0], model.Le.coefficients[0]
    re, r2, tau2 = model.value("RE"), model.value("R2"), model.tau2
    h = 1.0 / (1.0 + s * tau2)
    ze = re + s * le0 + r2 * s * tau2 * h
    zm = model.value("Mms") * s * s + model.value("Rms") * s + model.stiffness(s)
    det = ze * zm + bl0 * bl0 * s
    U = np.fft.rfft(u)
    dbl = _minus_constant(model.Bl.coefficients)
    dkms = _minus_constant(model.Kms.coefficients)
    dle = _minus_constant(model.Le.coefficients)
    le_slope = np.polynomial.polynomial.polyder(model.Le.coefficients)
    dl2 = model.l2_delta()
    l2_slope = np.polynomial.polynomial.polyder(dl2)
    has_l2 = np.any(dl2 != 0) and r2 > 0
    q1, q2 = model.le_i
    r = model.rms_v
    pv = np.polynomial.polynomial.polyval

    def solve(ne: np.ndarray, nm: np.ndarray) -> np.ndarray:
        rhs = U - ne
        current = (rhs * zm - bl0 * s * nm) / det
        displacement = (ze * nm + bl0 * rhs) / det
        return np.concatenate([current, displacement])

    def step(z: np.ndarray) -> np.ndarray:
        I, X = z[:s.size], z[s.size:]
        i = np.fft.irfft(I, n)
        x = np.fft.irfft(X, n)
        v = np.fft.irfft(s * X, n)
        ne = np.fft.rfft(pv(x, dbl) * v) + s * np.fft.rfft(pv(x, dle) * i + q1 * i * i + q2 * i * i * i)
        force = pv(x, dbl) * i + 0.5 * pv(x, le_slope) * i * i - r * v**3 - pv(x, dkms) * x
        if has_l2:
            i2 = np.fft.irfft(h * I, n)
            for _ in range(2):      # i2 itself depends on L2(x) (second order: two passes suffice)
                i2 = np.fft.irfft(h * (I - s / r2 * np.fft.rfft(pv(x, dl2) * i2)), n)
            ne = ne + h * s * np.fft.rfft(pv(x, dl2) * i2)
            force = force + 0.5 * pv(x, l2_slope) * i2 * i2
        return solve(ne, np.fft.rfft(force))

    z = solve(np.zeros_like(U), np.zeros_like(U))
    scale = np.linalg.norm(z) or 1.0
    history_z, history_f = [], []
    for iteration in range(1, MAX_ITERATIONS + 1):
        g = step(z)
        f = g - z
        if not np.all(np.isfinite(f)):
            raise SimulationDiverged("the large-signal model does not settle at this level")
        if np.linalg.norm(f) <= TOLERANCE * scale:
            z = g
            break
        history_z.append(z)
        history_f.append(f)
        if len(history_f) > _ANDERSON_DEPTH + 1:
            history_z.pop(0)
            history_f.pop(0)
        z = _anderson(history_z, history_f)
    else:
        raise SimulationDiverged(f"the large-signal model did not settle in {MAX_ITERATIONS} iterations at this "
                                 f"level (beyond the measured range?)")
    I, X = z[:s.size], z[s.size:]
    return SteadyState(float(sample_rate), u, np.fft.irfft(I, n), np.fft.irfft(X, n), iteration)


def _anderson(zs: list[np.ndarray], fs: list[np.ndarray]) -> np.ndarray:
    """The next iterate from the last residuals f_k = g(z_k) - z_k (type-II Anderson mixing)."""
    z, f = zs[-1], fs[-1]
    if len(fs) == 1:
        return z + f
    df = np.stack([fs[k + 1] - fs[k] for k in range(len(fs) - 1)], axis=1)
    dz = np.stack([zs[k + 1] - zs[k] for k in range(len(zs) - 1)], axis=1)
    a = np.concatenate([df.real, df.imag])
    b = np.concatenate([f.real, f.imag])
    gamma = np.linalg.lstsq(a, b, rcond=None)[0]
    return z + f - (dz + df) @ gamma


def _minus_constant(coefficients: np.ndarray) -> np.ndarray:
    c = np.array(coefficients, dtype=np.float64)
    c[0] = 0.0
    return c
