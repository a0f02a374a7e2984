"""The large-signal equations as linear regressions on the measured u, i and x (docs/physics.md section 6).

With x measured, both equations of the large-signal model are linear in the
coefficients of the polynomials (xn = x / x_scale, so that every power stays
of order one; coefficients.py turns them into ascending powers of x in m):

    electrical  U = RE I + sum_j B_j F[xn^j v] + sum_j L_j s F[xn^j i] + q1 s F[i^2] + q2 s F[i^3]
                    + R2 s tau2 / (1 + s tau2) I + sum_{j>=1} M_j H(s) s F[xn^j i2]
    mechanical  0 = sum_j B_j F[xn^j i] + sum_{j>=1} j / (2 x_scale) (L_j F[xn^(j-1) i^2] + M_j F[xn^(j-1) i2^2])
                    - Mms s^2 X - Rms s X - r F[v^3] - sum_j K_j F[xn^j x] - kappa (1 / c(s) - 1) X

F[.] is the DFT of one period (the equations hold sample by sample in the
time domain; they are compared line by line, where each line has its own
noise). The terms:

    Bl(x) = sum B_j xn^j          force factor, in the force and in the back-EMF alike
    Kms(x) = sum K_j xn^j         stiffness: the restoring force is Kms(x) x
    Le(x) = sum L_j xn^j          the coil's inductance; its flux Le(x) i, its reluctance force 1/2 Le'(x) i^2
    q1, q2                        Le(i): the flux gains q1 i^2 + q2 i^3 (iron saturating with the current)
    R2, tau2 = L2(0) / R2         the eddy-current branch ZP = s L2 R2 / (s L2 + R2) (LR-2)
    M_j                           L2(x) - L2(0); i2 = H(s) i is the branch's current, H = 1 / (1 + s tau2)
    Mms, Rms                      moving mass and mechanical resistance
    r                             a damping growing with speed, Rms(v) = Rms + r v^2 (a loss term)
    kappa, lambda                 log creep: the stiffness K0 / c(s), c(s) = 1 - lambda log10(w / ws),
                                  written as K(x) x plus kappa (1 / c - 1) X with kappa ~ Kms(0)

The eddy branch is exact, not linearised: with L2(x) i2 the branch's flux,
e2 = R2 (i - i2) = ZP(s) I + H(s) s F[(L2(x) - L2(0)) i2] for the true i2;
i2 is taken as H(s) i (its change by L2(x) is second order in the small L2
variation). tau2, lambda and ws enter nonlinearly: identify.py finds them by
variable projection (the least squares solved for the rest at each try).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from analysis.large_signal.data import RecordingData

ELECTRICAL, MECHANICAL = "electrical", "mechanical"


@dataclass(frozen=True, slots=True)
class Orders:
    """Which terms the model holds: polynomial orders and the optional terms."""

    bl: int = 6
    kms: int = 6
    le: int = 6
    l2: int = 0          # L2(x): powers 1 .. l2 (0: L2 constant)
    le_i: int = 0        # Le(i): 0, 1 (q1) or 2 (q1, q2) terms
    rms_v: bool = False
    creep: bool = False

    def names(self) -> list[tuple[str, int]]:
        """The coefficients, in the order of the regression's columns."""
        out = [("RE", 0), ("R2", 0), ("Mms", 0), ("Rms", 0)]
        out += [("Bl", j) for j in range(self.bl + 1)]
        out += [("Kms", j) for j in range(self.kms + 1)]
        out += [("Le", j) for j in range(self.le + 1)]
        out += [("L2", j) for j in range(1, self.l2 + 1)]
        out += [("LeI", j) for j in range(1, self.le_i + 1)]
        out += [("Rv", 2)] if self.rms_v else []
        out += [("creep", 0)] if self.creep else []
        return out


@dataclass(frozen=True, slots=True)
class Nuisance:
    """The parameters the equations are not linear in."""

    tau2: float = 1e-4         # s, L2 / R2
    lam: float = 0.0           # creep's lambda
    ws: float = 2 * np.pi * 50.0   # rad/s, creep's reference (the small-signal resonance)


