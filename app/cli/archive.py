"""`linpar archive list|show|export|rebuild|store|compare`: the measurement archive from the command line.

Only sqlite3 and json are imported for `list`, `show` and `rebuild`: listing
a large archive must not wait for numpy and scipy to load.
"""
from __future__ import annotations

import argparse
import sys

from analysis.bounds import LIST_LIMIT
from app.cli import archive_server, effects
from app.cli.archive_server import add_archive_options, say_notes
from app.cli.options import (SERIAL_LASER_MODEL, add_json_option, add_model_option, add_sd_option, model_effects,
                             name_text, number)
from app.cli.output import print_json

COMPARE_HEADING_MAX = 24        # eight columns of this width and the spread fit in about 240 characters

LIST_PARAMETERS = (("RE", "ohm", 1.0), ("fs", "Hz", 1.0), ("Bl", "T*m", 1.0), ("Mms", "g", 1e3), ("Qts", "", 1.0))


def register(sub) -> None:
    archive = sub.add_parser("archive", help="the measurement archive: list, show, export, rebuild, store, compare; "
                                             "setup and sync for a PostgreSQL server")
    archive.set_defaults(run=run)
    verbs = archive.add_subparsers(dest="archive_command", required=True, parser_class=type(archive))

    ls = verbs.add_parser("list", help="list stored measurements, newest first")
    for name in ("driver", "serial", "operator", "station"):
        ls.add_argument(f"--{name}", metavar="TEXT", type=name_text, help=f"only measurements whose {name} contains TEXT")
    ls.add_argument("--validity", choices=("green", "yellow", "red"))
    ls.add_argument("--since", metavar="DATE", help="measured on or after DATE (ISO, e.g. 2024-05-01)")
    ls.add_argument("--until", metavar="DATE", help="measured on or before DATE")
    ls.add_argument("--limit", type=number(LIST_LIMIT), metavar="N")

    show = verbs.add_parser("show", help="one measurement's record and files")
    show.add_argument("id", help="measurement id (or its first characters)")

    export = verbs.add_parser("export", help="copy a measurement's folder into DIR")
    export.add_argument("id")
    export.add_argument("dir")

    verbs.add_parser("rebuild", help="rebuild the index from the measurement folders")

    store = verbs.add_parser("store", help="analyse a recording and store it in the archive")
    store.add_argument("path", help="recording: NAME, NAME.wav or NAME.json")
    for name in ("driver", "serial", "operator", "station", "notes"):
        store.add_argument(f"--{name}", metavar="TEXT", type=name_text, default="")
    store.add_argument("--measured-at", metavar="DATE", help="when it was measured: ISO 8601 with its UTC offset "
                       "(2026-05-04T09:30+02:00, or Z for UTC); default: now")
    store.add_argument("--laser-stream", metavar="FILE", help="the raw laser stream to keep with it")
    add_sd_option(store)
    add_model_option(store, why=SERIAL_LASER_MODEL)
    effects.add_effects_file_option(store)

    compare = verbs.add_parser("compare", help="up to 8 measurements' parameters side by side")
    compare.add_argument("ids", nargs="+", metavar="ID")

    for parser in (ls, show, export, store, compare, verbs.choices["rebuild"]):
        add_archive_options(parser)
        add_json_option(parser, "print JSON")
    archive_server.register_verbs(verbs)


def _param(entry, name: str, scale: float) -> str:
    p = entry.parameters.get(name) or {}
    v = p.get("value")
    return "-" if not isinstance(v, (int, float)) else f"{v * scale:.4g}"


