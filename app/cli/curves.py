"""Other tools' curves on the command line: `linpar analyze --impedance/--hx/--uiv` (and diagnose's).

The analysis modules are imported inside the commands: building the parser
(`linpar --help`) stays light.
"""
from __future__ import annotations

import argparse
import dataclasses

from analysis.bounds import FREQUENCY
from app.cli.options import CliError, model_effects, number
from app.cli.output import print_json

CURVE_OPTIONS = ("impedance", "uiv")
# Options that mean something for imported curves only: with a recording they are refused, not ignored.
CURVE_ONLY = ("hx", "mm_per_volt", "hx_fmax", "phase", "fmin", "fmax", "all_lines")


def add_range_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--phase", choices=("deg", "rad"),
                        help="phase unit of the files (default: what the file's header says, else degrees)")
    parser.add_argument("--fmin", type=number(FREQUENCY), metavar="HZ", help="fit only lines at or above HZ")
    parser.add_argument("--fmax", type=number(FREQUENCY), metavar="HZ", help="fit only lines at or below HZ")
    parser.add_argument("--all-lines", action="store_true",
                        help="keep every line of linearly spaced files (default: thinned to 100 lines per decade)")


def add_curve_options(analyze: argparse.ArgumentParser) -> None:
    """Options of `linpar analyze` (and diagnose) for imported curves (PATH then becomes optional)."""
    group = analyze.add_argument_group("imported curves (instead of a recording)")
    group.add_argument("--impedance", metavar="FILE", help="impedance curve: .zma, .frd, REW export or text table")
    group.add_argument("--hx", metavar="FILE", help="displacement transfer function X/U (m/V; see --mm-per-volt)")
    group.add_argument("--uiv", metavar="FILE", help="CSV of complex U, I and laser velocity (or displacement) spectra")
    group.add_argument("--mm-per-volt", action="store_true", help="the --hx magnitude is in mm/V")
    group.add_argument("--hx-fmax", type=number(FREQUENCY), metavar="HZ",
                       help="fit Hx only up to HZ (default: 4 x fs, where the cone is still a piston)")
    add_range_options(group)


def wants_curves(args: argparse.Namespace) -> bool:
    """True when `linpar analyze` is about imported curves (or has nothing to analyse: said here)."""
    return (any(getattr(args, name, None) for name in CURVE_OPTIONS + CURVE_ONLY)
            or not getattr(args, "path", None))


def fit_range(args, hx_f_max=None):
    """The range options of `linpar added-mass` (its curves are read by their own command)."""
    from analysis.curves.fitting import LINES_PER_DECADE, FitRange
    return FitRange(f_min=args.fmin, f_max=args.fmax, hx_f_max=hx_f_max,
                    per_decade=None if args.all_lines else LINES_PER_DECADE)


def load_curves(args: argparse.Namespace):
    """The curves --impedance/--hx or --uiv name, read by analysis.curves.imported.import_curves (as the library
    and the GUI read them) with the range options, after the options' conflicts are said in their own words."""
    from analysis.curves.imported import import_curves
    if args.path and not (args.impedance or args.uiv or args.hx):
        used = [f"--{n.replace('_', '-')}" for n in CURVE_ONLY if getattr(args, n)]
        raise CliError(f"{', '.join(used)}: for imported curves only (--impedance/--uiv), not for a recording")
    if not (args.impedance or args.uiv or args.hx):
        raise CliError(f"{args.command} needs a recording path (NAME, NAME.wav or NAME.json) or curves: "
                       "--impedance FILE [--hx FILE] or --uiv FILE")
    if args.path:
        raise CliError("give either a recording PATH or imported curves (--impedance/--uiv), not both")
    if args.uiv and (args.impedance or args.hx):
        raise CliError("--uiv carries both Z and Hx: do not add --impedance or --hx")
    if args.hx and not args.impedance:
        raise CliError("--hx needs --impedance: Hx alone cannot be fitted")
    return import_curves(args.impedance, hx=args.hx, uiv=args.uiv, phase=args.phase,
                         hx_mm_per_volt=args.mm_per_volt, f_min=args.fmin, f_max=args.fmax,
                         hx_f_max=args.hx_fmax, all_lines=args.all_lines)


def analyze_curves(args: argparse.Namespace) -> int:
    from analysis.curves.fitting import curve_json, fit_curves
    from analysis.curves.reference import compare_with_reference
    from analysis.fit.model_uncertainty import model_uncertainty
    curves = load_curves(args)
    # No --model, no --method: fit_curves chooses (magnitude-only curves have their own defaults).
    effects = model_effects(args.model)
    fitted = fit_curves(curves.impedance, curves.displacement, effects, args.sd, curves.fit_range, curves.notes,
                        method=getattr(args, "method", None))
    result = model_uncertainty(fitted)        # the model part of each uncertainty (analysis.fit.model_uncertainty)
    # The files and the exporting tool's own fits go with the result, as the GUI's (app.jobs.curves): its report
    # then says the tool's fit beside linpar's.
    result = dataclasses.replace(result, files=curves.files, references=curves.references)
    if args.json:
        doc = curve_json(result)
        beside = compare_with_reference(result.fit, curves.references)
        if beside:
            doc["reference_fit"] = beside
        print_json(doc)
        return 0
    print(result.report())
    return 0
