"""`linpar qa`: production QA over the archive's population of units.

    linpar qa stats [--since DATE] [--until DATE] [--station S]... [--driver D]... [--parameter P]...
                    [--limits-version N] [--baseline N] [--json]
    linpar qa limits                                        the stored limits versions
    linpar qa limits --show N                               one version's limits file (JSON)
    linpar qa limits --from-golden [ID...] [--k K] [--out FILE]   propose limits (no ID: the golden units)
    linpar qa limits --store FILE [--note TEXT]             store a reviewed limits file as a new version
    linpar qa golden [--add ID...] [--remove ID...]         the golden units
    linpar qa export [filters] [--csv FILE] [--json FILE] [--dfq FILE]

Each takes --archive URL|DIR or --root DIR (app.cli.archive_server). The
statistics' text is in app.cli.qa_text; the numbers in analysis.production.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from analysis.bounds import BASELINE, COVERAGE_K, LIMITS_VERSION
from app.cli.archive_server import add_archive_options, open_from_args, say_notes
from app.cli.options import CliError, add_json_option, name_text, number
from app.cli.output import print_json


def _selection_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--since", metavar="DATE", help="measured on or after DATE (ISO 8601, e.g. 2024-05-01)")
    parser.add_argument("--until", metavar="DATE", help="measured on or before DATE")
    parser.add_argument("--station", action="append", default=[], metavar="S", help="only station S (exact; repeatable)")
    parser.add_argument("--driver", action="append", default=[], metavar="D", help="only driver D (exact; repeatable)")
    parser.add_argument("--parameter", action="append", default=[], metavar="P",
                        help="only parameter P (RE, fs, Qts, ...; repeatable; default: every one measured)")
    parser.add_argument("--limits-version", type=number(LIMITS_VERSION), metavar="N",
                        help="judge against limits version N (default: the newest)")


def register(sub) -> None:
    qa = sub.add_parser("qa", help="production QA: statistics over units, limits versions, golden units, export")
    qa.set_defaults(run=run)
    verbs = qa.add_subparsers(dest="qa_command", required=True, parser_class=type(qa))

    stats = verbs.add_parser("stats", help="per parameter: n, mean, sigma, Cp/Cpk, Pp/Ppk, yield, control-chart "
                                           "alarms, stations compared")
    _selection_options(stats)
    stats.add_argument("--baseline", type=number(BASELINE), default=50, metavar="N",
                       help="the control chart's limits come from the first N units (default %(default)s)")
    add_json_option(stats)

    limits = verbs.add_parser("limits", help="the archive's limits versions; propose limits from golden units; "
                                             "store a new version")
    what = limits.add_mutually_exclusive_group()
    what.add_argument("--show", type=number(LIMITS_VERSION), metavar="N", help="print limits version N as a limits file")
    what.add_argument("--from-golden", nargs="*", metavar="ID",
                      help="propose limits from these measurements (none given: the archive's golden units)")
    what.add_argument("--store", metavar="FILE", help="store a limits file (linpar-limits/1) as a new version "
                                                      "(an engineer's right)")
    limits.add_argument("--k", type=number(COVERAGE_K), default=3.0, help="limits at mean +- K sigma (default 3)")
    limits.add_argument("--out", metavar="FILE", help="write the proposal there (default: print it)")
    limits.add_argument("--name", metavar="TEXT", type=name_text, help="the proposal's name")
    limits.add_argument("--note", metavar="TEXT", type=name_text, default="", help="why this version (kept with it)")
    add_json_option(limits, "print JSON")

    golden = verbs.add_parser("golden", help="list, add or remove golden units (adding and removing: an engineer's "
                                             "right)")
    golden.add_argument("--add", nargs="+", default=[], metavar="ID")
    golden.add_argument("--remove", nargs="+", default=[], metavar="ID")
    add_json_option(golden, "print JSON")

    export = verbs.add_parser("export", help="the selected population as CSV (long), JSON or Q-DAS AQDEF (.dfq)")
    _selection_options(export)
    export.add_argument("--csv", metavar="FILE")
    export.add_argument("--json", metavar="FILE")
    export.add_argument("--dfq", metavar="FILE", help="Q-DAS AQDEF (qs-STAT, procella)")

    for parser in (stats, limits, golden, export):
        add_archive_options(parser)


def _selection(args):
    from analysis.archive.population import Selection
    return Selection(args.since, args.until, tuple(args.station), tuple(args.driver)).checked()


def _limits_version(archive, args):
    return archive.limits(args.limits_version) if args.limits_version else archive.limits()


def _stats(archive, args, with_stds: bool = True):
    from analysis.production import production_stats
    selection = _selection(args)
    population = archive.population(selection, args.parameter or None, with_stds)
    limits = _limits_version(archive, args)
    return population, production_stats(population, limits, getattr(args, "baseline", 50), args.parameter or None,
                                        selection.describe())


def run(args: argparse.Namespace) -> int:
    archive = open_from_args(args, creates=args.qa_command == "limits" and bool(getattr(args, "store", None)))
    try:
        return {"stats": _run_stats, "limits": _run_limits, "golden": _run_golden,
                "export": _run_export}[args.qa_command](archive, args)
    finally:
        say_notes(archive)


def _run_stats(archive, args) -> int:
    _population, stats = _stats(archive, args, with_stds=False)     # the statistics need no standard deviations
    if args.json:
        print_json({"archive": archive.location, **stats.as_json()})
    else:
        from app.cli.qa_text import stats_text
        print(stats_text(stats, archive.location))
    return 0


def _write(path: str, payload: bytes | str) -> Path:
    from analysis.archive.atomic import write_atomic
    return write_atomic(Path(path), payload)


def _run_limits(archive, args) -> int:
    from app.cli.qa_text import proposal_text, versions_text
    if args.show:
        print_json(archive.limits(args.show).document, indent=1)
        return 0
    if args.store:
        from analysis.files import read_text
        from analysis.limits import LimitsError, load_limits
        load_limits(args.store)                               # every check of a limits file, with its lines
        doc = json.loads(read_text(args.store, "config", "a JSON limits file", LimitsError))
        version = archive.store_limits(doc, args.note)
        if args.json:
            print_json(version.as_json())
        else:
            print(f"stored {args.store} as limits version {version.version} ({version.name}) in {archive.location}")
        return 0
    if args.from_golden is not None:
        from analysis.archive.population import Selection
        from analysis.production import propose_limits
        ids = [archive.resolve(i)[0] for i in args.from_golden] or archive.golden()
        if not ids:
            raise CliError("qa limits --from-golden: name the golden units' ids, or mark them first with "
                           "'linpar qa golden --add ID...'")
        population = archive.population(Selection(ids=tuple(ids)).checked())
        document, proposed, notes = propose_limits(population, args.k, ids, args.name or "")
        text = json.dumps(document, indent=1, ensure_ascii=False) + "\n"
        if args.out:
            _write(args.out, text)
        if args.json:
            print_json({"limits": document, "proposed": [p.as_json() for p in proposed], "notes": notes,
                        "written": args.out})
        else:
            print(proposal_text(proposed, notes, args.k, args.out, text))
        return 0
    versions = archive.limits_versions()
    if args.json:
        print_json([v.as_json() for v in versions])
    else:
        print(versions_text(versions, archive.location))
    return 0


def _run_golden(archive, args) -> int:
    ids = archive.golden()
    if args.add:
        from analysis.archive.population import Selection
        from analysis.production.golden import check_golden
        check_golden(archive.population(Selection(ids=tuple(archive.resolve(i)[0] for i in args.add)).checked()))
        ids = archive.set_golden(args.add, golden=True)
    if args.remove:
        ids = archive.set_golden(args.remove, golden=False)
    if args.json:
        print_json({"archive": archive.location, "golden": ids})
    else:
        print(f"{len(ids)} golden unit(s) in {archive.location}" + "".join(f"\n  {i}" for i in ids))
    return 0


def _run_export(archive, args) -> int:
    targets = [(o, p) for o, p in (("--csv", args.csv), ("--json", args.json), ("--dfq", args.dfq)) if p]
    if not targets:
        raise CliError("qa export: give --csv FILE, --json FILE and/or --dfq FILE")
    if len({Path(p).resolve() for _o, p in targets}) != len(targets):
        raise CliError("qa export: two outputs name the same file: choose one name for each")
    population, stats = _stats(archive, args)
    from analysis.production.aqdef import encode, write_dfq
    from analysis.production.exchange import population_csv, population_json
    excluded = {i for i, v, d in zip(population.ids, population.validity, population.verdicts)
                if v == "red" or d in ("invalid", "not judged")}
    written = []
    for option, path in targets:
        if option == "--csv":
            payload = population_csv(population)
        elif option == "--json":
            payload = json.dumps(population_json(population, stats.selection, archive.location, stats.limits),
                                 indent=1, ensure_ascii=False, allow_nan=False) + "\n"
        else:
            payload = encode(write_dfq(population, stats.parameters, excluded))
        written.append(str(_write(path, payload)))
    for path in written:
        print(f"written: {path}")
    print(f"{len(population)} measurement(s) of {archive.location} ({stats.selection})", file=sys.stderr)
    return 0
