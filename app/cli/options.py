"""The options several `linpar` commands share, and the checks of what enters through them.

`number(bound)` is an argparse type: the text becomes a finite number in
the bound's range, or argparse's one-line error ("argument --sd: found
1e+160, expected an effective radiating area Sd: a number from 0.0001 to 1
m^2"). The bound says what the number is; no command repeats a range.

Only the bounds and the default model are imported here: building the parser
(`linpar --help`) loads no analysis.
"""
from __future__ import annotations

import argparse
from typing import Callable, Sequence

from analysis.bounds import SD, Bound, BoundsError, parse_size_limit
from analysis.errors import LinparError
from analysis.model.defaults import DEFAULT_EFFECTS
from analysis.text_boundary import control_found, shown


class CliError(LinparError):
    """A command line that cannot be run as given: printed as one line, exit code 2."""


class Parser(argparse.ArgumentParser):
    """linpar's parsers. `fill(parser)`, if given, adds the options that cost imports (a registry's) when this
    parser is first used, to parse its command or show its help: not for every other command."""

    def __init__(self, *args, fill: Callable[["Parser"], None] | None = None, **kwargs):
        super().__init__(*args, **kwargs)
        self._fill = fill

    def _filled(self) -> None:
        fill, self._fill = self._fill, None
        if fill is not None:
            fill(self)

    def parse_known_args(self, args=None, namespace=None):
        self._filled()
        return super().parse_known_args(args, namespace)

    def format_usage(self) -> str:
        self._filled()
        return super().format_usage()

    def format_help(self) -> str:
        self._filled()
        return super().format_help()

    def error(self, message: str):  # one line, no usage dump: scripts read stderr
        raise CliError(f"{message} (see '{self.prog} --help')")


def number(bound: Bound) -> Callable[[str], float | int]:
    def parse(text: str):
        try:
            return bound.parse(text, "")
        except BoundsError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    parse.__name__ = bound.what          # argparse names the type in a few of its own messages
    return parse


def name_text(text: str) -> str:
    """An argparse type for a name kept with a measurement (serial, operator, station, driver, note): one line
    of text, refused as it enters (analysis.text_boundary) rather than stored and refused when read back."""
    what = control_found(text)
    if what:
        raise argparse.ArgumentTypeError(f"'{shown(text)[:60]}' holds {what}; expected one line of text")
    return text


name_text.__name__ = "name"


def size_limit(text: str) -> tuple[str, int]:
    try:
        return parse_size_limit(text)
    except BoundsError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--size-limit: ")) from None


# What a recording's default model adds for a serial laser (analysis/serial_laser.py), said in each --model help.
SERIAL_LASER_MODEL = "; a serial laser's recording also delay-x"


def add_model_option(parser, default: Sequence[str] = DEFAULT_EFFECTS, why: str = "") -> None:
    """--model EFFECTS; `default` is what the command fits without it (said in the help, never typed twice)."""
    parser.add_argument("--model", metavar="EFFECTS",
                        help=f"effect ids separated by commas (default {','.join(default)}{why}; "
                             "'none' for the textbook model)")


def add_method_option(parser) -> None:
    """--method NAME: the identification (analysis.fit.methods; the names written out: no import of the fit)."""
    parser.add_argument("--method", choices=("joint", "paper", "alternating"), default=None,
                        help="joint: Z and Hx fitted together (the default, but for magnitude-only |Z| and |Hx| "
                             "curves: alternating); paper: the seed paper's two steps, Z for the electrical "
                             "parameters, then Hx for Bl and the creep with those held; alternating: those two "
                             "steps repeated until they agree, the creep fitted on Hx alone")


def add_sd_option(parser, note: str = "") -> None:
    parser.add_argument("--sd", type=number(SD), metavar="M2", help=f"effective radiating area in m^2{note}")


def add_json_option(parser, what: str = "print one JSON object") -> None:
    parser.add_argument("--json", action="store_true", help=what)


def model_effects(text: str | None, option: str = "--model"):
    """The effects an option names; None when it was not given: the command's default, which the analysis
    chooses (a recording's depends on it: a serial laser's has delay-x; magnitude-only curves have their own).
    ModelError that names the option."""
    if text is None:
        return None
    from analysis.model.composed import ModelError
    if not text.replace(",", "").strip():      # an unset shell variable ($MODEL) must not fit the textbook model
        raise ModelError(f"{option}: empty: give effect ids separated by commas ('linpar effects' lists them), or "
                         "'none' for the textbook model")
    from analysis.effects import UnknownEffectError, parse_effects
    try:
        return parse_effects(text)
    except UnknownEffectError as exc:
        raise ModelError(f"{option}: {exc}") from None