@dataclass(eq=False)
class Columns:
    """The regressors of one recording at the largest orders; shape (..., bins) each, complex.

    ``lead`` is () for the coherent mean period, (P,) for every period.
    The nuisance-dependent columns are made by ``with_nuisance``.
    """

    data: RecordingData
    x_scale: float
    target_e: np.ndarray
    fixed_e: dict
    fixed_m: dict
    I_full: np.ndarray          # rfft of i, every bin (for the eddy branch's current)
    X_m: np.ndarray             # rfft of x at the mechanical bins
    x_time: np.ndarray          # x (offset and delay applied), time domain
    max_l2: int
    _cache: dict = field(default_factory=dict)

    @property
    def s_e(self) -> np.ndarray:
        return 2j * np.pi * self.data.electrical_bins * self.data.bin_width

    @property
    def s_m(self) -> np.ndarray:
        return 2j * np.pi * self.data.mechanical_bins * self.data.bin_width

    def with_nuisance(self, nu: Nuisance) -> tuple[dict, dict]:
        """(electrical, mechanical) columns by name at nuisance ``nu`` (the fixed ones included)."""
        key = (nu.tau2, nu.lam, nu.ws)
        if key in self._cache:
            return self._cache[key]
        d = self.data
        s_e, s_m = self.s_e, self.s_m
        n = d.period_samples
        e, m = dict(self.fixed_e), dict(self.fixed_m)
        h_full = 1.0 / (1.0 + 2j * np.pi * np.arange(n // 2 + 1) * d.bin_width * nu.tau2)
        e[("R2", 0)] = self.I_full[..., d.electrical_bins] * (1.0 - h_full[d.electrical_bins])
        m[("R2", 0)] = np.zeros_like(self.X_m)
        if self.max_l2:
            i2 = np.fft.irfft(self.I_full * h_full, n, axis=-1)
            xn = self.x_time / self.x_scale
            h_e = h_full[d.electrical_bins] * s_e
            power = np.ones_like(xn)
            for j in range(1, self.max_l2 + 1):
                # j / (2 x_scale) xn^(j-1) i2^2: the reluctance force of L2(x)'s j-th term
                m[("L2", j)] = j / (2.0 * self.x_scale) * _dft(power * i2 * i2, d.mechanical_bins)
                power = power * xn
                e[("L2", j)] = h_e * _dft(power * i2, d.electrical_bins)
        if nu.lam:
            c = 1.0 - nu.lam * np.log10(np.abs(s_m) / nu.ws)
            m[("creep", 0)] = -(1.0 / c - 1.0) * self.X_m
        else:
            m[("creep", 0)] = np.zeros_like(self.X_m)
        if len(self._cache) > 64:
            self._cache.clear()
        self._cache[key] = (e, m)
        return e, m


def build_columns(data: RecordingData, x_offset: float, delay_s: float, x_scale: float, max_orders: Orders,
                  periods: bool = False) -> Columns:
    """The nuisance-free regressors of one recording (every period with ``periods``, else the mean period).

    x_offset is added to the measured x (the rest position's shift); delay_s
    advances x (a laser that lags by delay_s is moved back onto the audio).
    """
    u, i, x = (data.u, data.i, data.x) if periods else (data.mean("u"), data.mean("i"), data.mean("x"))
    n = data.period_samples
    k_all = np.arange(n // 2 + 1)
    s_all = 2j * np.pi * k_all * data.bin_width
    X_full = np.fft.rfft(x, axis=-1)
    if delay_s:
        X_full = X_full * np.exp(s_all * delay_s)
    X_full[..., 0] += x_offset * n
    x = np.fft.irfft(X_full, n, axis=-1)
    v = np.fft.irfft(X_full * s_all, n, axis=-1)
    eb, mb = data.electrical_bins, data.mechanical_bins
    s_e, s_m = s_all[eb], s_all[mb]
    xn = x / x_scale
    I_full = np.fft.rfft(i, axis=-1)
    e: dict = {("RE", 0): I_full[..., eb]}
    m: dict = {("RE", 0): np.zeros(I_full[..., mb].shape, dtype=complex)}
    X_m = X_full[..., mb]
    e[("Mms", 0)] = np.zeros(I_full[..., eb].shape, dtype=complex)
    e[("Rms", 0)] = e[("Mms", 0)]
    m[("Mms", 0)] = -s_m * s_m * X_m
    m[("Rms", 0)] = -s_m * X_m
    zero_e, zero_m = e[("Mms", 0)], np.zeros_like(X_m)
    top = max(max_orders.bl, max_orders.kms, max_orders.le)
    powers = [np.ones_like(xn)]
    for _ in range(top):
        powers.append(powers[-1] * xn)
    for j in range(max_orders.bl + 1):
        e[("Bl", j)] = _dft(powers[j] * v, eb)
        m[("Bl", j)] = _dft(powers[j] * i, mb)
    for j in range(max_orders.kms + 1):
        e[("Kms", j)] = zero_e
        m[("Kms", j)] = -_dft(powers[j] * x, mb)
    i_sq = i * i
    for j in range(max_orders.le + 1):
        e[("Le", j)] = s_e * _dft(powers[j] * i, eb)
        m[("Le", j)] = zero_m if j == 0 else j / (2.0 * x_scale) * _dft(powers[j - 1] * i_sq, mb)
    for j in range(1, max_orders.le_i + 1):
        e[("LeI", j)] = s_e * _dft(i_sq if j == 1 else i_sq * i, eb)
        m[("LeI", j)] = zero_m
    if max_orders.rms_v:
        e[("Rv", 2)] = zero_e
        m[("Rv", 2)] = -_dft(v * v * v, mb)
    e[("creep", 0)] = zero_e
    return Columns(data, x_scale, U_of(u, eb), e, m, I_full, X_m, x, max_orders.l2)


def U_of(u: np.ndarray, bins: np.ndarray) -> np.ndarray:
    return _dft(u, bins)


def _dft(y: np.ndarray, bins: np.ndarray) -> np.ndarray:
    return np.fft.rfft(y, axis=-1)[..., bins]


def stacked(columns: Columns, names: list[tuple[str, int]], nu: Nuisance) -> tuple[np.ndarray, np.ndarray]:
    """(electrical, mechanical) regressor matrices (..., bins, len(names)) at ``nu``."""
    e, m = columns.with_nuisance(nu)
    return np.stack([e[n] for n in names], axis=-1), np.stack([m[n] for n in names], axis=-1)