def run(args: argparse.Namespace) -> int:
    verb = args.archive_command
    if verb in archive_server.SERVER_VERBS:
        return archive_server.run_verb(args)
    archive = archive_server.open_from_args(args, creates=verb == "store")
    if verb == "list":
        from analysis.archive import Filter
        entries = archive.list(Filter(args.driver, args.serial, args.operator, args.station, args.validity,
                                      args.since, args.until, args.limit))
        say_notes(archive)
        if args.json:
            print_json([e.as_json() for e in entries])
            return 0
        cols = "  ".join(f"{n + (' [' + u + ']' if u else ''):>10}" for n, u, _ in LIST_PARAMETERS)
        lines = [f"{'id':<22}  {'date (UTC)':<20}  {'driver':<20}  {'serial':<12}  {'validity':<8}  {cols}"]
        for e in entries:
            params = "  ".join(f"{_param(e, n, s):>10}" for n, _, s in LIST_PARAMETERS)
            lines.append(f"{e.id:<22}  {e.measured_at:<20}  {e.driver[:20]:<20}  {e.serial[:12]:<12}  "
                         f"{e.validity:<8}  {params}")
        lines.append(f"{len(entries)} measurement(s) in {archive.location}")
        sys.stdout.write("\n".join(lines) + "\n")
        return 0
    if verb == "show":
        m = archive.get(args.id)
        say_notes(archive)
        if args.json:
            print_json({**m.record, "path": str(m.folder)}, indent=1)
            return 0
        r = m.record
        for key in ("id", "measured_at", "stored_at", "driver", "serial", "operator", "station", "validity",
                    "notes"):
            if r.get(key):
                print(f"{key:<12} {r[key]}")
        print(f"{'model':<12} {', '.join(r.get('effects', [])) or 'textbook'}")
        print(f"{'folder':<12} {m.folder}")
        for role, name in r.get("files", {}).items():
            print(f"  {role:<12} {name}")
        print("parameters (SI):")
        for name, p in r.get("key_parameters", {}).items():
            value, std = p.get("value"), p.get("std")
            text = "n/a" if value is None else f"{value:.6g}" + ("" if std is None else f" ± {std:.2g}")
            print(f"  {name:<14} {text} {p.get('unit', '')}")
        for flag in r.get("flags", []):
            print(f"flagged: {flag}")
        return 0
    if verb == "export":
        target = archive.export(args.id, args.dir)
        say_notes(archive)
        if args.json:
            print_json({"exported": str(target)})
        else:
            print(f"exported to {target}")
        return 0
    if verb == "rebuild":
        report = archive.rebuild()
        if args.json:
            print_json({"indexed": report.indexed, "skipped": report.skipped})
        else:
            print(report.describe())
        return 0
    if verb == "store":
        return _store(archive, args)
    if verb == "compare":
        return _compare(archive, args)
    raise AssertionError(f"unknown archive command {verb!r}")     # the parser allows no other


def _store(archive, args) -> int:
    from analysis.archive.archive import checked_measured_at
    from analysis.fit.model_uncertainty import model_uncertainty
    from analysis.pipeline import analyze_path
    checked_measured_at(args.measured_at)        # before the analysis: a wrong date is said at once
    # The record's uncertainties with their model part, as `linpar analyze` prints them.
    result = model_uncertainty(analyze_path(args.path, args.sd, model_effects(args.model)))
    mid = archive.store(args.path, result, {"driver": args.driver, "serial": args.serial, "operator": args.operator,
                                            "station": args.station, "notes": args.notes,
                                            "measured_at": args.measured_at}, laser_stream=args.laser_stream)
    say_notes(archive)
    queued = archive.pending > 0
    from app.cli.stored_verdict import stored_verdict
    qa, words = (None, "") if queued else stored_verdict(archive, mid, result)
    if args.json:
        print_json({"id": mid, "validity": str(result.validity.overall), **({"queued": True} if queued else {}),
                    **({"qa": qa} if qa is not None else {})})
    else:
        print(f"{'queued' if queued else 'stored'} {mid} (validity {result.validity.overall})"
              + (": it waits in this station's queue until the server can be reached" if queued else ""))
        if words:
            print(words)
    return 0


def _heading(text: str, width: int) -> str:
    return text if len(text) < width else text[:width - 2] + "…"


def _compare(archive, args) -> int:
    from analysis.archive import compare
    from analysis.report.numbers import format_number, pretty_unit
    from analysis.text_boundary import terminal
    c = compare(archive, args.ids)
    say_notes(archive)
    if args.json:
        print_json(c.as_json())
        return 0
    # Which measurement each column is: two of one driver have the same name (and a serial measured twice
    # the same serial), so the columns are numbered, and the numbers said first with their ids and dates.
    labels = [terminal(label) for label in c.labels]
    for number, (mid, when, label) in enumerate(zip(c.ids, c.measured_at, labels), 1):
        print(f"{number}. {mid}  measured {when.replace('T', ' ').removesuffix('Z')} UTC  {label}")
    print()
    headings = [f"{number}. {label}" for number, label in enumerate(labels, 1)]
    width = max(14, min(COMPARE_HEADING_MAX, max(len(h) for h in headings) + 2))
    print(f"{'parameter':<14}{'unit':<8}" + "".join(f"{_heading(h, width):>{width}}" for h in headings)
          + f"{'spread':>{width}}")
    for row in c.rows:
        cells = "".join(f"{format_number(v, s) if v is not None else 'n/a':>{width}}" for v, s in zip(row.values, row.stds))
        spread = "" if row.spread is None else f"{row.spread:.3g}"
        print(f"{row.name:<14}{pretty_unit(row.display_unit):<8}{cells}{spread:>{width}}")
    return 0
