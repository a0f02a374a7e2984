"""A loudspeaker whose Bl, stiffness, inductances and damping depend on the cone and the coil, in the time domain.

Equations (docs/physics.md sections 1 and 6 with the parameters made functions of x,
i and v; state: coil current i, eddy-branch current i2, velocity v, displacement x):

    d/dt(L(x, i) i)  = u - RE i - R2 (i - i2) - Bl(x) v     (L(x, i) i: the coil's flux)
    d/dt(L2(x) i2)   = R2 (i - i2)                           (LR-2: ZP = s L2 R2 / (s L2 + R2) at rest)
    Mms dv/dt        = Bl(x) i - Rms(v) v - Kms(x) x + 1/2 Le'(x) i^2 + 1/2 L2'(x) i2^2   (reluctance forces)
    dx/dt            = v

    Mms = CMES Bl0^2, Rms0 = Bl0^2 / RES, Kms(0) = Bl0^2 / LCES (the electrical analogues of `values`)
    Bl(x)   = Bl0  (1 + b1 x + b2 x^2 + ...)      bl_poly   = (b1, b2, ...)   [1/m, 1/m^2, ...]
    Kms(x)  = Kms0 (1 + k1 x + k2 x^2 + ...)      kms_poly  = (k1, k2, ...)
    Le(x)   = LE0  (1 + l1 x + l2 x^2 + ...)      le_poly   = (l1, l2, ...)
    L2(x)   = L20  (1 + m1 x + m2 x^2 + ...)      l2_poly   = (m1, m2, ...)
    L(x, i) = Le(x) + LE0 (c1 i + c2 i^2)         le_i_poly = (c1, c2)        [1/A, 1/A^2]  (iron: Le(i))
    Rms(v)  = Rms0 (1 + r2 v^2)                   rms_v2                      [s^2/m^2]

Le(i) is added to Le(x), so that the flux L(x, i) i has the incremental
inductance d(L i)/di = Le(x) + LE0 (2 c1 i + 3 c2 i^2) and the reluctance
force stays 1/2 Le'(x) i^2 (the co-energy's x-derivative). The polynomials
are relative, so the small-signal parameters are `values` whatever the
shapes. They are evaluated at x clipped to +-x_range_m and i clipped to
+-i_range_a (the ranges in which the construction checks that every curve
stays positive and the explicit step stable).

How it is integrated: exact linear part + integrated nonlinear part
------------------------------------------------------------------
The state is split, s = s_lin + s_nl. s_lin is the small-signal response to
u, from frequency-sampled FIRs (instruments.simulation.linear_driver: exact
for a periodic excitation whose period divides fir_length, no latency), with
the whole analysis.model.composed: LR-2 if values hold L2 and R2, log creep if they
hold "lambda". s_nl obeys the linearised equations driven by what the linear
model leaves out,

    ds_nl/dt = A s_nl + E g(s_lin + s_nl, u)
    g_i = (e - Bl(x) v - Le'(x) v i) / L_inc(x, i) - (e - Bl0 v) / LE0,   e = u - RE i - e2
    g_2 = (e2 - L2'(x) v i2) / L2(x) - e2 / L20,                          e2 = R2 (i - i2)
    g_v = ((Bl(x) - Bl0) i - (Kms(x) - Kms0) x + 1/2 Le'(x) i^2 + 1/2 L2'(x) i2^2 - Rms0 r2 v^3) / Mms

and is stepped at the sample rate with the exponential integrator ETD2
(Cox & Matthews 2002): exact for the linear dynamics A, g extrapolated
linearly across the step from its last two values,

    s_nl[n+1] = Phi s_nl[n] + Ga g[n] + Gb (g[n] - g[n-1]),   [Phi Ga Gb] from one matrix exponential.

The eddy branch's small-signal current comes from the FIRs' outputs
(i2 = i - e2 / R2, e2 = u - RE i - e), so it needs no FIR of its own.

Why: a plain integrator of the whole system at 48 kHz cannot know the
band-limited voltage between samples; with linear interpolation Z and Hx come
out 17 % wrong at 10 kHz (0.9 % even at 4x oversampling). Here g -> 0 as
x -> 0, so at small signal the output IS the linear model, and the nonlinear
part, which lives mostly at low frequencies, is integrated where a step of
1/fs is short. g is treated explicitly; the one stiff terms in it, (LE0/L_inc - 1)
(RE + R2)/LE0 and (L20/L2(x) - 1) R2/L20, are checked at construction to
stay well inside the step's stability limit.

Approximations: creep acts on the small-signal part only (Kms(x) is a
frequency-independent stiffness: a real-valued log creep law has no causal
time-domain form, so a driver given "lambda" is not one the large-signal
identification can match exactly); R2 does not depend on x. Speed: the
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
from analysis.model.composed import Model
from instruments.simulation.block_driver import DriverBlock
from instruments.simulation.linear_driver import (
    DEFAULT_FIR_LENGTH, DEFAULT_PARTITION, PartitionedConvolver, frequency_sampled_fir)

# Defaults: the paper's driver softens with excursion (docs/physics.md section 6: fs falls, Cms rises).
# Kms(x)/Kms0 = 1 - 12000 x^2 + 4.5e7 x^4: -27 % at 5 mm, -64 % at 8.6 mm, lowest (0.2) at 11.5 mm.
# With the project's multitone (16,384 samples, 5 Hz - 10 kHz) the fitted fs falls from 70.5 to 58 Hz
# and Cms rises by 53 % at 8.5 mm peak: the paper's 57.1 Hz and +50 % at 8.6 mm (docs/physics.md section 6).
DEFAULT_KMS_POLY = (0.0, -12000.0, 0.0, 4.5e7)
# Bl(x)/Bl0 = 1 - 5000 x^2: -12.5 % at 5 mm (Klippel's Xmax criterion, 82 % of Bl0, near 6 mm).
DEFAULT_BL_POLY = (0.0, -5000.0)
# Le(x)/LE0 = 1 - 25 x: the coil's inductance rises when it moves in (x < 0), +-12.5 % at 5 mm.
DEFAULT_LE_POLY = (-25.0,)
DEFAULT_X_RANGE_M = 0.012
DEFAULT_I_RANGE_A = 20.0
_MAX_DEGREE = 4
# The explicit stiff terms times the step must stay below this (ETD2's explicit limit is ~1).
_STABILITY_MARGIN = 0.5


class NonlinearBlockDriver:
    """A BlockDriver whose Bl(x), Kms(x), Le(x), L2(x), Le(i) and Rms(v) are polynomials (see the module doc).

    From rest, a periodic excitation reaches its steady state after fir_length
    samples (the FIRs' history) plus a few ms (the perturbation's decay): with
    the default 65,536 taps, settle 5 periods of 16,384 samples; a fir_length
    of one period settles in two.
    """

    def __init__(self, values: Mapping[str, float], sample_rate: int,
                 bl_poly: Sequence[float] = DEFAULT_BL_POLY, kms_poly: Sequence[float] = DEFAULT_KMS_POLY,
                 le_poly: Sequence[float] = DEFAULT_LE_POLY, x_range_m: float = DEFAULT_X_RANGE_M,
                 fir_length: int = DEFAULT_FIR_LENGTH, partition_size: int = DEFAULT_PARTITION, *,
                 l2_poly: Sequence[float] = (), le_i_poly: Sequence[float] = (), rms_v2: float = 0.0,
                 i_range_a: float = DEFAULT_I_RANGE_A, substeps: int = 1):
        missing = [k for k in ("RE", "LE", "CMES", "LCES", "RES", "Bl") if k not in values]
        if missing:
            raise ValueError(f"values lack {', '.join(missing)} (the electrical analogues of docs/physics.md section 1)")
        if sample_rate <= 0:
            raise ValueError(f"sample_rate must be positive, got {sample_rate}")
        if values["LE"] <= 0:
            raise ValueError("LE must be positive: the current is a state of the integrator")
        self.sample_rate = int(sample_rate)
        self.values = {k: float(v) for k, v in values.items()}
        self.bl_poly, self.kms_poly, self.le_poly, self.l2_poly = (
            _padded(p, name) for p, name in ((bl_poly, "bl_poly"), (kms_poly, "kms_poly"), (le_poly, "le_poly"),
                                             (l2_poly, "l2_poly")))
        self.le_i_poly = _padded(le_i_poly, "le_i_poly", degree=2)
        if not (np.isfinite(rms_v2) and rms_v2 >= 0):
            raise ValueError(f"rms_v2 must be finite and >= 0 (a damping that grows with speed), got {rms_v2!r}")
        self.rms_v2 = float(rms_v2)
        if not (isinstance(substeps, int) and 1 <= substeps <= 16):
            raise ValueError(f"substeps must be an integer from 1 to 16, got {substeps!r}")
        self.substeps = substeps
        self.x_range_m = float(x_range_m)
        self.i_range_a = float(i_range_a)
        self.fir_length = int(fir_length)       # the rig's state reports it, as for the linear driver
        self.model = _small_signal_model(self.values)
        p = self.values
        self._consts = _constants(p)
        if any(self.l2_poly) and self._consts["L2"] <= 0:
            raise ValueError("l2_poly needs an eddy branch: give L2 and R2 in values")
        self._check_shapes()
        A, E = _perturbation_system(p, self._consts)
        self._phi, self._ga, self._gb = _etd2(A, E, 1.0 / (self.sample_rate * substeps))
        self._convolver = PartitionedConvolver(_linear_firs(self.model, p, self.sample_rate, fir_length, substeps),
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
        self._g_prev = [0.0, 0.0, 0.0]

    # --- what the driver is ------------------------------------------------------------------

    def bl(self, x: np.ndarray | float) -> np.ndarray:
        """Bl(x) in T*m (x clipped to the range)."""
        return self.values["Bl"] * _relative(self.bl_poly, self._clip(x))

    def kms(self, x: np.ndarray | float) -> np.ndarray:
        """Kms(x) in N/m."""
        return self._consts["K0"] * _relative(self.kms_poly, self._clip(x))

    def le(self, x: np.ndarray | float) -> np.ndarray:
        """Le(x) in H (at zero current)."""
        return self.values["LE"] * _relative(self.le_poly, self._clip(x))

    def l2(self, x: np.ndarray | float) -> np.ndarray:
        """L2(x) in H (0 without an eddy branch)."""
        return self._consts["L2"] * _relative(self.l2_poly, self._clip(x))

    def le_of_current(self, i: np.ndarray | float) -> np.ndarray:
        """L(0, i) in H: the coil's inductance at rest carrying i (Le(i))."""
        return self.values["LE"] * _relative(self.le_i_poly, np.clip(i, -self.i_range_a, self.i_range_a))

    def rms(self, v: np.ndarray | float) -> np.ndarray:
        """Rms(v) in kg/s."""
        return self._consts["Rms"] * (1.0 + self.rms_v2 * np.square(v))

    def __repr__(self) -> str:
        return (f"NonlinearBlockDriver({self.model.describe()}, {self.sample_rate} Hz, bl={self.bl_poly}, "
                f"kms={self.kms_poly}, le={self.le_poly}, l2={self.l2_poly}, le_i={self.le_i_poly}, "
                f"rms_v2={self.rms_v2})")

    # --- internals --------------------------------------------------------------------------------

    def _clip(self, x):
        return np.clip(x, -self.x_range_m, self.x_range_m)

    def _check_shapes(self) -> None:
        x = np.linspace(-self.x_range_m, self.x_range_m, 2001)
        i = np.linspace(-self.i_range_a, self.i_range_a, 2001)
        c = self._consts
        curves = [("Bl", self.bl(x)), ("Kms", self.kms(x)), ("Le", self.le(x))]
        if c["L2"] > 0:
            curves.append(("L2", self.l2(x)))
        for name, curve in curves:
            if np.any(curve <= 0):
                bad = x[np.argmax(curve <= 0)]
                raise ValueError(f"{name}(x) is not positive at x = {bad * 1e3:.2f} mm: change its polynomial "
                                 f"or narrow x_range_m ({self.x_range_m * 1e3:g} mm)")
        c1, c2 = self.le_i_poly[:2]
        incremental = np.min(self.le(x)) + c["LE"] * np.minimum(2 * c1 * i + 3 * c2 * i * i, 0.0).min()
        if incremental <= 0:
            raise ValueError(f"Le(i) makes the coil's incremental inductance negative within "
                             f"+-{self.i_range_a:g} A: flatten le_i_poly or narrow i_range_a")
        stiff = np.max(np.abs(c["LE"] / incremental - 1.0)) * (c["RE"] + c["R2"]) / c["LE"]
        if c["L2"] > 0:
            stiff = max(stiff, np.max(np.abs(c["L2"] / self.l2(x) - 1.0)) * c["R2"] / c["L2"])
        rate = self.sample_rate * self.substeps
        if stiff / rate > _STABILITY_MARGIN:
            raise ValueError(f"Le(x), Le(i) or L2(x) vary too much for the explicit step at {rate} Hz "
                             f"({stiff / rate:.2f} > {_STABILITY_MARGIN}): flatten their polynomials or take "
                             f"more substeps")

    def _integrate(self, u: np.ndarray, lin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The per-sample ETD2 loop over Python floats (see the module doc); returns total i and x."""
        n = u.size
        current = np.empty(n)
        displacement = np.empty(n)
        if n == 0:
            return current, displacement
        c = self._consts
        RE, R2, L20, Bl0, LE0, Mms = c["RE"], c["R2"], c["L2"], c["Bl"], c["LE"], c["Mms"]
        K0 = c["K0"]
        damping = c["Rms"] * self.rms_v2
        xr, ir = self.x_range_m, self.i_range_a
        inv_r2 = 1.0 / R2 if R2 > 0 else 0.0
        eddy = L20 > 0
        b1, b2, b3, b4 = (Bl0 * k for k in self.bl_poly)
        k1, k2, k3, k4 = (K0 * k for k in self.kms_poly)
        l1, l2, l3, l4 = (LE0 * k for k in self.le_poly)
        m1, m2, m3, m4 = (L20 * k for k in self.l2_poly)
        q1, q2 = (LE0 * k for k in self.le_i_poly)
        (p00, p01, p02, p03), (p10, p11, p12, p13), (p20, p21, p22, p23), (p30, p31, p32, p33) = \
            self._phi.tolist()
        (a00, a01, a02), (a10, a11, a12), (a20, a21, a22), (a30, a31, a32) = self._ga.tolist()
        (q00, q01, q02), (q10, q11, q12), (q20, q21, q22), (q30, q31, q32) = self._gb.tolist()
        a, b, vv, d = self._state
        gi0, g20, gv0 = self._g_prev
        g2 = 0.0
        out_i = [0.0] * n
        out_x = [0.0] * n
        half = 0.5
        m = self.substeps
        if m == 1:      # e2 = u - RE i - e of the linear part: no FIR needed at the samples themselves
            streams = [row.tolist() for row in lin] + [(u - RE * lin[0] - lin[3]).tolist()]
        else:           # the linear part at every substep, in time order: lin's rows are (i, v, x, e, e2) per substep
            streams = [lin[r::5].T.ravel().tolist() for r in range(5)]
        for step, (il, vl, xl, el, e2l) in enumerate(zip(*streams)):
            i = il + a
            v = vl + vv
            x = xl + d
            if step % m == 0:
                out_i[step // m] = i
                out_x[step // m] = x
            xc = xr if x > xr else (-xr if x < -xr else x)
            ic = ir if i > ir else (-ir if i < -ir else i)
            # Deviations from the small-signal values, Horner (f(x) - f0 = x (c1 + x (c2 + ...))).
            dbl = xc * (b1 + xc * (b2 + xc * (b3 + xc * b4)))
            dk = xc * (k1 + xc * (k2 + xc * (k3 + xc * k4)))
            le = LE0 + xc * (l1 + xc * (l2 + xc * (l3 + xc * l4)))
            dle = 0.0 if xc != x else l1 + xc * (2.0 * l2 + xc * (3.0 * l3 + xc * 4.0 * l4))
            incremental = le + (0.0 if ic != i else ic * (2.0 * q1 + 3.0 * q2 * ic))
            e2 = e2l + R2 * (a - b)                      # R2 (i - i2): the eddy branch's voltage
            e = el - RE * a - R2 * (a - b)               # u - RE i - e2
            gi = (e - (Bl0 + dbl) * v - dle * v * i) / incremental - (e - Bl0 * v) / LE0
            force = dbl * i - dk * x + half * dle * i * i - damping * v * v * v
            if eddy:
                i2 = il - e2l * inv_r2 + b
                l2x = L20 + xc * (m1 + xc * (m2 + xc * (m3 + xc * m4)))
                dl2 = 0.0 if xc != x else m1 + xc * (2.0 * m2 + xc * (3.0 * m3 + xc * 4.0 * m4))
                g2 = (e2 - dl2 * v * i2) / l2x - e2 / L20
                force += half * dl2 * i2 * i2
            gv = force / Mms
            si = gi - gi0
            s2 = g2 - g20
            sv = gv - gv0
            a, b, vv, d = (
                p00 * a + p01 * b + p02 * vv + p03 * d + a00 * gi + a01 * g2 + a02 * gv + q00 * si + q01 * s2
                + q02 * sv,
                p10 * a + p11 * b + p12 * vv + p13 * d + a10 * gi + a11 * g2 + a12 * gv + q10 * si + q11 * s2
                + q12 * sv,
                p20 * a + p21 * b + p22 * vv + p23 * d + a20 * gi + a21 * g2 + a22 * gv + q20 * si + q21 * s2
                + q22 * sv,
                p30 * a + p31 * b + p32 * vv + p33 * d + a30 * gi + a31 * g2 + a32 * gv + q30 * si + q31 * s2
                + q32 * sv)
            gi0 = gi
            g20 = g2
            gv0 = gv
        self._state = [a, b, vv, d]
        self._g_prev = [gi0, g20, gv0]
        current[:] = out_i
        displacement[:] = out_x
        return current, displacement


def _padded(poly: Sequence[float], name: str, degree: int = _MAX_DEGREE) -> tuple[float, ...]:
    coeffs = tuple(float(c) for c in poly)
    if len(coeffs) > degree:
        raise ValueError(f"{name}: at most {degree} coefficients (x^1 .. x^{degree}), got {len(coeffs)}")
    if not all(np.isfinite(coeffs)):
        raise ValueError(f"{name}: coefficients must be finite")
    return coeffs + (0.0,) * (degree - len(coeffs))


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
    E = np.zeros((4, 3))        # g = (g_i, g_2, g_v)
    E[0, 0] = 1.0
    E[1, 1] = 1.0
    E[2, 2] = 1.0
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


def _linear_firs(model: Model, p: Mapping[str, float], sample_rate: int, length: int,
                 substeps: int = 1) -> np.ndarray:
    """FIRs of the small-signal i, v, x, e = u - RE i - ZP i and e2 = ZP i (the inputs of g), per volt (e2's
    only with substeps).

    With substeps, one set per substep q, advanced by q / (substeps * sample_rate): the linear part between
    the samples (exact for a periodic excitation, as the FIRs themselves; see linear_driver).
    """
    def admittance(s):
        return 1.0 / model.impedance(s, p)

    def eddy_and_re(s):
        return model.blocked_impedance(s, p) - s * p["LE"]      # RE + ZP(s)

    responses = (admittance,
                 lambda s: s * model.displacement(s, p),
                 lambda s: model.displacement(s, p),
                 lambda s: 1.0 - eddy_and_re(s) * admittance(s),
                 lambda s: (eddy_and_re(s) - p["RE"]) * admittance(s))
    if substeps == 1:
        responses = responses[:4]       # e2 = u - RE i - e, from the others (a fifth FIR would cost 25 % more)
    firs = []
    with np.errstate(divide="ignore", invalid="ignore"):
        for q in range(substeps):
            advance = q / (substeps * sample_rate)
            firs += [frequency_sampled_fir(lambda s, r=r: r(s) * np.exp(s * advance), sample_rate, length)
                     for r in responses]
    return np.stack(firs)
