"""A loudspeaker whose Bl, stiffness and inductance depend on the cone position, in the time domain.

Equations (physics.md section 1 with the parameters made functions of x;
state: coil current i, eddy-branch current i2, velocity v, displacement x):

    d/dt(Le(x) i) = u - RE i - R2 (i - i2) - Bl(x) v        (Le(x) i: the coil's flux)
    L2 di2/dt     = R2 (i - i2)                              (LR-2: ZP = s L2 R2 / (s L2 + R2))
    Mms dv/dt     = Bl(x) i - Rms v - Kms(x) x + 1/2 Le'(x) i^2   (the last term: reluctance force)
    dx/dt         = v

    Mms = CMES Bl0^2, Rms = Bl0^2 / RES, Kms(0) = Bl0^2 / LCES (the electrical analogues of `values`)
    Bl(x)  = Bl0  (1 + b1 x + b2 x^2 + ...)      bl_poly  = (b1, b2, ...)   [1/m, 1/m^2, ...]
    Kms(x) = Kms0 (1 + k1 x + k2 x^2 + ...)      kms_poly = (k1, k2, ...)
    Le(x)  = LE0  (1 + l1 x + l2 x^2 + ...)      le_poly  = (l1, l2, ...)

The polynomials are relative, so the small-signal parameters are `values`
whatever the shapes. They are evaluated at x clipped to +-x_range_m (the
range in which the construction checks that Bl, Kms and Le stay positive).

How it is integrated: exact linear part + integrated nonlinear part
------------------------------------------------------------------
The state is split, s = s_lin + s_nl. s_lin is the small-signal response to
u, from frequency-sampled FIRs (instruments.simulation.linear_driver: exact
for a periodic excitation whose period divides fir_length, no latency), with
the whole analysis.model: LR-2 if values hold L2 and R2, log creep if they
hold "lambda". s_nl obeys the linearised equations driven by what the linear
model leaves out,

    ds_nl/dt = A s_nl + E g(s_lin + s_nl, u)
    g_i = (e - Bl(x) v - Le'(x) v i) / Le(x) - (e - Bl0 v) / LE0,   e = u - RE i - R2 (i - i2)
    g_v = ((Bl(x) - Bl0) i - (Kms(x) - Kms0) x + 1/2 Le'(x) i^2) / Mms

and is stepped at the sample rate with the exponential integrator ETD2
(Cox & Matthews 2002): exact for the linear dynamics A, g extrapolated
linearly across the step from its last two values,

    s_nl[n+1] = Phi s_nl[n] + Ga g[n] + Gb (g[n] - g[n-1]),   [Phi Ga Gb] from one matrix exponential.

Why: a plain integrator of the whole system at 48 kHz cannot know the
band-limited voltage between samples; with linear interpolation Z and Hx come
out 17 % wrong at 10 kHz (0.9 % even at 4x oversampling). Here g -> 0 as
x -> 0, so at small signal the output IS the linear model, and the nonlinear
part, which lives mostly at low frequencies, is integrated where a step of
1/fs is short. g is treated explicitly; the one stiff term in it, (LE0/Le(x) - 1)
(RE + R2)/LE0, is checked at construction to stay well inside the step's
stability limit.

Approximations: creep acts on the small-signal part only (Kms(x) is a
frequency-independent stiffness); L2 and R2 do not depend on x. Speed: the
perturbation is a per-sample loop over Python floats, ~1.4 us of CPU per
sample; 16 periods of 16,384 samples take ~0.5 s of CPU with the FIRs
(bench/validity_bench.py measures it). A driver of the virtual rig at 48 kHz
thus uses ~7 % of a core.
"""
from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
import scipy.linalg

from analysis.effects import parse_effects
from analysis.model import Model
from instruments.simulation.block_driver import DriverBlock
from instruments.simulation.linear_driver import (
    DEFAULT_FIR_LENGTH, DEFAULT_PARTITION, PartitionedConvolver, frequency_sampled_fir)

