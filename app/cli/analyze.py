"""`linpar analyze`: fit the parameters of a recording (or, with --impedance/--uiv, of imported curves)."""
from __future__ import annotations

import argparse

from app.cli import curves, effects
from app.cli.options import (SERIAL_LASER_MODEL, add_json_option, add_method_option, add_model_option, add_sd_option,
                             model_effects)
from app.cli.output import print_json

EXIT_QA_FAIL = 1


def register(sub) -> None:
    analyze = sub.add_parser("analyze", help="fit the parameters of a recording")
    analyze.add_argument("path", nargs="?", help="recording: NAME, NAME.wav or NAME.json (or --impedance/--uiv)")
    add_sd_option(analyze)
    add_model_option(analyze, why=SERIAL_LASER_MODEL)
    add_method_option(analyze)
    add_json_option(analyze)
    analyze.add_argument("--limits", metavar="FILE",
                         help="QA limits (JSON): print pass/fail; exit 0 pass, 1 fail, 2 error")
    curves.add_curve_options(analyze)
    effects.add_effects_file_option(analyze)
    analyze.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    if curves.wants_curves(args):
        if args.limits:
            from analysis.limits import LimitsError
            raise LimitsError("--limits applies to recordings, not to imported curves")
        return curves.analyze_curves(args)
    return analyze_recording(args)


def analyze_recording(args: argparse.Namespace) -> int:
    from analysis.api import analyze
    if args.limits:
        from analysis import limits as qa
    limits = qa.load_limits(args.limits) if args.limits else None    # a bad limits file fails before the analysis
    # With the model part of each uncertainty (refits when the model misses the data by more than its noise).
    result = analyze(args.path, sd_m2=args.sd, effects=model_effects(args.model), method=args.method or "joint")
    doc = result.as_json()
    if limits is not None:
        doc["limits"] = qa.judge_result(limits, result.parameters, result.validity)
    if args.json:
        print_json(doc)
    else:
        print(result.report())
        if limits is not None:
            print("\n" + qa.format_verdicts(limits, result.parameters, result.validity))
    if limits is None:
        return 0
    # 0 pass, 1 fail, 2 when the unit was not judged: invalid or uncertain (measure again), or not judged (the
    # model misses the measurement by more than the fit-error tolerance: find the model).
    return {"pass": 0, "fail": EXIT_QA_FAIL}.get(doc["limits"]["verdict"], 2)
