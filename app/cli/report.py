"""`linpar report` and `linpar export`: a measurement from the archive (ID) or a recording (PATH).

A PATH that names an existing recording is analysed on the fly; anything
else is looked up in the archive as a measurement id (or its first characters).

`linpar report ... --limits FILE` judges the parameters against a QA limits
file: the report carries the verdict (a banner under the title and a table
per parameter), and the verdict is printed ("QA: PASS|FAIL|NOT JUDGED").
The exit code says whether the report was written (0) or not (2), not the
verdict: `linpar analyze --limits` is the command whose exit code is the verdict.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from app.cli import effects
from app.cli.archive_server import add_archive_options, open_from_args
from app.cli.options import SERIAL_LASER_MODEL, CliError, add_model_option, add_sd_option, model_effects


def export_options() -> list[tuple[str, str]]:
    """(kind, help) of every export format in analysis.export's registry."""
    from analysis.export import exporters
    return [(e.kind, f"{e.title} ({e.suffix})") for e in exporters().values()]


def _source_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("source", metavar="ID|PATH", help="archived measurement id, or a recording to analyse")
    add_archive_options(parser)
    add_sd_option(parser, " (recordings only)")
    add_model_option(parser, why="; recordings only" + SERIAL_LASER_MODEL)
    effects.add_effects_file_option(parser)


def register(sub) -> None:
    report = sub.add_parser("report", help="PDF and HTML report of one measurement")
    _source_arguments(report)
    report.add_argument("--pdf", metavar="FILE")
    report.add_argument("--html", metavar="FILE")
    report.add_argument("--limits", metavar="FILE",
                        help="QA limits (JSON, linpar-limits/1): the report shows pass/fail per parameter and overall")
    report.set_defaults(run=run_report)

    # The formats' options need every export module (0.05 s): added when `export` is the command.
    export = sub.add_parser("export", help="parameters, curves and a driver file of one measurement",
                            fill=_add_export_options)
    _source_arguments(export)
    export.set_defaults(run=run_export)


def _add_export_options(export: argparse.ArgumentParser) -> None:
    for kind, what in export_options():
        export.add_argument(f"--{kind.replace('_', '-')}", dest=kind, metavar="FILE", help=what)


def _is_recording(text: str) -> bool:
    from analysis.recording.format import recording_paths
    wav, sidecar = recording_paths(text)
    return wav.is_file() and sidecar.is_file()


def _not_a_file(source: str) -> None:
    """CliError when SOURCE names a file that is no recording: half of one, or a curve of another tool; a folder
    (RecordingError): the archive's "not a measurement id" would have answered each."""
    from pathlib import Path

    from analysis.recording.format import not_a_folder, recording_paths
    not_a_folder(source)
    if not Path(source).is_file():
        return
    wav, sidecar = recording_paths(source)
    if Path(source) in (wav, sidecar):
        missing = sidecar if Path(source) == wav else wav
        raise CliError(f"{source}: a recording is NAME.wav with its sidecar NAME.json, and {missing} is not there: "
                       "keep the two files together")
    raise CliError(f"{source}: a file, not a recording (NAME.wav and NAME.json) or a measurement id: curves of "
                   "another tool are fitted with 'linpar analyze --impedance FILE' (or --uiv FILE); their report "
                   "and exports come from the window: File > Open curves..., then File > Export report...")


def load_source(args):
    """(StoredResult, header, settings, calibration) of the ID or PATH."""
    if _is_recording(args.source):
        from analysis.archive.results import stored_from_recording
        stored, header, calibration = stored_from_recording(args.source, args.sd, model_effects(args.model))
        return stored, header, None, calibration
    _not_a_file(args.source)
    if args.sd is not None or args.model is not None:
        raise CliError(f"{args.source}: --sd and --model apply to recordings; an archived measurement keeps "
                       "its own")
    m = open_from_args(args).get(args.source)
    record = m.record
    header = {k: record.get(k) for k in ("driver", "serial", "measured_at", "operator", "station", "id")}
    return m.result(), header, m.load_json("settings"), m.load_json("calibration")


def _outputs_spare_the_inputs(args, outputs) -> None:
    """OutputError when an output file is one of the command's inputs (the recording, the limits, each other)."""
    from analysis.files import check_outputs_spare_inputs
    from analysis.recording.format import recording_paths
    inputs = [*recording_paths(args.source), *([Path(args.limits)] if getattr(args, "limits", None) else [])]
    check_outputs_spare_inputs(outputs, inputs)


def run_report(args: argparse.Namespace) -> int:
    if not args.pdf and not args.html:
        raise CliError("report: give --pdf FILE and/or --html FILE")
    _outputs_spare_the_inputs(args, [(o, p) for o, p in (("--pdf", args.pdf), ("--html", args.html)) if p])
    from analysis.limits import load_limits
    from analysis.report import build_report, write_report
    limits = load_limits(args.limits) if args.limits else None    # a bad file fails before the analysis
    stored, header, settings, calibration = load_source(args)
    content = build_report(stored, header, settings, calibration, limits)
    written = write_report(content, args.pdf, args.html)
    if content.qa is not None:
        print(f"QA: {content.qa.headline} — {content.qa.why} (limits {content.qa.file})")
    _say_written(written)
    return 0


def run_export(args: argparse.Namespace) -> int:
    options = export_options()
    targets = {kind: getattr(args, kind) for kind, _ in options if getattr(args, kind)}
    if not targets:
        raise CliError("export: give at least one of " + ", ".join(
            f"--{k.replace('_', '-')} FILE" for k, _ in options))
    _outputs_spare_the_inputs(args, [(f"--{k.replace('_', '-')}", p) for k, p in targets.items()])
    from analysis.export import write_exports
    stored, header, _, _ = load_source(args)
    _say_written(write_exports(stored, targets, header))
    return 0


def _say_written(paths) -> None:
    for path in paths:
        print(f"written: {path}")

