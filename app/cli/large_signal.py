"""`linpar large-signal` and `linpar measure --plan large-signal`: the large-signal curves of a driver.

    linpar large-signal REC... [--order N] [--json] [--bl-min PCT] [--cms-min PCT] [--le-change PCT]
                        [--predict VOLT [--sine HZ] [--two-tones F1,F2]]
                        [--pdf FILE] [--html FILE] [--csv FILE] [--export-json FILE]
    linpar measure --plan large-signal --out DIR [--level VOLT] [--max-excursion MM] [--max-voltage VOLT]
                   [--max-distortion DB] [--max-temperature-rise K] [--step FACTOR] [measure's options]

REC is a recording (NAME, NAME.wav or NAME.json) or a plan's summary
(NAME.large-signal.json: its complete steps). The identification
(analysis.large_signal) prints the curves, the coil's rest offset and the
excursion limits, or with --json one object (the contract in
analysis/large_signal/result.py). --order is the highest order BIC may
choose for Bl, Kms and Le (default 6). --pdf/--html write the report,
--csv/--export-json the curves (analysis/report/large_signal.py,
analysis/export/large_signal.py); an output that would replace one of the
recordings read, or something not a regular file, is refused before the
identification runs.

The plan steps the level up from --level (default: the large-signal
template's 0.5 V) until a limit, each step a recording in --out (see
instruments/measurement/large_signal_plan.py); the complete steps are then
identified as above. A step that a device ends keeps what was recorded, and
the command exits 2 with what happened, after printing what it could.
The steps are not stored in the measurement archive.

Every number given is checked where it enters (finite, in range) with one
line that says what is wrong; the analysis and devices load only when a
command runs.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from analysis.bounds import (AUDIO_FREQUENCY, DISTORTION_DB, EXCURSION_MM, LEVEL_STEP, LEVEL_V_RMS, LIMIT_PERCENT,
                             POLYNOMIAL_ORDER, TEMPERATURE_RISE_K)
from app.cli import devices
from app.cli.devices import say
from app.cli.options import CliError, add_json_option, number
from app.cli.output import print_json

PLANS = ("single", "large-signal")
OUTPUTS = (("pdf", "write the report as PDF"), ("html", "write the report as HTML (self-contained)"),
           ("csv", "write the curves as CSV (x, Bl, Kms, Cms, Le with 1-sigma across the measured range)"),
           ("export-json", "write the JSON (as --json prints it) to FILE"))


def _two_tones(text: str) -> tuple[float, float]:
    parse = number(AUDIO_FREQUENCY)
    parts = [p for p in text.split(",") if p.strip()]
    if len(parts) != 2:
        raise argparse.ArgumentTypeError(f"expected two frequencies F1,F2 in Hz (F1 < F2), got {text!r}")
    f1, f2 = (parse(p) for p in parts)
    if not f1 < f2:
        raise argparse.ArgumentTypeError(f"expected F1 < F2, got {text!r}")
    return f1, f2


def register(sub) -> None:
    c = sub.add_parser("large-signal", help="Bl(x), Kms(x), Le(x), the coil's rest offset and the excursion limits")
    c.add_argument("paths", nargs="+", metavar="REC",
                   help="recordings of one driver at large signal (NAME, NAME.wav or NAME.json), or a plan's "
                        "NAME.large-signal.json")
    c.add_argument("--order", type=number(POLYNOMIAL_ORDER), default=6, metavar="N",
                   help="highest polynomial order BIC may choose for Bl, Kms, Le (default %(default)s)")
    c.add_argument("--bl-min", type=number(LIMIT_PERCENT), default=82.0, metavar="PCT",
                   help="X_Bl: the excursion where Bl falls to PCT %% of Bl(0) (default %(default)g, Klippel)")
    c.add_argument("--cms-min", type=number(LIMIT_PERCENT), default=75.0, metavar="PCT",
                   help="X_C: where the compliance falls to PCT %% of Cms(0) (default %(default)g)")
    c.add_argument("--le-change", type=number(LIMIT_PERCENT), default=10.0, metavar="PCT",
                   help="X_L: where Le leaves Le(0) by PCT %% (default %(default)g, after IEC 62458)")
    c.add_argument("--predict", type=number(LEVEL_V_RMS), metavar="VOLT",
                   help="predict the distortion at this level (V RMS): the multitone, and --sine / --two-tones")
    c.add_argument("--sine", type=number(AUDIO_FREQUENCY), metavar="HZ",
                   help="with --predict: H2 and H3 of current and displacement for a sine at HZ")
    c.add_argument("--two-tones", type=_two_tones, metavar="F1,F2",
                   help="with --predict: IMD2 and IMD3 for two tones F1 + F2 (amplitudes 4:1)")
    add_json_option(c)
    for option, what in OUTPUTS:
        c.add_argument(f"--{option}", type=Path, metavar="FILE", help=what)
    c.set_defaults(run=run)


# The large-signal plan's limits: (option, bound, default, help). Their defaults are filled in by run_plan, so
# that a limit given to the single plan, which would ignore it, is seen and refused (plan_options_checked).
PLAN_LIMITS = (
    ("max-excursion", EXCURSION_MM, 4.0, "MM", "stop at this peak excursion (default %g mm)"),
    ("max-voltage", LEVEL_V_RMS, 10.0, "VOLT", "never above this level (default %g V RMS)"),
    ("max-distortion", DISTORTION_DB, -20.0, "DB", "stop when the current's distortion reaches DB re the signal "
                                                   "(default %g dB)"),
    ("max-temperature-rise", TEMPERATURE_RISE_K, 20.0, "K", "stop when the voice coil warmed by K kelvin (RE per "
                                                            "period; default %g K)"),
    ("step", LEVEL_STEP, 1.41, "FACTOR", "level factor per step (default %g, +3 dB)"),
)


def add_plan_options(measure: argparse.ArgumentParser) -> None:
    """measure's --plan and the large-signal plan's limits."""
    measure.add_argument("--plan", choices=PLANS, default="single",
                         help="'single': one measurement (default); 'large-signal': steps up the level until a "
                              "limit, each step a recording, then identifies Bl(x), Kms(x), Le(x)")
    for option, bound, default, metavar, what in PLAN_LIMITS:
        measure.add_argument(f"--{option}", type=number(bound), metavar=metavar,
                             help=f"large-signal plan: {what % default}")


def plan_options_checked(args: argparse.Namespace) -> None:
    """CliError when the single plan is given a large-signal limit; otherwise each limit not given gets its
    default."""
    for option, _, default, _, _ in PLAN_LIMITS:
        attribute = option.replace("-", "_")
        if getattr(args, attribute) is None:
            setattr(args, attribute, default)
        elif args.plan != "large-signal":
            raise CliError(f"--{option} is a limit of the large-signal plan: add --plan large-signal, or leave it "
                           f"out")


def run(args: argparse.Namespace) -> int:
    from analysis.large_signal import LimitThresholds, Prediction, large_signal
    from analysis.large_signal.words import format_large_signal
    if (args.sine is not None or args.two_tones is not None) and args.predict is None:
        raise CliError("--sine and --two-tones need --predict VOLT (the level to predict at)")
    thresholds = LimitThresholds(args.bl_min / 100.0, args.cms_min / 100.0, args.le_change / 100.0)
    predictions = [] if args.predict is None else [Prediction(args.predict, args.sine, args.two_tones)]
    inputs = expand(args.paths)
    outputs = checked_outputs(args, inputs)          # before the identification: a mistake costs nothing
    result = large_signal(inputs, args.order, thresholds, predictions)
    if args.json:
        print_json(result.as_json())
    else:
        print(format_large_signal(result))
    for path in write_outputs(result, outputs):
        print(f"written: {path}", file=sys.stderr)
    return 0


def checked_outputs(args: argparse.Namespace, inputs) -> dict[str, Path]:
    """The files to write; OutputError (one line) when one would replace an input of this command (a recording's
    WAV or sidecar), another output or something that is not a regular file."""
    from analysis.files import check_output, check_outputs_spare_inputs
    from analysis.recording.format import recording_paths
    taken = [p for path in inputs for p in _recording_files(path, recording_paths)]
    outputs = {option: path for option, _ in OUTPUTS
               if (path := getattr(args, option.replace("-", "_"))) is not None}
    check_outputs_spare_inputs([(f"--{option}", path) for option, path in outputs.items()], taken)
    for path in outputs.values():
        check_output(path)          # a FIFO, a device, a folder: refused before anything runs
    return outputs


def _recording_files(path, recording_paths) -> list[Path]:
    """The files a recording argument reads (NAME.wav and NAME.json), or the path as given if it names none."""
    try:
        return list(recording_paths(path))
    except (OSError, ValueError):
        return [Path(path)]


def write_outputs(result, outputs: dict[str, Path]) -> list[Path]:
    """The report and exports asked for, each written atomically."""
    from analysis.archive.atomic import write_atomic
    from analysis.export.large_signal import curves_csv, curves_json
    from analysis.report.large_signal import render_large_signal_html, render_large_signal_pdf
    render = {"pdf": render_large_signal_pdf, "html": render_large_signal_html, "csv": curves_csv,
              "export-json": curves_json}
    return [write_atomic(path, render[option](result)) for option, path in outputs.items()]


def expand(paths) -> list[Path]:
    """Recordings, with a plan's summary replaced by its complete steps (in its folder)."""
    from analysis.large_signal.plan_summary import is_summary, summary_recordings
    out = []
    for given in paths:
        out += summary_recordings(given) if is_summary(given) else [Path(given)]
    return out


