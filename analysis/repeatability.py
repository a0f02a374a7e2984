"""Repeatability: the spread of each parameter over repeated measurements (the paper's Table I).

Input: any number of parameter tables (name -> ParameterValue), from
recordings analysed (AnalysisResult.parameters) or imported curve sets
(CurveAnalysis.parameters). Output per parameter: how many results gave it,
the mean, the sample standard deviation (ddof = 1: the spread one repeat
would show) and that standard deviation in percent of the mean.

The spread over repeats is the honest uncertainty of a single measurement
(remounting, temperature, suspension history); each fit's own standard error
only says how well one recording pins the parameter down.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from analysis.derived import ParameterValue


@dataclass(frozen=True, slots=True)
class Spread:
    name: str
    n: int                      # results that gave a value
    mean: float | None
    std: float | None           # sample standard deviation; None below two values
    percent: float | None       # std / |mean| * 100
    unit: str                   # SI
    display_unit: str
    display_scale: float
    mean_fit_std: float | None = None   # the typical fit standard error, to set beside the spread

    def as_json(self) -> dict:
        return {"n": self.n, "mean": self.mean, "std": self.std, "percent": self.percent, "unit": self.unit,
                "mean_fit_std": self.mean_fit_std}


def repeatability(tables: Sequence[Mapping[str, ParameterValue]]) -> dict[str, Spread]:
    """Mean, standard deviation and percent of every parameter over `tables`, in first-seen order."""
    names: list[str] = []
    for table in tables:
        names += [n for n in table if n not in names]
    out: dict[str, Spread] = {}
    for name in names:
        present = [t[name] for t in tables if name in t]
        ref = present[0]
        values = np.array([p.value for p in present if p.value is not None], dtype=float)
        fit_stds = [p.std for p in present if p.value is not None and p.std is not None]
        n = len(values)
        mean = float(values.mean()) if n else None
        std = float(values.std(ddof=1)) if n >= 2 else None
        percent = 100.0 * std / abs(mean) if std is not None and mean else None
        out[name] = Spread(name, n, mean, std, percent, ref.unit, ref.display_unit, ref.display_scale,
                           float(np.mean(fit_stds)) if fit_stds else None)
    return out


def format_spread(spreads: Mapping[str, Spread], n_results: int) -> str:
    """A text table in customary units, as the paper's Table I."""
    lines = [f"{n_results} results", f"{'parameter':<14}{'mean':>14}{'std':>12}{'std %':>9}  unit"]
    for s in spreads.values():
        if s.mean is None:
            lines.append(f"{s.name:<14}{'n/a':>14}{'':>12}{'':>9}  {s.display_unit}")
            continue
        mean = f"{s.mean * s.display_scale:.6g}"
        std = "-" if s.std is None else f"{s.std * abs(s.display_scale):.2g}"
        pct = "-" if s.percent is None else f"{s.percent:.2f}"
        lines.append(f"{s.name:<14}{mean:>14}{std:>12}{pct:>9}  {s.display_unit}")
    return "\n".join(lines)
