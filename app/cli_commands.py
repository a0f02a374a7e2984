"""What each `linpar` subcommand does (no Qt here)."""
from __future__ import annotations

import argparse
import json
import sys

from analysis.derived import ParameterValue
from analysis.effects import UnknownEffectError, parse_effects
from analysis.limits import LimitsError
from analysis.model import ModelError
from analysis.pipeline import AnalysisResult, analyze_path, result_json
from app.cli_effects import cmd_effects
from app.cli_json import dumps

EXIT_QA_FAIL = 1


def dispatch(args: argparse.Namespace) -> int:
    from app import cli_import
    if args.command in ("addedmass", "stats") or (args.command == "analyze" and cli_import.wants_curves(args)):
        if getattr(args, "limits", None):
            raise LimitsError("--limits applies to recordings, not to imported curves")
        return cli_import.dispatch(args)
    if args.command == "analyze":
        return cmd_analyze(args)
    if args.command == "diagnose":
        from app.cli_diagnose import cmd_diagnose
        return cmd_diagnose(args)
    if args.command == "effects":
        return cmd_effects(args)
    raise AssertionError(f"unknown command {args.command!r}")     # the parser allows no other


def _effects(text: str | None, option: str = "--model"):
    """The effects an option names; ModelError that names the option."""
    try:
        return parse_effects(text)
    except UnknownEffectError as exc:
        raise ModelError(f"{option}: {exc}") from None


def cmd_analyze(args: argparse.Namespace) -> int:
    from analysis import limits as qa
    path = getattr(args, "limits", None)
    limits = qa.load_limits(path) if path else None    # a bad limits file fails before the analysis
    result = analyze_path(args.path, args.sd, _effects(args.model))
    doc = result_json(result)
    if limits is not None:
        doc["limits"] = qa.judge_result(limits, result.parameters, result.validity)
    if args.json:
        print(dumps(doc))
    else:
        print(format_result(result))
        if limits is not None:
            print("\n" + qa.format_verdicts(limits, result.parameters, result.validity))
    if limits is None:
        return 0
    # 0 pass, 1 fail, 2 (an error: the measurement must be repeated, or its model found) when not judged.
    return {"pass": 0, "fail": EXIT_QA_FAIL}.get(doc["limits"]["verdict"], 2)


def format_value(p: ParameterValue) -> tuple[str, str]:
    if p.value is None:
        return "n/a", ""
    v = p.value * p.display_scale
    s = None if p.std is None else p.std * abs(p.display_scale)
    digits = 4
    if s and s > 0:
        import math
        digits = max(2, min(8, int(-math.floor(math.log10(s))) + 1))
        return f"{v:.{digits}f}" if abs(v) < 1e6 else f"{v:.6g}", f"{s:.2g}"
    return f"{v:.6g}", "-"


def format_result(result: AnalysisResult) -> str:
    lines = [f"{'parameter':<14}{'value':>14}  {'1-sigma':>10}  unit"]
    missing: dict[str, list[str]] = {}      # reason -> the parameters it keeps out
    for p in result.parameters.values():
        value, std = format_value(p)
        lines.append(f"{p.name:<14}{value:>14}  {std:>10}  {p.display_unit}")
        if p.value is None:
            missing.setdefault(str(p.reason), []).append(p.name)
    notes = [f"  {', '.join(names)}: {reason}" for reason, names in missing.items()]
    fit = result.fit
    if fit is None:
        lines += ["", f"not fitted: {getattr(result, 'not_fitted', None)}"]
        notes = []          # every parameter has that one reason
    else:
        chi = ", ".join(f"{k} {v:.3g}" for k, v in fit.chi2_red_by_channel().items())
        lines += ["", f"model: {fit.model.describe()}   reduced chi^2: {chi}   AIC {fit.aic:.1f}   "
                      f"BIC {fit.bic:.1f}   ({fit.n_data} data, {fit.n_varying} parameters)"]
        if not fit.success:
            lines.append(f"warning: the fit did not converge: {fit.message}")
    if notes:
        lines += ["", "not reported:"] + notes
    lines.append(f"validity: {result.validity.get('overall', 'unknown')}")
    for channel in (result.validity.get("channels") or {}).values():
        for f in channel.get("findings") or ():
            lines.append(f"  {f['severity']}: {f['message']}; {f['remedy']}")
    return "\n".join(lines)
