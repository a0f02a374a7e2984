"""Effects of the user's own on the command line: --effects-file, the user folder, `linpar effects`.

Every command that fits a model reads the user folder ($LINPAR_EFFECTS, else effects/ in the
platform's configuration folder), the packages' `linpar.effects` entry points, and the files given
with --effects-file, before it does anything else: a bad file stops it at once with one line.
"""
from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from analysis.config_folder import EFFECTS_FOLDER_ENV, config_folder
from app.cli.options import add_json_option
from app.cli.output import print_json

if TYPE_CHECKING:       # the catalogue (and scipy) is loaded by the commands that use it, not by every start
    from analysis.effects import Effect

# The commands that build models from effect ids (and so may name effects of the user's own).
COMMANDS = ("analyze", "diagnose", "effects", "report", "export", "archive", "addedmass", "stats", "levels")


def register(sub) -> None:
    effects = sub.add_parser("effects", help="list the effects catalogue and your own effects")
    add_json_option(effects, None)
    add_effects_file_option(effects)
    effects.set_defaults(run=run)


def add_effects_file_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--effects-file", dest="effects_files", action="append", default=[], metavar="FILE",
                        help="an effect of your own (TOML; repeatable), beside the catalogue and the user folder "
                             f"(${EFFECTS_FOLDER_ENV} or {config_folder() / 'effects'})")


def load(args: argparse.Namespace) -> tuple[Effect, ...]:
    """Read and register the user's effects (registry.EffectFileError, one line, when one is bad)."""
    from analysis.effects import registry
    effects = registry.load_user_effects(getattr(args, "effects_files", None) or ())
    registry.register(effects)
    return effects


def _parameters_text(effect: Effect) -> str:
    return ", ".join(f"{p.name} [{p.display_unit}" + (f", typically {p.typical_text()}]" if p.typical else "]")
                     for p in effect.params)


def run(args: argparse.Namespace) -> int:
    from analysis.effects import CATALOGUE, categories, registry
    users = registry.user_effects()
    if args.json:
        print_json([e.describe() for e in (*CATALOGUE.values(), *users)], indent=1)
        return 0
    for category, effects in categories().items():
        print(f"[{category}]")
        for e in effects:
            print(f"  {e.id:<22} {e.title} ({_parameters_text(e)})")
            print(f"  {'':<22} cures: {e.signature}")
    print(f"[effects of your own] (folder: {registry.user_folder()})")
    if not users:
        print("  none: write a TOML file there, or give --effects-file FILE (docs/effects.md)")
    for e in users:
        formula = getattr(e, "formula", None)
        print(f"  {e.id:<22} {e.title} ({_parameters_text(e)})")
        print(f"  {'':<22} site: {e.site.key}" + (f"; formula: {formula.text}" if formula is not None else ""))
        print(f"  {'':<22} from: {registry.source_of(e)}")
    return 0
