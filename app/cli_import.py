"""`linpar` commands on other tools' curves: analyze --impedance/--hx/--uiv, addedmass, stats.

The analysis modules are imported inside the commands: building the parser
(`linpar --help`) stays light.
"""
from __future__ import annotations

import argparse

from analysis.bounds import ADDED_MASS_G, FREQUENCY, SD
from app.cli_options import number

CURVE_OPTIONS = ("impedance", "uiv")
# Options that mean something for imported curves only: with a recording they are refused, not ignored.
CURVE_ONLY = ("hx", "mm_per_volt", "hx_fmax", "phase", "fmin", "fmax", "all_lines")


def _add_range_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--phase", choices=("deg", "rad"),
                        help="phase unit of the files (default: what the file's header says, else degrees)")
    parser.add_argument("--fmin", type=number(FREQUENCY), metavar="HZ", help="fit only lines at or above HZ")
    parser.add_argument("--fmax", type=number(FREQUENCY), metavar="HZ", help="fit only lines at or below HZ")
    parser.add_argument("--all-lines", action="store_true",
                        help="keep every line of linearly spaced files (default: thinned to 100 lines per decade)")


def add_analyze_options(analyze: argparse.ArgumentParser) -> None:
    """Options of `linpar analyze` for imported curves (PATH then becomes optional)."""
    group = analyze.add_argument_group("imported curves (instead of a recording)")
    group.add_argument("--impedance", metavar="FILE", help="impedance curve: .zma, .frd, REW export or text table")
    group.add_argument("--hx", metavar="FILE", help="displacement transfer function X/U (m/V; see --mm-per-volt)")
    group.add_argument("--uiv", metavar="FILE", help="CSV of complex U, I and laser velocity (or displacement) spectra")
    group.add_argument("--mm-per-volt", action="store_true", help="the --hx magnitude is in mm/V")
    group.add_argument("--hx-fmax", type=number(FREQUENCY), metavar="HZ",
                       help="fit Hx only up to HZ (default: 4 x fs, where the cone is still a piston)")
    _add_range_options(group)


def add_commands(sub) -> None:
    """The `addedmass` and `stats` subcommands."""
    mass = sub.add_parser("addedmass", help="Bl and Mms from impedance curves with added masses")
    mass.add_argument("free", metavar="FREE", help="free-air impedance curve")
    mass.add_argument("--mass", nargs=2, action="append", metavar=("G", "FILE"), required=True,
                      help="an added mass in grams and its impedance curve (once or twice)")
    mass.add_argument("--sd", type=number(SD), metavar="M2", help="effective radiating area in m^2 (for Vas)")
    mass.add_argument("--model", metavar="EFFECTS",
                      help="effect ids (default leach,creep-log-causal: real coils need the semi-inductance)")
    mass.add_argument("--json", action="store_true", help="print one JSON object")
    _add_range_options(mass)

    stats = sub.add_parser("stats", help="repeatability: mean, std and percent over repeated recordings")
    stats.add_argument("paths", nargs="+", metavar="FILE", help="recordings (NAME, NAME.wav or NAME.json)")
    stats.add_argument("--sd", type=number(SD), metavar="M2")
    stats.add_argument("--model", metavar="EFFECTS", help="effect ids (default lr2,creep-log)")
    stats.add_argument("--json", action="store_true")


def wants_curves(args: argparse.Namespace) -> bool:
    """True when `linpar analyze` is about imported curves (or has nothing to analyse: said here)."""
    return (any(getattr(args, name, None) for name in CURVE_OPTIONS + CURVE_ONLY)
            or not getattr(args, "path", None))


def dispatch(args: argparse.Namespace) -> int:
    if args.command == "analyze":
        return cmd_analyze_curves(args)
    if args.command == "addedmass":
        return cmd_addedmass(args)
    if args.command == "stats":
        return cmd_stats(args)
    raise AssertionError(f"unknown command {args.command!r}")     # the parser allows no other


def fit_range(args, hx_f_max=None):
    from analysis.curve_fit import LINES_PER_DECADE, FitRange
    return FitRange(args.fmin, args.fmax, hx_f_max, None if args.all_lines else LINES_PER_DECADE)


def _effects(text: str | None, option: str = "--model"):
    from app.cli_commands import _effects as named_effects
    return named_effects(text, option)


def _print_json(doc: dict) -> None:
    from app.cli_json import dumps
    print(dumps(doc))


def load_curves(args: argparse.Namespace):
    """(Z, Hx or None, notes) from --impedance/--hx or --uiv, checked for conflicting options."""
    from app.cli import CliError
    from analysis.importers import read_curve, read_uiv
    if args.path and not (args.impedance or args.uiv or args.hx):
        used = [f"--{n.replace('_', '-')}" for n in CURVE_ONLY if getattr(args, n)]
        raise CliError(f"{', '.join(used)}: for imported curves only (--impedance/--uiv), not for a recording")
    if not (args.impedance or args.uiv or args.hx):
        raise CliError("analyze needs a recording path (NAME, NAME.wav or NAME.json) or curves: "
                       "--impedance FILE [--hx FILE] or --uiv FILE")
    if args.path:
        raise CliError("give either a recording PATH or imported curves (--impedance/--uiv), not both")
    if args.uiv and (args.impedance or args.hx):
        raise CliError("--uiv carries both Z and Hx: do not add --impedance or --hx")
    if args.hx and not args.impedance:
        raise CliError("--hx needs --impedance: Hx alone cannot be fitted")
    if args.uiv:
        uiv = read_uiv(args.uiv)
        z, hx, notes = uiv.impedance, uiv.displacement, [uiv.describe()]
    else:
        z_curve = read_curve(args.impedance, "impedance", args.phase)
        notes = [z_curve.describe()]
        z, hx = z_curve.transfer, None
        if args.hx:
            hx_curve = read_curve(args.hx, "displacement", args.phase, "mm/V" if args.mm_per_volt else None)
            hx = hx_curve.transfer
            notes.append(hx_curve.describe())
    return z, hx, notes


