"""The large-signal curves as files: a CSV table across the measured range, and the JSON of `linpar large-signal`.

    x_m, Bl_Tm, Bl_std_Tm, Kms_N_per_m, Kms_std_N_per_m, Cms_m_per_N, Le_H, Le_std_H[, L2_H, L2_std_H]

One row per point, CSV_POINTS across the range the measurements covered (the
polynomials are not exported where they would extrapolate); comment lines
('#') above the header give the traceability header (analysis.session: driver,
serial, date, operator, station, template, software), the exporting software,
the polynomials (ascending powers of x in m), the rest offset and the limits. SI units, decimal point, numbers in
Python's shortest round-trip form.
"""
from __future__ import annotations

import json
from typing import TYPE_CHECKING

import numpy as np

from analysis.json_finite import dumps
from analysis.session import comment_lines

if TYPE_CHECKING:       # the registry looks through this module: it must not load the large-signal fit
    from analysis.large_signal.result import LargeSignalResult

CSV_POINTS = 101


def curves_csv(result: LargeSignalResult) -> str:
    from analysis.large_signal.curves import compliance_of
    model, derived = result.model, result.derived
    lo, hi = model.x_range
    x = np.linspace(lo, hi, CSV_POINTS)
    names = [n for n in ("Bl", "Kms", "Le", "L2") if n in model.curves]
    title = f"large-signal curves of {result.driver.get('name') or 'the driver'} (linpar)"
    comments = [f"x from {lo!r} to {hi!r} m, positive outwards; 1-sigma columns from the identification"]
    for name in names:
        curve = model.curves[name]
        comments.append(f"{name}(x) = sum c_k x^k [{curve.unit}], c = {json.dumps(curve.coefficients.tolist())}")
    comments.append(f"offset (Bl maximum) {derived.offset_m!r} m: {derived.coil_advice()}")
    for limit in derived.limits.values():
        bound = " (a lower bound: beyond the measured range)" if limit.beyond_range else ""
        comments.append(f"{limit.name} ({limit.criterion}) {limit.value!r} m{bound}")
    columns = {"x_m": x}
    units = {"Bl": "Tm", "Kms": "N_per_m", "Le": "H", "L2": "H"}
    for name in names:
        curve = model.curves[name]
        columns[f"{name}_{units[name]}"] = curve(x)
        columns[f"{name}_std_{units[name]}"] = curve.sigma(x)
        if name == "Kms":
            columns["Cms_m_per_N"] = compliance_of(curve, x)
    lines = comment_lines(title, result.header) + [f"# {c}" for c in comments] + [",".join(columns)]
    for row in zip(*columns.values()):
        lines.append(",".join(repr(float(v)) for v in row))
    return "\n".join(lines) + "\n"


def curves_json(result: LargeSignalResult) -> str:
    """The JSON of `linpar large-signal --json` (NaN and infinities as null)."""
    return dumps(result.as_json(), indent=1, ensure_ascii=True) + "\n"
