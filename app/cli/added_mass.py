"""`linpar addedmass`: Bl and Mms from impedance curves with added masses (the joint fit and its cross-checks)."""
from __future__ import annotations

import argparse

from analysis.bounds import ADDED_MASS_G
from analysis.model.defaults import ADDED_MASS_EFFECTS
from app.cli.curves import add_range_options, fit_range
from app.cli.options import CliError, add_json_option, add_model_option, add_sd_option, model_effects
from app.cli.output import print_json


def register(sub) -> None:
    mass = sub.add_parser("addedmass", help="Bl and Mms from impedance curves with added masses")
    mass.add_argument("free", metavar="FREE", help="free-air impedance curve")
    mass.add_argument("--mass", nargs=2, action="append", metavar=("G", "FILE"), required=True,
                      help="an added mass in grams and its impedance curve (once or twice)")
    add_sd_option(mass, " (for Vas)")
    add_model_option(mass, ADDED_MASS_EFFECTS, ": real coils need the semi-inductance")
    add_json_option(mass)
    add_range_options(mass)
    mass.set_defaults(run=run)


def _mass_curves(args):
    from analysis.added_mass import MassCurve
    from analysis.importers import read_curve
    free = read_curve(args.free, "impedance", args.phase)
    curves, notes = [MassCurve(impedance=free.transfer, added_mass_kg=0.0)], [free.describe()]
    if len(args.mass) > 2:
        raise CliError("--mass: give one or two added masses")
    masses = [ADDED_MASS_G.parse(grams, f"--mass {grams} {path}") for grams, path in args.mass]
    if len(masses) == 2 and masses[0] == masses[1]:
        raise CliError(f"--mass: both added masses are {masses[0]:g} g: give two different masses (or one)")
    # Lightest first: the model-free dual-mass method takes them in that order, whatever the command line's.
    for grams, (_, path) in sorted(zip(masses, args.mass), key=lambda pair: pair[0]):
        curve = read_curve(path, "impedance", args.phase)
        curves.append(MassCurve(impedance=curve.transfer, added_mass_kg=grams * 1e-3))
        notes.append(curve.describe())
    return curves, notes


def run(args: argparse.Namespace) -> int:
    from analysis import added_mass as am
    curves, notes = _mass_curves(args)
    effects = model_effects(am.DEFAULT_EFFECTS if args.model is None else args.model)
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
    from analysis.added_mass_agreement import disagreements
    apart = disagreements(primary, checks)
    if args.json:
        print_json({**am.added_mass_document(primary, checks, notes), "disagreements": apart})
        return 0
    for result in [primary, *checks]:
        print(result.report())
        print()
    if apart:
        print("The methods disagree:")
        print("\n".join(f"  {line}" for line in apart))
        print()
    for note in notes:
        print(f"  {note}")
    return 0

