"""`linpar`'s parser and its one error boundary: parse, then run the command's `run(args)`."""
from __future__ import annotations

import argparse
import gc
import os
import sys
from importlib import import_module
from typing import Sequence

from analysis.bounds import SIZE_KINDS, size_limits_set
from analysis.errors import is_user_error, user_message
from analysis.text_boundary import SURROGATES, control_found, shown, terminal
from app.cli import effects
from app.cli.options import CliError, Parser, size_limit

# 70: EX_SOFTWARE of sysexits.h, "an internal software error has been detected". 141: what a shell reports for a
# program ended by SIGPIPE (128 + 13), as `yes | head` ends `yes`.
EXIT_OK, EXIT_ERROR, EXIT_INTERNAL, EXIT_INTERRUPTED, EXIT_BROKEN_PIPE = 0, 2, 70, 130, 141

# Each command and the module of app/cli that registers it, in the order `linpar --help` lists them. A command
# line that names its command builds that module's parser only: building all fourteen imported what every
# command needs (the devices, the measurement plans, the archive's server options ...), 4 % of the instructions
# of `linpar analyze` (about 15 ms of CPU time). tests/app/cli/test_boundary.py checks the table against what
# each module registers.
COMMANDS = {"analyze": "analyze", "diagnose": "diagnose", "addedmass": "added_mass", "stats": "stats", "rig": "rig",
            "measure": "measure", "recover": "recover", "archive": "archive", "report": "report", "export": "report",
            "levels": "levels", "large-signal": "large_signal", "qa": "qa", "effects": "effects", "gui": "gui"}
COMMAND_GROUPS = tuple(dict.fromkeys(COMMANDS.values()))


class _Version(argparse.Action):
    """`--version`: the installed version, looked up only when asked. Given to argparse's own version action
    when the parser was built, importing app.crash_report and looking the version up cost every command's start
    8-10 ms (importlib.metadata is imported only when a package names linpar's effects' entry point group)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS,
                 help="show the program's version number and exit"):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        from app.crash_report import version
        print(f"linpar {version()}")
        parser.exit()


def command_group(module: str):
    """The module of app/cli named `module` (a value of COMMANDS), imported when its parser is first built."""
    return import_module(f"app.cli.{module}")


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """linpar's parser: with every command, or with `command`'s group only (the same parser for its command
    line; argparse's message for an unknown command lists them all, so that one needs them all)."""
    parser = Parser(prog="linpar", description="Loudspeaker linear parameters from voltage, current and "
                                               "laser displacement.")
    parser.add_argument("--size-limit", action="append", type=size_limit, metavar="KIND=SIZE", default=[],
                        help="read larger files than the defaults, which fit any real measurement: KIND is "
                             f"{', '.join(SIZE_KINDS)}; SIZE like 500M or 4G (before the command; repeatable)")
    parser.add_argument("--version", action=_Version)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for group in (COMMANDS[command],) if command else COMMAND_GROUPS:
        command_group(group).register(sub)
    return parser


def command_named(argv: Sequence[str]) -> str | None:
    """The command a command line names, when that is plain before parsing: the first word after linpar's own
    options (only --size-limit takes a value). None, so that every command is built, for anything less plain:
    no command, an unknown one, -h, --version, an abbreviated option, a value that looks like an option."""
    i = 0
    while i < len(argv):
        arg = str(argv[i])
        if arg == "--size-limit" and i + 1 < len(argv) and not str(argv[i + 1]).startswith("-"):
            i += 2
        elif arg.startswith("--size-limit="):
            i += 1
        else:
            return arg if arg in COMMANDS else None
    return None


def _check_encoding(argv: Sequence[str]) -> None:
    """Arguments that were not UTF-8 bytes (a Latin-1 name) are refused before anything prints or stores them."""
    for arg in argv:
        what = control_found(str(arg), SURROGATES)
        if what:
            raise CliError(f"the argument '{shown(str(arg))[:60]}' holds {what}")


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; the CLI's only error boundary (analysis.errors): exit 2 for the user's errors,
    70 for a bug (one line, the details in a crash report), 130 for Ctrl-C. Without `argv` it runs the process's
    own command line (`linpar`, `python -m app.cli`), and the process ends when it returns."""
    ran: list[str] = []
    try:
        return _run(argv, ran)
    finally:
        if argv is None and "gui" not in ran and command_named(sys.argv[1:]) != "gui":
            # The interpreter's exit collects the garbage of every object still alive: all the command imported
            # (3-5 % of `linpar analyze`'s CPU time, in instructions counted). Frozen, they are left to the
            # process's end; output is still flushed, atexit handlers and the finalizers of what reference
            # counting frees still run; only reference cycles still there at exit are not collected. Not for the
            # window, whose Qt objects in such cycles would then never be destroyed: its exit is not timed.
            gc.freeze()


def _run(argv: Sequence[str] | None, ran: list[str]) -> int:
    """main's work; `ran` gets the command parsed (argparse's reading: `--size-lim X gui` runs the window too)."""
    try:
        given = sys.argv[1:] if argv is None else argv
        _check_encoding(given)
        args = build_parser(command_named(given)).parse_args(given)
        ran.append(args.command)
        with size_limits_set(**dict(args.size_limit)):
            if effects.builds_models(args):
                effects.load(args)      # a bad effect file stops every command that builds models: one line
            return args.run(args)
    except KeyboardInterrupt:
        print("linpar: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # The reader went away (`linpar archive list | head`): nothing is wrong, and nothing more reaches it. Not
        # "linpar: error: Broken pipe"; and the interpreter, flushing stdout at exit, would complain once more.
        _stdout_to_devnull()
        return EXIT_BROKEN_PIPE
    except Exception as exc:  # noqa: BLE001 - the boundary: a user error is one line, anything else a bug
        if is_user_error(exc):
            print(f"linpar: error: {terminal(user_message(exc))}", file=sys.stderr)
            return EXIT_ERROR
        from app.crash_report import internal_error_line
        print(f"linpar: {internal_error_line(exc, argv=argv)}", file=sys.stderr)
        return EXIT_INTERNAL


def _stdout_to_devnull() -> None:
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):     # a stream of the caller's (a test's capture): nothing to do
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, fd)
    os.close(devnull)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
