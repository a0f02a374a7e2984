"""`linpar diagnose`: rank the effects the model may lack, follow the greedy path, say what is missing and where.

The analysis is imported when the command runs: building the parser (`linpar --help`) stays light.
"""
from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from app.cli import curves, effects
from app.cli.options import add_json_option, add_sd_option, model_effects
from app.cli.output import print_json

if TYPE_CHECKING:
    from analysis.diagnosis.result import DiagnosisResult


def register(sub) -> None:
    diagnose = sub.add_parser("diagnose", help="find which physical effect the model lacks")
    diagnose.add_argument("path", nargs="?", help="recording: NAME, NAME.wav or NAME.json (or --impedance/--uiv)")
    diagnose.add_argument("--from", dest="start", metavar="EFFECTS", default="none",
                          help="the starting model's effect ids (default: the textbook model)")
    add_sd_option(diagnose)
    add_json_option(diagnose)
    curves.add_curve_options(diagnose)
    effects.add_effects_file_option(diagnose)
    diagnose.set_defaults(run=run)


def run_diagnosis(args: argparse.Namespace) -> DiagnosisResult:
    """The diagnosis of the recording (or curves) the command names, with its Sd and drift finding."""
    from analysis.api import diagnose
    start = model_effects(args.start, "--from")     # a bad --from fails before the data are read
    source = args.path
    if curves.wants_curves(args):
        source = curves.load_curves(args)
    return diagnose(source, start=start, sd_m2=args.sd)


def run(args: argparse.Namespace) -> int:
    result = run_diagnosis(args)
    if args.json:
        print_json(result.as_json())
    else:
        print(result.report())
    return 0
