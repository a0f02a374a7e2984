"""A result's text report: what `AnalysisResult.report()` and `CurveAnalysis.report()` return, and what
`linpar analyze` (and measure, recover) prints for a fitted recording or imported curves."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from analysis.derived import ParameterValue


def format_value(p: ParameterValue) -> tuple[str, str]:
    if p.value is None:
        return "n/a", ""
    v = p.value * p.display_scale
    s = None if p.std is None else p.std * abs(p.display_scale)
    digits = 4
    if s and s > 0:
        digits = max(2, min(8, int(-math.floor(math.log10(s))) + 1))
        return f"{v:.{digits}f}" if abs(v) < 1e6 else f"{v:.6g}", f"{s:.2g}"
    return f"{v:.6g}", "-"


def _part(std: float | None, p: ParameterValue) -> str:
    return "-" if std is None else f"{std * abs(p.display_scale):.2g}"


def format_result(result) -> str:
    """The parameter table, the fit's summary, what is not reported and why, the validity, then the fit's report
    (FitResult.report: statistics, fitted parameters with sigma, correlations, parameters on a bound)."""
    # The uncertainty's two parts (noise, model), when the analysis estimated them; the 1-sigma is their total.
    parts = any(p.std_noise is not None or p.std_model is not None for p in result.parameters.values())
    lines = [f"{'parameter':<14}{'value':>14}  {'1-sigma':>10}  unit"
             + (f"{'noise':>10}  {'model':>10}" if parts else "")]
    missing: dict[str, list[str]] = {}      # reason -> the parameters it keeps out
    for p in result.parameters.values():
        value, std = format_value(p)
        row = f"{p.name:<14}{value:>14}  {std:>10}  {p.display_unit}"
        if parts and p.value is not None:
            row = f"{row:<46}" + "".join(f"{_part(x, p):>10}  " for x in (p.std_noise, p.std_model)).rstrip()
        lines.append(row)
        if p.value is None:
            missing.setdefault(str(p.reason), []).append(p.name)
    notes = [f"  {', '.join(names)}: {reason}" for reason, names in missing.items()]
    fit = result.fit
    if fit is None:
        lines += ["", f"not fitted: {getattr(result, 'not_fitted', None)}"]
        notes = []          # every parameter has that one reason
    else:
        chi = ", ".join(f"{k} {v:.3g}" for k, v in fit.chi2_red_by_channel().items())
        lines += ["", f"model: {fit.model.describe()} ({fit.method} fit)   reduced chi^2: {chi}   AIC {fit.aic:.1f}   "
                      f"BIC {fit.bic:.1f}   ({fit.n_data} data, {fit.n_varying} parameters)"]
        if result.validity.fit_error_percent:
            from analysis.fit.error import fit_error_text
            lines.append("fit error: " + fit_error_text(result.validity) + " (rms misfit of each curve in its fitted band)")
        from analysis.fit.model_uncertainty import model_part_words
        if model_part_words(result.validity):
            lines.append(model_part_words(result.validity))
        if not fit.success:
            lines.append(f"warning: the fit did not converge: {fit.message}")
        from analysis.fit.added_effects import stuck_effect_notes
        lines += [f"warning: {note}" for note in stuck_effect_notes(fit)]
        report = fit.report()
    if notes:
        lines += ["", "not reported:"] + notes
    lines.append(f"validity: {result.validity.overall}")
    for f in result.validity.findings:
        lines.append(f"  {f.severity}: {f.message}; {f.remedy}")
    if fit is not None:
        lines += ["", report]           # the fit's own report (analysis.fit.report): correlations, bounds
    return "\n".join(lines)


def format_curve_result(result) -> str:
    """An analysis.curves.fitting.CurveAnalysis said (not imported here: it imports this module): format_result's
    text, then the band each curve was fitted over, the fit errors, the exporting tool's own fit beside linpar's
    (when the result carries the tool's fitted curves: `references`) and the notes on the curves (how far to trust
    numbers no validity check has judged)."""
    ranges = ", ".join(f"{name} {lo:g}-{hi:g} Hz" for name, (lo, hi) in result.ranges.items())
    errors = ", ".join(f"{k} {v:.2g} %" for k, v in result.validity.fit_error_percent.items())
    imported = result.validity.imported
    lines = [format_result(result), f"fitted: {ranges}; fit error: {errors} (rms misfit of each curve)",
             f"note: {imported.note}; {imported.uncertainties}"]
    if result.references:
        from analysis.curves.reference import compare_with_reference, comparison_words
        beside = compare_with_reference(result.fit, result.references)
        lines += [comparison_words(name, c) for name, c in beside.items()]
    lines += [f"  {note}" for note in result.notes]
    return "\n".join(lines)
