"""`linpar recover`: measurements a crash (or a kill) cut short, kept, analysed or discarded, as the GUI offers.

    linpar recover [DIR]                        list them (DIR: the measure command's --out; default .)
    linpar recover [DIR] --keep [NAME...]       write each as NAME.wav + NAME.json, marked partial
    linpar recover [DIR] --analyse [NAME...]    keep, then print what `linpar analyze` prints
    linpar recover [DIR] --discard NAME...      remove their journals (the data are lost: named one by one)

A measurement whose process died before writing its recording leaves its
input in a journal, DIR/NAME.unfinished/ (instruments.measurement.recovery).
Without NAME, --keep and --analyse take every one in DIR. Exit 0 when all
that was asked was done; 2 when a name is unknown or a journal cannot be
recovered (the others are still done, and each problem is a line on stderr).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from app.cli import output
from app.cli.options import CliError, add_json_option
from app.cli.output import print_json


def register(sub) -> None:
    recover = sub.add_parser("recover", help="measurements cut short by a crash: list, keep, analyse or discard")
    recover.add_argument("dir", nargs="?", default=".", metavar="DIR",
                         help="the folder the measurement was written to (measure --out; default: .)")
    what = recover.add_mutually_exclusive_group()
    what.add_argument("--keep", nargs="*", metavar="NAME", help="write them as recordings (all without NAME)")
    what.add_argument("--analyse", "--analyze", nargs="*", metavar="NAME",
                      help="write them as recordings and analyse them (all without NAME)")
    what.add_argument("--discard", nargs="+", metavar="NAME", help="remove their journals: the data are lost")
    add_json_option(recover)
    recover.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from instruments.measurement.recovery import discard, find_unfinished, recover
    folder = Path(args.dir)
    if not folder.is_dir():
        raise CliError(f"{folder}: not a folder: expected the folder a measurement was written to (measure --out)")
    found = {u.name: u for u in find_unfinished(folder)}
    names = args.keep if args.keep is not None else args.analyse if args.analyse is not None else args.discard
    if names is None:
        return _list(found, folder, args.json)
    unknown = [n for n in names if n not in found]
    if unknown:
        raise CliError(f"{', '.join(unknown)}: no unfinished measurement of that name in {folder} "
                       f"(there: {', '.join(found) or 'none'})")
    chosen = [found[n] for n in names] if names else list(found.values())
    done, failed = [], []
    for unfinished in chosen:
        try:
            if args.discard is not None:
                discard(unfinished)
                done.append({"name": unfinished.name, "discarded": str(unfinished.journal)})
                _say(f"discarded {unfinished.journal}")
                continue
            wav = recover(unfinished)
            _say(f"kept {unfinished.name} as {wav} (marked partial)")
            entry = {"name": unfinished.name, "recording": str(wav)}
            if args.analyse is not None:
                entry["analysis"] = _analysis(wav, args.json)
            done.append(entry)
        except Exception as exc:  # noqa: BLE001 - one journal's problem must not stop the others
            from analysis.errors import is_user_error, user_message
            if not is_user_error(exc):
                raise
            failed.append({"name": unfinished.name, "error": user_message(exc)})
            print(f"linpar: error: {user_message(exc)}", file=sys.stderr)
    if args.json:
        print_json({"folder": str(folder), "done": done, "failed": failed})
    return 2 if failed else 0


def _list(found: dict, folder: Path, as_json: bool) -> int:
    if as_json:
        print_json({"folder": str(folder), "unfinished": [
            {"name": u.name, "journal": str(u.journal), "started_at": u.started_at, "periods": u.periods,
             "seconds": u.seconds, "serial_laser": u.serial_laser, "driver": u.driver,
             "recoverable": not u.problem, "problem": u.problem or None} for u in found.values()]})
        return 0
    if not found:
        print(f"no unfinished measurement in {folder}")
        return 0
    for u in found.values():
        print(u.describe())
    print(f"{len(found)} unfinished measurement(s) in {folder}: 'linpar recover {folder} --keep' writes them as "
          f"recordings, --analyse also analyses them, --discard NAME removes one")
    return 0


def _analysis(wav: Path, as_json: bool):
    from analysis.pipeline import analyze_path
    result = analyze_path(wav)
    if as_json:
        return result.as_json()
    print(f"{wav}:")
    print(result.report())
    return None


def _say(text: str) -> None:
    output.say("recover", text)
