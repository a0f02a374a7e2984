"""What the curves say about the driver: the coil's rest offset, the stiffness asymmetry, the excursion limits.

    offset           where Bl(x) is largest; positive x is outwards (away from the magnet), so a maximum
                     at x < 0 means the coil rests too far out and should move in by |offset|
    Kms asymmetry    A_K = 2 (Kms(+X) - Kms(-X)) / (Kms(+X) + Kms(-X)), in %, at the largest excursion
                     X measured on both sides
    X_Bl             the smallest |x| at which Bl(x) falls to bl_ratio of Bl(0)        (82 %)
    X_C              ... at which Cms(x) = 1 / Kms(x) falls to compliance_ratio of Cms(0) (75 %)
    X_L              ... at which Le(x) leaves Le(0) by more than le_change              (10 %)

The defaults are Klippel's published ones, after IEC 62458 (docs/physics.md
section 6). A limit is looked for on both sides of the rest position,
inside the range the measurements covered: where a side's curve never
crosses its threshold there, that side only says "beyond the covered range"
and the limit is reported as a lower bound when it is that side's edge that
bounds it (``beyond_range``). The 1-sigma of each value comes from drawing
the coefficients (and the rest position) from their covariance.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from analysis.large_signal.data import LargeSignalError
from analysis.large_signal.model import LargeSignalModel

GRID_POINTS = 801
DRAWS = 300


@dataclass(frozen=True, slots=True)
class LimitThresholds:
    bl_ratio: float = 0.82
    compliance_ratio: float = 0.75
    le_change: float = 0.10

    def __post_init__(self) -> None:
        for name, value in (("bl_ratio", self.bl_ratio), ("compliance_ratio", self.compliance_ratio),
                            ("le_change", self.le_change)):
            if not (isinstance(value, (int, float)) and np.isfinite(value) and 0.0 < value < 1.0):
                raise LargeSignalError(f"{name}: expected a fraction between 0 and 1 (exclusive), got {value!r}")

    def criteria(self) -> dict[str, str]:
        return {"X_Bl": f"Bl >= {self.bl_ratio * 100:g} %", "X_C": f"Cms >= {self.compliance_ratio * 100:g} %",
                "X_L": f"Le within ±{self.le_change * 100:g} %"}


@dataclass(frozen=True, slots=True)
class Limit:
    name: str
    value: float | None          # m; None when neither side could be looked at
    std: float
    criterion: str
    beyond_range: bool           # value is a lower bound: the covered range ends before the threshold
    side: str | None             # "outward" / "inward": the side that limits

    def as_json(self) -> dict:
        return {"value": self.value, "std": _finite(self.std), "criterion": self.criterion,
                "beyond_range": self.beyond_range, "side": self.side}


@dataclass(frozen=True, slots=True)
class Derived:
    offset_m: float              # Bl's maximum
    offset_std: float
    offset_at_edge: bool         # the maximum is at an edge of the covered range: it may lie beyond
    asymmetry_percent: float     # stiffness
    asymmetry_std: float
    asymmetry_at_m: float        # where it is evaluated
    limits: dict = field(default_factory=dict)    # name -> Limit

    def coil_advice(self) -> str:
        """Where to move the coil, in words."""
        mm = abs(self.offset_m) * 1e3
        if self.offset_at_edge:
            return (f"Bl(x) is still rising at the edge of the measured range ({self.offset_m * 1e3:+.2f} mm): "
                    f"measure at a higher level to find its maximum")
        if mm < max(2.0 * self.offset_std * 1e3, 0.02):
            return "the coil is centred: Bl(x) is largest at its rest position"
        direction = "in (towards the magnet)" if self.offset_m < 0 else "out (away from the magnet)"
        return f"Bl(x) is largest {mm:.2f} mm {'inwards' if self.offset_m < 0 else 'outwards'}: move the coil " \
               f"{mm:.2f} mm {direction}"

    def as_json(self) -> dict:
        return {"offset_m": self.offset_m, "offset_std_m": _finite(self.offset_std),
                "offset_at_edge": self.offset_at_edge, "coil_advice": self.coil_advice(),
                "kms_asymmetry_percent": self.asymmetry_percent, "kms_asymmetry_std": _finite(self.asymmetry_std),
                "kms_asymmetry_at_m": self.asymmetry_at_m}


def derived(model: LargeSignalModel, thresholds: LimitThresholds = LimitThresholds(), draws: int = DRAWS,
            seed: int = 0) -> Derived:
    """Offset, asymmetry and limits with their 1-sigma (module doc)."""
    lo, hi = model.x_range
    grid = np.linspace(lo, hi, GRID_POINTS)
    x_sym = min(-lo, hi)
    samples = _draws(model, draws, seed)
    offset, at_edge = _bl_maximum(model.Bl.coefficients, grid)
    offsets = [_bl_maximum(bl, grid)[0] for bl, _, _, _ in samples]
    asym = _asymmetry(model.Kms.coefficients, x_sym)
    asyms = [_asymmetry(k, x_sym) for _, k, _, _ in samples]
    criteria = thresholds.criteria()
    limits = {}
    for name, ratio_of in (("X_Bl", lambda bl, k, le: _ratio(bl, grid)),
                           ("X_C", lambda bl, k, le: _compliance_ratio(k, grid)),
                           ("X_L", lambda bl, k, le: _ratio(le, grid))):
        margin = _margin_fn(name, thresholds)
        value, beyond, side = _limit(grid, margin(ratio_of(model.Bl.coefficients, model.Kms.coefficients,
                                                           model.Le.coefficients)))
        spread = [_limit(grid, margin(ratio_of(bl, k, le)))[0] for bl, k, le, _ in samples]
        spread = [v for v in spread if v is not None]
        limits[name] = Limit(name, value, float(np.std(spread)) if len(spread) > 2 else float("nan"),
                             criteria[name], beyond, side)
    return Derived(offset, _spread(offsets), at_edge, asym, _spread(asyms), x_sym, limits)


def _spread(values: list[float]) -> float:
    return float(np.std(values)) if values else float("nan")


def _margin_fn(name: str, th: LimitThresholds):
    """How far inside its allowed region a ratio is (>= 0 inside), per limit."""
    if name == "X_Bl":
        return lambda r: r - th.bl_ratio
    if name == "X_C":
        return lambda r: r - th.compliance_ratio
    return lambda r: th.le_change - np.abs(r - 1.0)


def _ratio(coefficients: np.ndarray, grid: np.ndarray) -> np.ndarray:
    return np.polynomial.polynomial.polyval(grid, coefficients) / coefficients[0]


def _compliance_ratio(kms: np.ndarray, grid: np.ndarray) -> np.ndarray:
    k = np.polynomial.polynomial.polyval(grid, kms)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(k > 0, kms[0] / k, np.inf)


def _limit(grid: np.ndarray, margin: np.ndarray) -> tuple[float, bool, str | None]:
    """The smallest |x| where the margin turns negative, on either side (interpolated between grid points);
    a lower bound (beyond_range) when a side stays inside up to the covered range's edge and that edge is
    nearer than the other side's crossing."""
    centre = int(np.argmin(np.abs(grid)))
    candidates = []
    for side, step in (("outward", 1), ("inward", -1)):
        indices = np.arange(centre, grid.size if step > 0 else -1, step)
        out = np.flatnonzero(margin[indices] < 0)
        if out.size == 0:
            candidates.append((abs(float(grid[indices[-1]])), True, side))
            continue
        k = indices[out[0]]
        if out[0] == 0:
            candidates.append((abs(float(grid[k])), False, side))
            continue
        before = indices[out[0] - 1]
        fraction = margin[before] / (margin[before] - margin[k])
        candidates.append((abs(float(grid[before] + fraction * (grid[k] - grid[before]))), False, side))
    return min(candidates)


