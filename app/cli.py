"""The `linpar` command line. Qt is imported only by `linpar gui`."""
from __future__ import annotations

import argparse
import sys
from typing import Sequence

from analysis.bounds import SD, SIZE_KINDS, size_limits_set
from analysis.errors import LinparError, is_user_error, user_message
from app import cli_effects, cli_import
from app.cli_options import number, size_limit

# 70: EX_SOFTWARE of sysexits.h, "an internal software error has been detected".
EXIT_OK, EXIT_ERROR, EXIT_INTERNAL, EXIT_INTERRUPTED = 0, 2, 70, 130


class CliError(LinparError):
    """A command line that cannot be run as given: printed as one line, exit code 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, no usage dump: scripts read stderr
        raise CliError(f"{message} (see '{self.prog} --help')")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="linpar", description="Loudspeaker linear parameters from voltage, current and "
                                                "laser displacement.")
    parser.add_argument("--size-limit", action="append", type=size_limit, metavar="KIND=SIZE", default=[],
                        help="read larger files than the defaults, which fit any real measurement: KIND is "
                             f"{', '.join(SIZE_KINDS)}; SIZE like 500M or 4G (before the command; repeatable)")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    analyze = sub.add_parser("analyze", help="fit the parameters of a recording")
    analyze.add_argument("path", nargs="?", help="recording: NAME, NAME.wav or NAME.json (or --impedance/--uiv)")
    analyze.add_argument("--sd", type=number(SD), metavar="M2", help="effective radiating area in m^2")
    analyze.add_argument("--model", metavar="EFFECTS",
                         help="effect ids separated by commas (default lr2,creep-log; 'none' for the textbook model)")
    analyze.add_argument("--json", action="store_true", help="print one JSON object")
    analyze.add_argument("--limits", metavar="FILE",
                         help="QA limits (JSON): print pass/fail; exit 0 pass, 1 fail, 2 error")
    cli_import.add_analyze_options(analyze)
    cli_effects.add_option(analyze)

    diagnose = sub.add_parser("diagnose", help="find which physical effect the model lacks")
    diagnose.add_argument("path", nargs="?", help="recording: NAME, NAME.wav or NAME.json (or --impedance/--uiv)")
    diagnose.add_argument("--from", dest="start", metavar="EFFECTS", default="none",
                          help="the starting model's effect ids (default: the textbook model)")
    diagnose.add_argument("--sd", type=number(SD), metavar="M2")
    diagnose.add_argument("--json", action="store_true")
    cli_import.add_analyze_options(diagnose)
    cli_effects.add_option(diagnose)

    cli_import.add_commands(sub)

    from app import cli_rig
    cli_rig.add_commands(sub)

    from app import cli_measure, cli_recover
    cli_measure.add_commands(sub)
    cli_recover.add_commands(sub)

    from app import cli_archive, cli_report
    cli_archive.add_commands(sub)
    cli_report.add_commands(sub)

    from app import cli_levels
    cli_levels.add_commands(sub)

    from app import cli_large_signal
    cli_large_signal.add_commands(sub)

    from app import cli_qa
    cli_qa.register(sub)

    effects = sub.add_parser("effects", help="list the effects catalogue and your own effects")
    effects.add_argument("--json", action="store_true")
    cli_effects.add_option(effects)

    gui = sub.add_parser("gui", help="start the workstation window")
    gui.add_argument("path", nargs="?", help="a recording to open")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; the CLI's only error boundary (analysis.errors): exit 2 for the user's errors,
    70 for a bug (one line, the details in a crash report), 130 for Ctrl-C."""
    try:
        args = build_parser().parse_args(argv)
        with size_limits_set(**dict(args.size_limit)):
            return _run(args)
    except KeyboardInterrupt:
        print("linpar: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Exception as exc:  # noqa: BLE001 - the boundary: a user error is one line, anything else a bug
        if is_user_error(exc):
            print(f"linpar: error: {user_message(exc)}", file=sys.stderr)
            return EXIT_ERROR
        from app.crash_report import internal_error_line
        print(f"linpar: {internal_error_line(exc, argv=argv)}", file=sys.stderr)
        return EXIT_INTERNAL


def _run(args: argparse.Namespace) -> int:
    if args.command in cli_effects.COMMANDS:
        cli_effects.load(args)           # a bad effect file stops every command that builds models: one line
    if args.command == "rig":
        from app import cli_rig
        return cli_rig.run(args)
    if args.command in ("archive", "report", "export"):
        from app import cli_archive, cli_report
        return cli_archive.run(args) if args.command == "archive" else cli_report.run(args)
    if args.command == "levels":
        from app import cli_levels
        return cli_levels.run(args)
    if args.command == "large-signal" or getattr(args, "plan", None) == "large-signal":
        from app import cli_large_signal
        return cli_large_signal.run(args) if args.command == "large-signal" else cli_large_signal.run_plan(args)
    if args.command == "qa":
        from app import cli_qa
        return cli_qa.run(args)
    if args.command == "measure":
        from app import cli_measure
        return cli_measure.run(args)
    if args.command == "recover":
        from app import cli_recover
        return cli_recover.run(args)
    if args.command == "gui":
        from app.main import run_gui
        return run_gui(args.path)
    from app import cli_commands
    return cli_commands.dispatch(args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
