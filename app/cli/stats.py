"""`linpar stats`: repeatability: mean, std and percent of each parameter over repeated recordings."""
from __future__ import annotations

import argparse

from app.cli.options import add_json_option, add_model_option, add_sd_option, model_effects
from app.cli.output import print_json


def register(sub) -> None:
    stats = sub.add_parser("stats", help="repeatability: mean, std and percent over repeated recordings")
    stats.add_argument("paths", nargs="+", metavar="FILE", help="recordings (NAME, NAME.wav or NAME.json)")
    add_sd_option(stats)
    add_model_option(stats)
    add_json_option(stats)
    stats.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from analysis.pipeline import analyze_path, require_fit
    from analysis.repeatability import format_spread, repeatability
    effects = model_effects(args.model) if args.model else None
    tables = []
    for path in args.paths:
        result = analyze_path(path, args.sd, effects)
        require_fit(result, "be one of the repeated results")
        tables.append(result.parameters)
    spreads = repeatability(tables)
    if args.json:
        print_json({"n_results": len(tables), "files": list(args.paths),
                    "parameters": {n: s.as_json() for n, s in spreads.items()}})
    else:
        print(format_spread(spreads, len(tables)))
    return 0