# Defaults: the paper's driver softens with excursion (physics.md section 6: fs falls, Cms rises).
# Kms(x)/Kms0 = 1 - 12000 x^2 + 4.5e7 x^4: -27 % at 5 mm, -64 % at 8.6 mm, lowest (0.2) at 11.5 mm.
# With the project's multitone (16,384 samples, 5 Hz - 10 kHz) the fitted fs falls from 70.5 to 58 Hz
# and Cms rises by 53 % at 8.5 mm peak: the paper's 57.1 Hz and +50 % at 8.6 mm (physics.md section 6).
DEFAULT_KMS_POLY = (0.0, -12000.0, 0.0, 4.5e7)
# Bl(x)/Bl0 = 1 - 5000 x^2: -12.5 % at 5 mm (Klippel's Xmax criterion, 82 % of Bl0, near 6 mm).
DEFAULT_BL_POLY = (0.0, -5000.0)
# Le(x)/LE0 = 1 - 25 x: the coil's inductance rises when it moves in (x < 0), +-12.5 % at 5 mm.
DEFAULT_LE_POLY = (-25.0,)
DEFAULT_X_RANGE_M = 0.012
_MAX_DEGREE = 4
# The explicit stiff term times the step must stay below this (ETD2's explicit limit is ~1).
_STABILITY_MARGIN = 0.5


