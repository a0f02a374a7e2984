"""`linpar stats`: repeatability: mean, std and percent of each parameter over repeated recordings."""
from __future__ import annotations

import argparse

from app.cli.options import (SERIAL_LASER_MODEL, CliError, add_json_option, add_model_option, add_sd_option,
                             model_effects)
from app.cli.output import print_json, say


def register(sub) -> None:
    stats = sub.add_parser("stats", help="repeatability: mean, std and percent over repeated recordings")
    stats.add_argument("paths", nargs="+", metavar="FILE", help="recordings (NAME, NAME.wav or NAME.json)")
    add_sd_option(stats)
    add_model_option(stats, why=SERIAL_LASER_MODEL)
    add_json_option(stats)
    stats.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from analysis.pipeline import analyze_path, require_fit
    from analysis.repeatability import format_spread, repeatability
    effects = model_effects(args.model)
    tables, left_out = [], []
    for path in args.paths:
        result = analyze_path(path, args.sd, effects)
        require_fit(result, "be one of the repeated results")
        why = _not_a_repeat(result.validity)
        if why is not None:       # its numbers are not to be trusted: averaged in, they hid as a wide spread
            left_out.append({"file": str(path), "why": why})
            say("stats", f"{path} left out: {why}; measure it again")
            continue
        tables.append(result.parameters)
    if not tables:
        raise CliError(f"none of the {len(args.paths)} recordings is valid (each is red: see above); measure again")
    spreads = repeatability(tables)
    if args.json:
        used = [str(p) for p in args.paths if str(p) not in {o["file"] for o in left_out}]
        print_json({"n_results": len(tables), "files": used, "left_out": left_out,
                    "parameters": {n: s.as_json() for n, s in spreads.items()}})
    else:
        print(format_spread(spreads, len(tables)))
        if left_out:
            print(f"left out (red): {len(left_out)} of {len(args.paths)}: "
                  + ", ".join(o["file"] for o in left_out))
    return 0


def _not_a_repeat(validity) -> str | None:
    """Why a result is no repeat of the others (its validity is red: a broken measurement), None when it is one."""
    if validity.overall != "red":
        return None
    codes = sorted({f.code for f in validity.findings if str(f.severity) == "red" and f.code})
    return "validity red" + (f" ({', '.join(codes)})" if codes else "")