def run_plan(args: argparse.Namespace) -> int:
    """`linpar measure --plan large-signal` (module doc)."""
    import threading
    from contextlib import ExitStack
    from dataclasses import replace

    from analysis.large_signal import LargeSignalError, large_signal
    from analysis.large_signal.stepping import StepLimits
    from analysis.large_signal.words import format_large_signal
    from instruments.measurement.large_signal_plan import LargeSignalPlan, run_large_signal
    from instruments.measurement.plan import MeasurementPlan

    plan_options_checked(args)
    if args.out.exists() and not args.out.is_dir():
        raise CliError(f"--out {args.out}: not a folder: the plan writes a recording a step and its summary there; "
                       f"choose a folder")
    if args.level is not None and args.level > args.max_voltage:
        raise CliError(f"--level {args.level:g} V: the plan starts at most at --max-voltage {args.max_voltage:g} V: "
                       f"lower --level or raise --max-voltage")
    base = MeasurementPlan.from_template(args.template or "large-signal", n_periods=args.periods,
                                         period_samples=args.period, on_xrun=args.on_xrun)
    limits = StepLimits(args.max_excursion * 1e-3, args.max_voltage, args.max_distortion, args.max_temperature_rise)
    plan = LargeSignalPlan(base, args.level or base.level_v_rms, args.step, limits)
    cancel = threading.Event()
    with ExitStack() as stack:
        audio, laser, driver = devices.open_devices(args, stack)
        if args.sd is not None:
            driver = {**driver, "sd_m2": args.sd}
        plan = replace(plan, base=replace(plan.base, driver={k: v for k, v in driver.items() if v is not None}))
        say(f"large-signal plan from {plan.start_level_v:g} V, x{plan.step:g} per step, until "
            f"{args.max_excursion:g} mm, {args.max_voltage:g} V, {args.max_distortion:g} dB current distortion "
             f"or +{args.max_temperature_rise:g} K on {audio.describe()}")
        try:
            outcome = run_large_signal(plan, audio, devices.laser_sensor(laser), args.out, name=args.name,
                                       cancel=cancel, progress=devices.Progress(), on_step=_said_step)
        except KeyboardInterrupt:
            cancel.set()
            raise
    say(f"stopped: {outcome.message}; summary in {outcome.summary_path}")
    doc: dict = {"plan": {"summary": str(outcome.summary_path), "stopped_by": outcome.stopped_by,
                          "message": outcome.message, "recordings": [str(p) for p in outcome.recordings]}}
    text = None
    if outcome.recordings:
        try:
            result = large_signal(outcome.recordings)
            doc["large_signal"] = result.as_json()
            text = format_large_signal(result)
        except LargeSignalError as exc:
            doc["large_signal"], doc["error"] = None, str(exc)
            text = f"the steps could not be identified: {exc}"
    if args.json:
        print_json(doc)
    elif text:
        print(text)
    if outcome.stopped_by in ("fault", "cancelled"):
        raise CliError(f"{outcome.message} (the steps before are kept; summary in {outcome.summary_path})")
    return 0


def _said_step(step) -> None:
    m = step.measures
    peak = "no displacement" if m.peak_m is None else f"peak {m.peak_m * 1e3:.2f} mm"
    say(f"step {step.index} at {step.level_v:.3g} V: {peak}, current distortion {m.current_distortion_db:.1f} dB, "
        f"RE {m.re_ohm:.3f} ohm -> {step.recording_path}")
    if step.message:
        say(f"step {step.index} at {step.level_v:.3g} V: {step.message}")
