"""A curve against the displacement: a polynomial in ascending powers of x (m), its covariance and its range.

    f(x) = sum_k c_k x^k,   var f(x) = J(x) C J(x)^T + (f'(x) sigma_x0)^2,   J(x) = (1, x, x^2, ...)

C is the coefficients' covariance from the regression; sigma_x0 is the
uncertainty of the rest position the polynomial is centred on (a shift of
the whole curve along x, which the coefficients' covariance does not hold).
The curve means something only inside x_range, the displacement the
measurements covered: outside it a polynomial extrapolates, so evaluating
there is allowed (plots draw the whole axis) but limits beyond it are
reported as such (limits.py).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

UNITS = {"Bl": "T*m", "Kms": "N/m", "Le": "H", "L2": "H", "Cms": "m/N"}
DISPLAY = {"Bl": ("T·m", 1.0), "Kms": ("N/mm", 1e-3), "Le": ("mH", 1e3), "L2": ("mH", 1e3), "Cms": ("mm/N", 1e3)}


@dataclass(frozen=True, slots=True, eq=False)
class Curve:
    name: str                     # "Bl", "Kms", "Le", "L2"
    coefficients: np.ndarray      # ascending powers of x in m, SI
    cov: np.ndarray               # covariance of the coefficients
    x_range: tuple[float, float]  # m, what the measurements covered
    x0_std: float = 0.0           # m, uncertainty of the rest position

    @property
    def unit(self) -> str:
        return UNITS[self.name]

    @property
    def order(self) -> int:
        return self.coefficients.size - 1

    @property
    def std(self) -> np.ndarray:
        return np.sqrt(np.maximum(np.diag(self.cov), 0.0))

    def __call__(self, x) -> np.ndarray:
        return np.polynomial.polynomial.polyval(np.asarray(x, dtype=np.float64), self.coefficients)

    def derivative(self, x) -> np.ndarray:
        return np.polynomial.polynomial.polyval(np.asarray(x, dtype=np.float64),
                                                np.polynomial.polynomial.polyder(self.coefficients))

    def sigma(self, x) -> np.ndarray:
        """1-sigma of f(x), m -> unit of the curve."""
        x = np.atleast_1d(np.asarray(x, dtype=np.float64))
        jac = np.vander(x, self.coefficients.size, increasing=True)
        var = np.einsum("ij,jk,ik->i", jac, self.cov, jac) + (self.derivative(x) * self.x0_std) ** 2
        return np.sqrt(np.maximum(var, 0.0))

    def inside(self, x) -> np.ndarray:
        x = np.asarray(x, dtype=np.float64)
        return (x >= self.x_range[0]) & (x <= self.x_range[1])

    def as_json(self) -> dict:
        return {"coefficients": self.coefficients.tolist(), "unit": self.unit, "std": self.std.tolist(),
                "x_range": [float(self.x_range[0]), float(self.x_range[1])], "order": self.order,
                "covariance": self.cov.tolist(), "x0_std_m": self.x0_std}

    def sampled(self, n: int = 101, margin: float = 0.0) -> dict:
        """Values and 1-sigma at n points across the covered range (plus a margin on each side), SI."""
        lo, hi = self.x_range
        width = hi - lo
        x = np.linspace(lo - margin * width, hi + margin * width, n)
        return {"x_m": x, "value": self(x), "sigma": self.sigma(x)}


def compliance_of(kms: Curve, x: np.ndarray) -> np.ndarray:
    """Cms(x) = 1 / Kms(x), m/N (NaN where Kms(x) <= 0)."""
    k = kms(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(k > 0, 1.0 / k, np.nan)
