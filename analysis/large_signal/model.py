"""The identified large-signal model in SI units, centred on the coil's rest position.

    Bl(x), Kms(x), Le(x), L2(x)      polynomials in ascending powers of x (m), curves.Curve
    RE, R2, L2(0) = R2 tau2          the coil and its eddy-current branch (LR-2)
    q1, q2                           Le(i): the coil's flux is Le(x) i + q1 i^2 + q2 i^3
    Mms, Rms, r                      moving mass, mechanical resistance, Rms(v) = Rms + r v^2
    kappa, lambda, ws                log creep: the stiffness K(x) x + kappa (1 / c(s) - 1) X,
                                     c(s) = 1 - lambda log10(w / ws), absent at DC

from the regression's scaled coefficients (columns.py: B_j xn^j with
xn = x / x_scale, so c_j = B_j / x_scale^j, and the covariance likewise).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.large_signal.curves import Curve
from analysis.large_signal.identify import Identification

CURVES = ("Bl", "Kms", "Le")
SCALARS = ("RE", "R2", "Mms", "Rms")


@dataclass(frozen=True, slots=True, eq=False)
class Scalar:
    value: float
    std: float


@dataclass(frozen=True, slots=True, eq=False)
class LargeSignalModel:
    curves: dict                  # name -> Curve: "Bl", "Kms", "Le" and, when identified, "L2"
    scalars: dict                 # name -> Scalar: RE, R2, Mms, Rms, tau2, and the optional terms' coefficients
    tau2: float                   # s
    lam: float
    ws: float                     # rad/s
    le_i: tuple[float, ...]       # (q1, q2) H/A, H/A^2 (zeros when absent)
    rms_v: float                  # r, kg s / m^2
    creep: float                  # kappa, N/m (0 without creep)
    x_range: tuple[float, float]  # m

    @property
    def Bl(self) -> Curve:
        return self.curves["Bl"]

    @property
    def Kms(self) -> Curve:
        return self.curves["Kms"]

    @property
    def Le(self) -> Curve:
        return self.curves["Le"]

    def value(self, name: str) -> float:
        return self.scalars[name].value

    @property
    def L20(self) -> float:
        return self.value("R2") * self.tau2

    def l2_delta(self) -> np.ndarray:
        """Coefficients of L2(x) - L2(0) (ascending, SI); zeros without L2(x)."""
        if "L2" not in self.curves:
            return np.zeros(1)
        c = self.curves["L2"].coefficients.copy()
        c[0] = 0.0
        return c

    def stiffness(self, s: np.ndarray) -> np.ndarray:
        """The small-signal mechanical stiffness K0 + kappa (1 / c(s) - 1), with creep absent at DC."""
        k0 = self.Kms.coefficients[0]
        out = np.full(s.shape, k0, dtype=complex)
        if self.creep and self.lam:
            w = np.abs(s)
            nz = w > 0
            c = 1.0 - self.lam * np.log10(w[nz] / self.ws)
            out[nz] += self.creep * (1.0 / c - 1.0)
        return out


def model_of(ident: Identification) -> LargeSignalModel:
    """The SI model of an identification (coefficients rescaled, the L2 branch's L2(0) put in front)."""
    xs = ident.x_scale
    x_range = _covered(ident)
    x0_std = _combined(ident.offsets_std)
    curves = {}
    for name in CURVES + ("L2",):
        powers, coeffs, cov = ident.block(name)
        if name == "L2":
            if powers.size == 0:
                continue
            powers = np.concatenate([[0], powers])
            r2, var_r2 = ident.value("R2"), ident.cov[_index(ident, "R2"), _index(ident, "R2")]
            coeffs = np.concatenate([[r2 * ident.nuisance.tau2], coeffs])
            full = np.zeros((powers.size, powers.size))
            full[1:, 1:] = cov
            full[0, 0] = var_r2 * ident.nuisance.tau2**2
            cov = full
        scale = 1.0 / xs ** powers.astype(float)
        c = np.zeros(powers.max() + 1)
        c[powers] = coeffs * scale
        cv = np.zeros((c.size, c.size))
        cv[np.ix_(powers, powers)] = cov * np.outer(scale, scale)
        curves[name] = Curve(name, c, cv, x_range, x0_std)
    scalars = {}
    for name in SCALARS:
        k = _index(ident, name)
        scalars[name] = Scalar(float(ident.theta[k]), float(np.sqrt(max(ident.cov[k, k], 0.0))))
    optional = {("LeI", 1): "q1", ("LeI", 2): "q2", ("Rv", 2): "r", ("creep", 0): "kappa"}
    for key, label in optional.items():
        if key in ident.names:
            k = ident.names.index(key)
            scalars[label] = Scalar(float(ident.theta[k]), float(np.sqrt(max(ident.cov[k, k], 0.0))))
    scalars["tau2"] = Scalar(ident.nuisance.tau2, float("nan"))
    if ident.orders.creep:
        scalars["lambda"] = Scalar(ident.nuisance.lam, float("nan"))
    return LargeSignalModel(curves, scalars, ident.nuisance.tau2, ident.nuisance.lam, ident.nuisance.ws,
                            (ident.value("LeI", 1), ident.value("LeI", 2)), ident.value("Rv", 2),
                            ident.value("creep"), x_range)


def _covered(ident: Identification) -> tuple[float, float]:
    lows, highs = [], []
    for data, offset in zip(ident.data, ident.offsets):
        x = data.mean("x") + offset
        lows.append(float(x.min()))
        highs.append(float(x.max()))
    return min(lows), max(highs)


def _combined(stds) -> float:
    finite = [s for s in stds if np.isfinite(s) and s > 0]
    if not finite:
        return 0.0
    return float(1.0 / np.sqrt(np.sum(1.0 / np.square(finite))))


def _index(ident: Identification, name: str, power: int = 0) -> int:
    return ident.names.index((name, power))
