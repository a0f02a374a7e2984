"""A fit's report, on the model of lmfit's fit_report: statistics, parameters with sigma, correlations, bounds.

    [[Fit statistics]]
        model              = lr2 + creep-log, with Hx
        converged          = yes (function evaluations: 412)
        data points        = 1964
        variables          = 10
        chi-square         = 1961.7
        reduced chi-square = 1.004 (impedance 1.01, displacement 0.998)
        Akaike info crit   = 1981.7
        Bayesian info crit = 2037.5
    [[Parameters]]
        RE   = 3.02000 +/- 7.0e-06 ohm (0.00023 %)
        ...
    [[Correlations]] (unreported correlations are below 0.5 in absolute value)
        C(LE, L2) = -0.934
    [[Notes]]
        Q_c = 0.1 ended on its lower bound: the data push it further than the effect allows

FitResult.report() returns the text; the CLI prints it, the Model lab shows it, and the stored results keep
`report_json` so that a report of an archived measurement says the same (analysis.report.content).

Correlations: lmfit shows |r| >= 0.1. A loudspeaker's lumped parameters all share the resonance, so at 0.1
nearly every pair is listed; MIN_CORREL = 0.5 keeps the pairs that trade against each other, the ones a
reader must know about before trusting either value alone.

Nothing here imports analysis.fit.least_squares (which calls this module): the fit is read by its attributes.
"""
from __future__ import annotations

import math
from typing import Any

MIN_CORREL = 0.5


def fit_report_json(fit, min_correl: float = MIN_CORREL) -> dict[str, Any]:
    """The report's content, in SI: what `fit_report_text` prints and what a stored result keeps."""
    specs = {spec.name: spec for spec in fit.model.param_specs}
    parameters = []
    for name, spec in specs.items():
        value, sigma = fit.values.get(name), fit.stderr.get(name)
        parameters.append({"name": name, "value": value, "std": sigma, "unit": spec.unit,
                           "display_unit": spec.display_unit, "display_scale": spec.display_scale,
                           "varied": name in fit.varying})
    return {"statistics": {"model": fit.model.describe(), "converged": bool(fit.success), "message": fit.message,
                           "function_evaluations": fit.nfev, "data_points": fit.n_data, "variables": fit.n_varying,
                           "chi2": fit.chi2, "chi2_red": fit.chi2_red, "chi2_red_by_channel": fit.chi2_red_by_channel(),
                           "aic": fit.aic, "bic": fit.bic},
            "parameters": parameters,
            "min_correl": min_correl,
            "correlations": _correlations(fit, min_correl),
            "notes": _bound_notes(fit, specs)}


def _correlations(fit, min_correl: float) -> list[dict[str, Any]]:
    """Pairs of varied parameters with |r| >= min_correl, strongest first (lmfit's order)."""
    r = fit.correlation()
    if r is None:
        return []
    pairs = []
    for i, a in enumerate(fit.varying):
        for j in range(i + 1, len(fit.varying)):
            value = float(r[i, j])
            if math.isfinite(value) and abs(value) >= min_correl:
                pairs.append({"a": a, "b": fit.varying[j], "r": value})
    return sorted(pairs, key=lambda p: -abs(p["r"]))


def _bound_notes(fit, specs) -> list[str]:
    notes = []
    for name, spec in specs.items():
        value = fit.values.get(name)
        if value is None or not spec.on_bound(value):
            continue
        side = "lower" if value - spec.min <= spec.max - value else "upper"
        notes.append(f"{name} = {_number(value * spec.display_scale)}{_unit(spec.display_unit)} ended on its {side} "
                     f"bound: the data push it further than the model allows (held there; no sigma)")
    if fit.covar is None and fit.varying:
        notes.append("no covariance: the uncertainties and correlations could not be estimated")
    return notes


def fit_report_text(doc: dict[str, Any]) -> str:
    """The report as lmfit prints one, from `fit_report_json` (a stored result's copy prints the same)."""
    s = doc["statistics"]
    chi = ", ".join(f"{k} {_number(v, 4)}" for k, v in s["chi2_red_by_channel"].items())
    converged = "yes" if s["converged"] else f"NO: {s['message']}"
    lines = ["[[Fit statistics]]",
             f"    model              = {s['model']}",
             f"    converged          = {converged} (function evaluations: {s['function_evaluations']})",
             f"    data points        = {s['data_points']}",
             f"    variables          = {s['variables']}",
             f"    chi-square         = {_number(s['chi2'], 6)}",
             f"    reduced chi-square = {_number(s['chi2_red'], 4)} ({chi})",
             f"    Akaike info crit   = {_number(s['aic'], 6)}",
             f"    Bayesian info crit = {_number(s['bic'], 6)}",
             "[[Parameters]]"]
    width = max((len(p["name"]) for p in doc["parameters"]), default=0)
    for p in doc["parameters"]:
        lines.append(f"    {p['name']:<{width}} = {_parameter(p)}")
    lines.append(f"[[Correlations]] (unreported correlations are below {doc['min_correl']:g} in absolute value)")
    if not doc["correlations"]:
        lines.append("    none")
    for c in doc["correlations"]:
        lines.append(f"    C({c['a']}, {c['b']}) = {c['r']:+.3f}")
    if doc["notes"]:
        lines.append("[[Notes]]")
        lines += [f"    {note}" for note in doc["notes"]]
    return "\n".join(lines)


def fit_report_rows(doc: dict[str, Any]) -> list[tuple[str, str]]:
    """What a printed report adds to its model's rows: the strong correlations and the parameters on a bound."""
    pairs = ", ".join(f"{c['a']}–{c['b']} {c['r']:+.2f}" for c in doc["correlations"]) or "none"
    rows = [(f"Correlations (|r| ≥ {doc['min_correl']:g})", pairs)]
    rows += [("Note", note) for note in doc["notes"]]
    return rows


def _parameter(p: dict[str, Any]) -> str:
    value, sigma, scale = p["value"], p["std"], p["display_scale"]
    if value is None or not math.isfinite(value):
        return "n/a"
    unit = _unit(p["display_unit"])
    if not p["varied"]:
        return f"{_number(value * scale)}{unit} (held)"
    if sigma is None or not math.isfinite(sigma):
        return f"{_number(value * scale)}{unit} +/- n/a"
    relative = f" ({100 * sigma / abs(value):.2g} %)" if value else ""
    return f"{_number(value * scale)} +/- {sigma * abs(scale):.2g}{unit}{relative}"


def _unit(unit: str) -> str:
    return "" if unit in ("-", "1", "") else f" {unit}"


def _number(x: float | None, digits: int = 6) -> str:
    return "n/a" if x is None or not math.isfinite(x) else f"{x:.{digits}g}"