def cmd_analyze_curves(args: argparse.Namespace) -> int:
    from analysis.curve_fit import curve_json, fit_curves
    z, hx, notes = load_curves(args)
    result = fit_curves(z, hx, _effects(args.model), args.sd, fit_range(args, args.hx_fmax), notes)
    if args.json:
        _print_json(curve_json(result))
        return 0
    from app.cli_commands import format_result
    print(format_result(result))
    ranges = ", ".join(f"{name} {lo:g}-{hi:g} Hz" for name, (lo, hi) in result.ranges.items())
    rms = ", ".join(f"{k} {100 * v:.2g} %" for k, v in result.validity["rms_relative_residual"].items())
    print(f"fitted: {ranges}; rms relative misfit: {rms}")
    print(f"note: {result.validity['note']}; {result.validity['uncertainties']}")
    for note in result.notes:
        print(f"  {note}")
    return 0


def _mass_curves(args):
    from analysis.added_mass import MassCurve
    from analysis.importers import read_curve
    from app.cli import CliError
    free = read_curve(args.free, "impedance", args.phase)
    curves, notes = [MassCurve(free.transfer, 0.0)], [free.describe()]
    if len(args.mass) > 2:
        raise CliError("--mass: give one or two added masses")
    masses = [ADDED_MASS_G.parse(grams, f"--mass {grams} {path}") for grams, path in args.mass]
    if len(masses) == 2 and masses[0] == masses[1]:
        raise CliError(f"--mass: both added masses are {masses[0]:g} g: give two different masses (or one)")
    # Lightest first: the model-free dual-mass method takes them in that order, whatever the command line's.
    for grams, (_, path) in sorted(zip(masses, args.mass), key=lambda pair: pair[0]):
        curve = read_curve(path, "impedance", args.phase)
        curves.append(MassCurve(curve.transfer, grams * 1e-3))
        notes.append(curve.describe())
    return curves, notes


def cmd_addedmass(args: argparse.Namespace) -> int:
    from analysis import added_mass as am
    curves, notes = _mass_curves(args)
    effects = _effects(args.model or am.DEFAULT_EFFECTS)
    f_range = fit_range(args)
    primary = am.joint_added_mass(curves, effects, args.sd, f_range)
    checks = []
    loaded = [c for c in curves if c.added_mass_kg > 0]
    if len(loaded) == 2 and all(c.impedance.has_phase for c in curves):
        checks.append(am.model_free_dual_mass(curves[0].impedance, loaded[0].impedance, loaded[0].added_mass_kg,
                                              loaded[1].impedance, loaded[1].added_mass_kg, args.sd))
    for c in loaded:
        checks.append(am.single_added_mass(curves[0].impedance, c.impedance, c.added_mass_kg, effects, args.sd,
                                           f_range))
    if args.json:
        doc = am.added_mass_json(primary)
        doc["validity"] = {"overall": "unknown", "note": "imported curves: no per-line noise, no validity checks",
                           "import": notes}
        doc["cross_checks"] = [am.added_mass_json(r) for r in checks]
        _print_json(doc)
        return 0
    for result in [primary, *checks]:
        print(_format_added_mass(result))
        print()
    for note in notes:
        print(f"  {note}")
    return 0


def _format_added_mass(result) -> str:
    from analysis.added_mass import REPORTED
    from app.cli_commands import format_value
    lines = [f"{result.method}", f"{'parameter':<10}{'value':>14}  {'1-sigma':>10}  unit"]
    for name in REPORTED:
        p = result.parameters.get(name)
        if p is None or p.value is None:
            continue
        value, std = format_value(p)
        lines.append(f"{name:<10}{value:>14}  {std:>10}  {p.display_unit}")
    if result.fit is not None:
        chi = ", ".join(f"{k} {v:.3g}" for k, v in result.fit.chi2_red_by_channel().items())
        lines.append(f"model: {result.fit.model.describe()}   reduced chi^2: {chi}")
    lines += [f"  {n}" for n in result.notes]
    return "\n".join(lines)


def cmd_stats(args: argparse.Namespace) -> int:
    from analysis.pipeline import analyze_path, require_fit
    from analysis.repeatability import format_spread, repeatability
    effects = _effects(args.model) if args.model else None
    tables = []
    for path in args.paths:
        result = analyze_path(path, args.sd, effects)
        require_fit(result, "be one of the repeated results")
        tables.append(result.parameters)
    spreads = repeatability(tables)
    if args.json:
        _print_json({"n_results": len(tables), "files": list(args.paths),
                     "parameters": {n: s.as_json() for n, s in spreads.items()}})
    else:
        print(format_spread(spreads, len(tables)))
    return 0
