"""`linpar levels`: the parameters against peak excursion over recordings at rising levels (Table II).

    linpar levels FILE... [--sd M2] [--model EFFECTS] [--json]
    linpar levels --simulate [--levels V1,V2,...] [--out DIR] [--json]

--simulate measures the series on the simulated nonlinear driver (the paper's
driver, softening with excursion): with --out the recordings are written
there and analysed from the files, as recordings from a rig would be; without
it they are analysed in memory and not kept. The text output is the table;
the JSON also holds the data of the fs-against-excursion plot (Fig. 14).

The analysis and the simulator are imported inside the commands: building the
parser (`linpar --help`) stays light.
"""
from __future__ import annotations

import argparse
import sys

from app.cli.options import (SERIAL_LASER_MODEL, CliError, add_json_option, add_model_option, add_sd_option,
                             model_effects)
from app.cli.output import print_json


def _levels(text: str) -> tuple[float, ...]:
    from analysis.bounds import LEVEL_V_RMS, BoundsError
    try:
        levels = tuple(LEVEL_V_RMS.parse(part, "") for part in text.split(",") if part.strip())
    except BoundsError as exc:
        raise argparse.ArgumentTypeError(f"{exc} (volts RMS separated by commas: 0.3,1,3)") from None
    if not levels:
        raise argparse.ArgumentTypeError(f"expected volts RMS separated by commas (0.3,1,3), got {text!r}")
    return levels


def register(sub) -> None:
    levels = sub.add_parser("levels", help="level series: the parameters against peak excursion (Table II)")
    levels.add_argument("paths", nargs="*", metavar="FILE",
                        help="recordings at rising levels (NAME, NAME.wav or NAME.json)")
    levels.add_argument("--simulate", action="store_true",
                        help="measure the series on the simulated nonlinear driver instead of FILEs")
    levels.add_argument("--levels", type=_levels, metavar="V1,V2,...",
                        help="with --simulate: drive levels in V RMS (default 0.3,1,3,6,10,14: ~0.15-8.5 mm)")
    levels.add_argument("--out", metavar="DIR", help="with --simulate: write the recordings to DIR (kept)")
    add_sd_option(levels)
    add_model_option(levels, why=SERIAL_LASER_MODEL)
    add_json_option(levels, "print one JSON object (with the Fig. 14 data)")
    levels.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from analysis.level_series import format_series, level_series
    if args.simulate and args.paths:
        raise CliError("give either recordings (FILE...) or --simulate, not both")
    if not args.simulate:
        if not args.paths:
            raise CliError("levels needs recordings at rising levels (FILE...) or --simulate")
        used = [name for name, value in (("--levels", args.levels), ("--out", args.out)) if value]
        if used:
            raise CliError(f"{', '.join(used)}: only with --simulate")
    effects = model_effects(args.model)         # a bad --model fails before the simulation
    items = _simulate(args) if args.simulate else list(args.paths)
    series = level_series(items, args.sd, effects)
    if args.json:
        print_json(series.as_json())
    else:
        print(format_series(series))
    return 0


def _simulate(args: argparse.Namespace) -> list:
    """The simulated series at args.levels: .wav paths with --out, else Recordings in memory."""
    from instruments.simulation import level_series as sim
    levels = args.levels or sim.DEFAULT_LEVELS_V
    try:
        sim.check_levels(levels)
    except sim.LevelsError as exc:
        raise CliError(f"--levels: {exc}") from None

    def progress(i, n, level):      # on stderr: stdout is the table or the JSON
        print(f"simulating level {i + 1}/{n}: {level:g} V RMS", file=sys.stderr, flush=True)
    if args.out:
        return sim.write_level_series(args.out, levels, progress=progress)
    recordings = []
    for i, level in enumerate(levels):
        progress(i, len(levels), level)
        recordings.append(sim.simulate_level(level, index=i))
    return recordings
