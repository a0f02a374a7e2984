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
# Of `linpar archive`, the verbs that analyse (store) or compare fits; list, show, export, sync... read records only.
ARCHIVE_VERBS = ("store", "compare")


def builds_models(args: argparse.Namespace) -> bool:
    """Whether the command reads the effects (the user folder too): only those that build models do, so that a
    bad effect file never blocks listing, showing, exporting or syncing the archive."""
    if args.command == "archive":
        return getattr(args, "archive_command", None) in ARCHIVE_VERBS
    return args.command in COMMANDS


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
    """Read and register the user's effects. Every file that cannot be used is named (not only the first); the
    good ones are registered. `linpar effects` lists the bad ones beside the good; any other command stops with
    one line naming them all (EffectFileError)."""
    from analysis.effects import registry
    problems: list[str] = []
    effects = registry.load_user_effects(getattr(args, "effects_files", None) or (), problems=problems)
    registry.register(effects)
    args.effect_problems = problems
    if args.command != "effects":       # `linpar effects` lists what loaded first, then says the same line
        _refuse_problems(args)
    return effects


def _refuse_problems(args: argparse.Namespace) -> None:
    """One line naming every effect file that cannot be used, when there are any (exit 2)."""
    from analysis.effects.file_error import EffectFileError
    problems = getattr(args, "effect_problems", [])
    if problems:
        many = f"{len(problems)} effect files cannot be used: " if len(problems) > 1 else ""
        raise EffectFileError(many + "; ".join(problems))


def _parameters_text(effect: Effect) -> str:
    return ", ".join(f"{p.name} [{p.display_unit}" + (f", typically {p.typical_text()}]" if p.typical else "]")
                     for p in effect.params)


def run(args: argparse.Namespace) -> int:
    from analysis.effects import CATALOGUE, categories, registry
    users = registry.user_effects()
    if args.json:
        print_json([e.describe() for e in (*CATALOGUE.values(), *users)], indent=1)
        _refuse_problems(args)
        return 0
    for category, effects in categories().items():
        print(f"[{category}]")
        for e in effects:
            print(f"  {e.id:<22} {e.title} ({_parameters_text(e)})")
            print(f"  {'':<22} cures: {e.signature}")
    print(f"[effects of your own] (folder: {registry.user_folder()})")
    if not users and not getattr(args, "effect_problems", []):     # a file that could not be read: said below
        print("  none: write a TOML file there, or give --effects-file FILE (docs/effects.md)")
    for e in users:
        formula = getattr(e, "formula", None)
        print(f"  {e.id:<22} {e.title} ({_parameters_text(e)})")
        print(f"  {'':<22} site: {e.site.key}" + (f"; formula: {formula.text}" if formula is not None else ""))
        print(f"  {'':<22} from: {registry.source_of(e)}")
    _refuse_problems(args)
    return 0