class NonlinearBlockDriver:
    """A BlockDriver whose Bl(x), Kms(x), Le(x) are polynomials in the displacement (see the module doc).

    From rest, a periodic excitation reaches its steady state after fir_length
    samples (the FIRs' history) plus a few ms (the perturbation's decay): with
    the default 65,536 taps, settle 5 periods of 16,384 samples; a fir_length
    of one period settles in two.
    """

    def __init__(self, values: Mapping[str, float], sample_rate: int,
                 bl_poly: Sequence[float] = DEFAULT_BL_POLY, kms_poly: Sequence[float] = DEFAULT_KMS_POLY,
                 le_poly: Sequence[float] = DEFAULT_LE_POLY, x_range_m: float = DEFAULT_X_RANGE_M,
                 fir_length: int = DEFAULT_FIR_LENGTH, partition_size: int = DEFAULT_PARTITION):
        missing = [k for k in ("RE", "LE", "CMES", "LCES", "RES", "Bl") if k not in values]
        if missing:
            raise ValueError(f"values lack {', '.join(missing)} (the electrical analogues of physics.md)")
        if sample_rate <= 0:
            raise ValueError(f"sample_rate must be positive, got {sample_rate}")
        if values["LE"] <= 0:
            raise ValueError("LE must be positive: the current is a state of the integrator")
        self.sample_rate = int(sample_rate)
        self.values = {k: float(v) for k, v in values.items()}
        self.bl_poly, self.kms_poly, self.le_poly = (_padded(p, name) for p, name in
                                                     ((bl_poly, "bl_poly"), (kms_poly, "kms_poly"),
                                                      (le_poly, "le_poly")))
        self.x_range_m = float(x_range_m)
        self.fir_length = int(fir_length)       # the rig's state reports it, as for the linear driver
        self.model = _small_signal_model(self.values)
        p = self.values
        self._consts = _constants(p)
        self._check_shapes()
        A, E = _perturbation_system(p, self._consts)
        self._phi, self._ga, self._gb = _etd2(A, E, 1.0 / self.sample_rate)
        self._convolver = PartitionedConvolver(_linear_firs(self.model, p, self.sample_rate, fir_length),
                                               partition_size)
        self.reset()

    # --- the BlockDriver protocol ---------------------------------------------------------------

    def process(self, voltage: np.ndarray) -> DriverBlock:
        u = np.array(voltage, dtype=np.float64).ravel()
        u.flags.writeable = False
        lin = self._convolver.process(u)
        current, displacement = self._integrate(u, lin)
        current.flags.writeable = False
        displacement.flags.writeable = False
        return DriverBlock(u, current, displacement)

    def reset(self) -> None:
        self._convolver.reset()
        self._state = [0.0, 0.0, 0.0, 0.0]     # i_nl, i2_nl, v_nl, x_nl
        self._g_prev = [0.0, 0.0]

    # --- what the driver is ------------------------------------------------------------------

    def bl(self, x: np.ndarray | float) -> np.ndarray:
        """Bl(x) in T*m (x clipped to the range)."""
        return self.values["Bl"] * _relative(self.bl_poly, np.clip(x, -self.x_range_m, self.x_range_m))

    def kms(self, x: np.ndarray | float) -> np.ndarray:
        """Kms(x) in N/m."""
        return self._consts["K0"] * _relative(self.kms_poly, np.clip(x, -self.x_range_m, self.x_range_m))

    def le(self, x: np.ndarray | float) -> np.ndarray:
        """Le(x) in H."""
        return self.values["LE"] * _relative(self.le_poly, np.clip(x, -self.x_range_m, self.x_range_m))

    def __repr__(self) -> str:
        return (f"NonlinearBlockDriver({self.model.describe()}, {self.sample_rate} Hz, bl={self.bl_poly}, "
                f"kms={self.kms_poly}, le={self.le_poly})")

    # --- internals --------------------------------------------------------------------------------

    def _check_shapes(self) -> None:
        x = np.linspace(-self.x_range_m, self.x_range_m, 2001)
        for name, curve in (("Bl", self.bl(x)), ("Kms", self.kms(x)), ("Le", self.le(x))):
            if np.any(curve <= 0):
                bad = x[np.argmax(curve <= 0)]
                raise ValueError(f"{name}(x) is not positive at x = {bad * 1e3:.2f} mm: change its polynomial "
                                 f"or narrow x_range_m ({self.x_range_m * 1e3:g} mm)")
        c = self._consts
        stiff = np.max(np.abs(self.values["LE"] / self.le(x) - 1.0)) * (c["RE"] + c["R2"]) / self.values["LE"]
        if stiff / self.sample_rate > _STABILITY_MARGIN:
            raise ValueError(f"Le(x) varies too much for the explicit step at {self.sample_rate} Hz "
                             f"({stiff / self.sample_rate:.2f} > {_STABILITY_MARGIN}): flatten le_poly")

    def _integrate(self, u: np.ndarray, lin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The per-sample ETD2 loop over Python floats (see the module doc); returns total i and x."""
        n = u.size
        current = np.empty(n)
        displacement = np.empty(n)
        if n == 0:
            return current, displacement
        c = self._consts
        RE, R2, Bl0, LE0, K0, Mms = c["RE"], c["R2"], c["Bl"], c["LE"], c["K0"], c["Mms"]
        xr = self.x_range_m
        b1, b2, b3, b4 = (Bl0 * k for k in self.bl_poly)
        k1, k2, k3, k4 = (K0 * k for k in self.kms_poly)
        l1, l2, l3, l4 = (LE0 * k for k in self.le_poly)
        (p00, p01, p02, p03), (p10, p11, p12, p13), (p20, p21, p22, p23), (p30, p31, p32, p33) = \
            self._phi.tolist()
        (a00, a01), (a10, a11), (a20, a21), (a30, a31) = self._ga.tolist()
        (q00, q01), (q10, q11), (q20, q21), (q30, q31) = self._gb.tolist()
        a, b, vv, d = self._state
        gi0, gv0 = self._g_prev
        out_i = [0.0] * n
        out_x = [0.0] * n
        half = 0.5
        rows = zip(u.tolist(), lin[0].tolist(), lin[1].tolist(), lin[2].tolist(), lin[3].tolist())
        for k, (uu, il, vl, xl, el) in enumerate(rows):
            i = il + a
            v = vl + vv
            x = xl + d
            xc = xr if x > xr else (-xr if x < -xr else x)
            # Deviations from the small-signal values, Horner (f(x) - f0 = x (c1 + x (c2 + ...))).
            dbl = xc * (b1 + xc * (b2 + xc * (b3 + xc * b4)))
            dk = xc * (k1 + xc * (k2 + xc * (k3 + xc * k4)))
            le = LE0 + xc * (l1 + xc * (l2 + xc * (l3 + xc * l4)))
            dle = 0.0 if xc != x else l1 + xc * (2.0 * l2 + xc * (3.0 * l3 + xc * 4.0 * l4))
            e = el - RE * a - R2 * (a - b)
            gi = (e - (Bl0 + dbl) * v - dle * v * i) / le - (e - Bl0 * v) / LE0
            gv = (dbl * i - dk * x + half * dle * i * i) / Mms
            si = gi - gi0
            sv = gv - gv0
            a, b, vv, d = (p00 * a + p01 * b + p02 * vv + p03 * d + a00 * gi + a01 * gv + q00 * si + q01 * sv,
                           p10 * a + p11 * b + p12 * vv + p13 * d + a10 * gi + a11 * gv + q10 * si + q11 * sv,
                           p20 * a + p21 * b + p22 * vv + p23 * d + a20 * gi + a21 * gv + q20 * si + q21 * sv,
                           p30 * a + p31 * b + p32 * vv + p33 * d + a30 * gi + a31 * gv + q30 * si + q31 * sv)
            gi0 = gi
            gv0 = gv
            out_i[k] = i
            out_x[k] = x
        self._state = [a, b, vv, d]
        self._g_prev = [gi0, gv0]
        current[:] = out_i
        displacement[:] = out_x
        return current, displacement


def _padded(poly: Sequence[float], name: str) -> tuple[float, ...]:
    coeffs = tuple(float(c) for c in poly)
    if len(coeffs) > _MAX_DEGREE:
        raise ValueError(f"{name}: at most {_MAX_DEGREE} coefficients (x^1 .. x^{_MAX_DEGREE}), got {len(coeffs)}")
    if not all(np.isfinite(coeffs)):
        raise ValueError(f"{name}: coefficients must be finite")
    return coeffs + (0.0,) * (_MAX_DEGREE - len(coeffs))


def _relative(poly: tuple[float, ...], x):
    """1 + c1 x + c2 x^2 + ... (Horner)."""
    acc = np.zeros_like(np.asarray(x, dtype=np.float64))
    for coeff in reversed(poly):
        acc = (acc + coeff) * x
    return 1.0 + acc


def _small_signal_model(p: Mapping[str, float]) -> Model:
    effects = []
    if "L2" in p and "R2" in p:
        effects.append("lr2")
    if "lambda" in p:
        effects.append("creep-log")
    return Model(parse_effects(",".join(effects) or "none"), with_displacement=True)


def _constants(p: Mapping[str, float]) -> dict[str, float]:
    Bl = p["Bl"]
    return {"RE": p["RE"], "LE": p["LE"], "Bl": Bl, "L2": p.get("L2", 0.0), "R2": p.get("R2", 0.0),
            "Mms": p["CMES"] * Bl**2, "Rms": Bl**2 / p["RES"], "K0": Bl**2 / p["LCES"]}


def _perturbation_system(p: Mapping[str, float], c: Mapping[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """A and E of ds/dt = A s + E g for s = (i, i2, v, x), without creep (see the module doc)."""
    RE, LE, R2, L2, Bl, Mms, Rms, K0 = (c[k] for k in ("RE", "LE", "R2", "L2", "Bl", "Mms", "Rms", "K0"))
    eddy = R2 / L2 if L2 > 0 else 0.0      # without LR-2, i2 stays 0 and R2 is 0
    A = np.array([[-(RE + R2) / LE, R2 / LE, -Bl / LE, 0.0],
                  [eddy, -eddy, 0.0, 0.0],
                  [Bl / Mms, 0.0, -Rms / Mms, -K0 / Mms],
                  [0.0, 0.0, 1.0, 0.0]])
    E = np.zeros((4, 2))
    E[0, 0] = 1.0
    E[2, 1] = 1.0
    return A, E


def _etd2(A: np.ndarray, E: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Phi = e^{Ah}; Ga = int_0^h e^{A(h-t)} dt E; Gb = int_0^h e^{A(h-t)} t/h dt E.

    From the exponential of [[A h, E h, 0], [0, 0, I], [0, 0, 0]]: the exact
    step for an input g(t) = g0 + (g0 - g_prev) t/h.
    """
    n, m = A.shape[0], E.shape[1]
    M = np.zeros((n + 2 * m, n + 2 * m))
    M[:n, :n] = A * h
    M[:n, n:n + m] = E * h
    M[n:n + m, n + m:] = np.eye(m)
    X = scipy.linalg.expm(M)
    return X[:n, :n], X[:n, n:n + m], X[:n, n + m:]


def _linear_firs(model: Model, p: Mapping[str, float], sample_rate: int, length: int) -> np.ndarray:
    """FIRs of the small-signal i, v, x and e = u - RE i - ZP i (the inputs of g), per volt."""
    def admittance(s):
        return 1.0 / model.impedance(s, p)

    def eddy_and_re(s):
        return model.blocked_impedance(s, p) - s * p["LE"]      # RE + ZP(s)

    responses = (admittance,
                 lambda s: s * model.displacement(s, p),
                 lambda s: model.displacement(s, p),
                 lambda s: 1.0 - eddy_and_re(s) * admittance(s))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.stack([frequency_sampled_fir(r, sample_rate, length) for r in responses])