def _bl_maximum(bl: np.ndarray, grid: np.ndarray) -> tuple[float, bool]:
    values = np.polynomial.polynomial.polyval(grid, bl)
    k = int(np.argmax(values))
    # Refine between the neighbours (a parabola through three points).
    if 0 < k < grid.size - 1:
        y0, y1, y2 = values[k - 1:k + 2]
        denominator = y0 - 2 * y1 + y2
        shift = 0.5 * (y0 - y2) / denominator if denominator else 0.0
        return float(grid[k] + shift * (grid[1] - grid[0])), False
    return float(grid[k]), True


def _asymmetry(kms: np.ndarray, x: float) -> float:
    plus, minus = np.polynomial.polynomial.polyval([x, -x], kms)
    return float(200.0 * (plus - minus) / (plus + minus))


def _draws(model: LargeSignalModel, n: int, seed: int):
    """(Bl, Kms, Le coefficients, rest shift) drawn from the covariance; the shift moves every curve alike."""
    rng = np.random.default_rng(seed)
    curves = [model.Bl, model.Kms, model.Le]
    if not all(np.all(np.isfinite(c.cov)) for c in curves):
        return []      # a fit that could not say its covariance: the limits' 1-sigma are unknown, not zero
    draws = [rng.multivariate_normal(c.coefficients, _psd(c.cov), size=n, method="eigh") for c in curves]
    shifts = rng.normal(0.0, model.Bl.x0_std, size=n) if model.Bl.x0_std > 0 else np.zeros(n)
    out = []
    for k in range(n):
        shifted = [_shifted(d[k], shifts[k]) for d in draws]
        out.append((*shifted, shifts[k]))
    return out


def _shifted(coefficients: np.ndarray, shift: float) -> np.ndarray:
    """The coefficients of f(x + shift)."""
    if shift == 0:
        return coefficients
    out = np.zeros(coefficients.size)
    composed = np.polynomial.Polynomial(coefficients)(np.polynomial.Polynomial([shift, 1.0])).coef
    out[:composed.size] = composed[:coefficients.size]
    return out


def _psd(cov: np.ndarray) -> np.ndarray:
    values, vectors = np.linalg.eigh((cov + cov.T) / 2.0)
    return (vectors * np.maximum(values, 0.0)) @ vectors.T


def _finite(value: float) -> float | None:
    return float(value) if np.isfinite(value) else None
