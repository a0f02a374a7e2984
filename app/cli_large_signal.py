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
import math
import sys
from pathlib import Path

PLANS = ("single", "large-signal")
SUMMARY_SUFFIX = ".large-signal.json"
OUTPUTS = (("pdf", "write the report as PDF"), ("html", "write the report as HTML (self-contained)"),
           ("csv", "write the curves as CSV (x, Bl, Kms, Cms, Le with 1-sigma across the measured range)"),
           ("export-json", "write the JSON (as --json prints it) to FILE"))


def _number(low: float, high: float, what: str):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from None
        if not (math.isfinite(value) and low <= value <= high):
            raise argparse.ArgumentTypeError(f"expected {what} from {low:g} to {high:g}, got {text!r}")
        return value
    return parse


def _order(text: str) -> int:
    from analysis.large_signal.identify import HIGHEST_ORDER
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if not 0 <= value <= HIGHEST_ORDER:
        raise argparse.ArgumentTypeError(f"expected an order from 0 to {HIGHEST_ORDER}, got {text!r}")
    return value


def _two_tones(text: str) -> tuple[float, float]:
    parts = [p for p in text.split(",") if p.strip()]
    parse = _number(1.0, 20000.0, "a frequency in Hz")
    if len(parts) != 2:
        raise argparse.ArgumentTypeError(f"expected two frequencies F1,F2 in Hz (F1 < F2), got {text!r}")
    f1, f2 = (parse(p) for p in parts)
    if not f1 < f2:
        raise argparse.ArgumentTypeError(f"expected F1 < F2, got {text!r}")
    return f1, f2


def add_commands(sub) -> None:
    c = sub.add_parser("large-signal", help="Bl(x), Kms(x), Le(x), the coil's rest offset and the excursion limits")
    c.add_argument("paths", nargs="+", metavar="REC",
                   help="recordings of one driver at large signal (NAME, NAME.wav or NAME.json), or a plan's "
                        "NAME.large-signal.json")
    c.add_argument("--order", type=_order, default=6, metavar="N",
                   help="highest polynomial order BIC may choose for Bl, Kms, Le (default %(default)s)")
    c.add_argument("--bl-min", type=_number(1.0, 99.0, "a percentage"), default=82.0, metavar="PCT",
                   help="X_Bl: the excursion where Bl falls to PCT %% of Bl(0) (default %(default)g, Klippel)")
    c.add_argument("--cms-min", type=_number(1.0, 99.0, "a percentage"), default=75.0, metavar="PCT",
                   help="X_C: where the compliance falls to PCT %% of Cms(0) (default %(default)g)")
    c.add_argument("--le-change", type=_number(1.0, 99.0, "a percentage"), default=10.0, metavar="PCT",
                   help="X_L: where Le leaves Le(0) by PCT %% (default %(default)g, after IEC 62458)")
    c.add_argument("--predict", type=_number(1e-3, 200.0, "a level in V RMS"), metavar="VOLT",
                   help="predict the distortion at this level (V RMS): the multitone, and --sine / --two-tones")
    c.add_argument("--sine", type=_number(1.0, 20000.0, "a frequency in Hz"), metavar="HZ",
                   help="with --predict: H2 and H3 of current and displacement for a sine at HZ")
    c.add_argument("--two-tones", type=_two_tones, metavar="F1,F2",
                   help="with --predict: IMD2 and IMD3 for two tones F1 + F2 (amplitudes 4:1)")
    c.add_argument("--json", action="store_true", help="print one JSON object")
    for option, what in OUTPUTS:
        c.add_argument(f"--{option}", type=Path, metavar="FILE", help=what)


def add_plan_options(measure: argparse.ArgumentParser) -> None:
    """measure's --plan and the large-signal plan's limits."""
    measure.add_argument("--plan", choices=PLANS, default="single",
                         help="'single': one measurement (default); 'large-signal': steps up the level until a "
                              "limit, each step a recording, then identifies Bl(x), Kms(x), Le(x)")
    measure.add_argument("--max-excursion", type=_number(0.01, 50.0, "a peak excursion in mm"), default=4.0,
                         metavar="MM", help="large-signal plan: stop at this peak excursion (default %(default)g mm)")
    measure.add_argument("--max-voltage", type=_number(0.001, 200.0, "a level in V RMS"), default=10.0,
                         metavar="VOLT", help="large-signal plan: never above this level (default %(default)g V RMS)")
    measure.add_argument("--max-distortion", type=_number(-80.0, 0.0, "a level in dB"), default=-20.0,
                         metavar="DB", help="large-signal plan: stop when the current's distortion reaches DB re "
                                            "the signal (default %(default)g dB)")
    measure.add_argument("--max-temperature-rise", type=_number(0.1, 200.0, "a temperature rise in K"),
                         default=20.0, metavar="K",
                         help="large-signal plan: stop when the voice coil warmed by K kelvin (RE per period; "
                              "default %(default)g K)")
    measure.add_argument("--step", type=_number(1.05, 4.0, "a factor"), default=1.41, metavar="FACTOR",
                         help="large-signal plan: level factor per step (default %(default)g, +3 dB)")


def user_errors() -> tuple[type[BaseException], ...]:
    """Errors shown to the user as one line (exit 2) by app.cli."""
    from analysis.large_signal import LargeSignalError
    from analysis.recording import RecordingError
    return (LargeSignalError, RecordingError, ValueError, OSError)


def run(args: argparse.Namespace) -> int:
    from analysis.large_signal import LimitThresholds, Prediction, large_signal
    from analysis.large_signal.words import format_large_signal
    from app.cli import CliError
    from app.cli_import import _print_json
    if (args.sine is not None or args.two_tones is not None) and args.predict is None:
        raise CliError("--sine and --two-tones need --predict VOLT (the level to predict at)")
    thresholds = LimitThresholds(args.bl_min / 100.0, args.cms_min / 100.0, args.le_change / 100.0)
    predictions = [] if args.predict is None else [Prediction(args.predict, args.sine, args.two_tones)]
    inputs = expand(args.paths)
    outputs = checked_outputs(args, inputs)          # before the identification: a mistake costs nothing
    result = large_signal(inputs, args.order, thresholds, predictions)
    if args.json:
        _print_json(result.as_json())
    else:
        print(format_large_signal(result))
    for path in write_outputs(result, outputs):
        print(f"written: {path}", file=sys.stderr)
    return 0


def checked_outputs(args: argparse.Namespace, inputs) -> dict[str, Path]:
    """The files to write, refused (ValueError, one line) when one would replace an input of this command or
    something that is not a regular file."""
    from analysis.recording import recording_paths
    taken = set()
    for path in inputs:
        try:
            taken.update(p.resolve() for p in recording_paths(path))
        except (OSError, ValueError):
            taken.add(Path(path).resolve())
    outputs = {}
    for option, _ in OUTPUTS:
        path = getattr(args, option.replace("-", "_"))
        if path is None:
            continue
        if path.resolve() in taken:
            raise ValueError(f"--{option} {path}: that is one of the recordings read: choose another file")
        if path.exists() and not path.is_file():
            raise ValueError(f"--{option} {path}: not a regular file")
        if path.resolve() in {p.resolve() for p in outputs.values()}:
            raise ValueError(f"--{option} {path}: already named for another output")
        outputs[option] = path
    return outputs


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
    import json
    from analysis.large_signal import LargeSignalError
    out = []
    for text in paths:
        path = Path(text)
        if not path.name.endswith(SUMMARY_SUFFIX):
            out.append(path)
            continue
        try:
            doc = json.loads(path.read_text(encoding="utf-8"))
            steps = [s for s in doc["steps"] if s.get("recording") and s.get("usable", not s.get("partial"))]
        except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError, AttributeError) as exc:
            raise LargeSignalError(f"{path}: not a readable large-signal plan summary ({exc})") from None
        if not steps:
            raise LargeSignalError(f"{path}: the plan recorded no complete step")
        out += [path.parent / str(s["recording"]) for s in steps]
    return out


def run_plan(args: argparse.Namespace) -> int:
    """`linpar measure --plan large-signal` (module doc)."""
    import threading
    from contextlib import ExitStack
    from dataclasses import replace

    from analysis.large_signal import LargeSignalError, large_signal
    from analysis.large_signal.stepping import StepLimits
    from analysis.large_signal.words import format_large_signal
    from app import cli_measure
    from app.cli import CliError
    from app.cli_import import _print_json
    from instruments.measurement.large_signal_plan import LargeSignalPlan, run_large_signal
    from instruments.measurement.plan import MeasurementPlan

    base = MeasurementPlan.from_template(args.template or "large-signal", n_periods=args.periods,
                                         period_samples=args.period, on_xrun=args.on_xrun)
    limits = StepLimits(args.max_excursion * 1e-3, args.max_voltage, args.max_distortion, args.max_temperature_rise)
    plan = LargeSignalPlan(base, args.level or base.level_v_rms, args.step, limits)
    cancel = threading.Event()
    with ExitStack() as stack:
        audio, laser, driver = cli_measure._devices(args, stack)
        if args.sd is not None:
            driver = {**driver, "sd_m2": args.sd}
        plan = replace(plan, base=replace(plan.base, driver={k: v for k, v in driver.items() if v is not None}))
        _say(f"large-signal plan from {plan.start_level_v:g} V, x{plan.step:g} per step, until "
             f"{args.max_excursion:g} mm, {args.max_voltage:g} V, {args.max_distortion:g} dB current distortion "
             f"or +{args.max_temperature_rise:g} K on {audio.describe()}")
        try:
            outcome = run_large_signal(plan, audio, cli_measure._laser_sensor(laser), args.out, name=args.name,
                                       cancel=cancel, progress=cli_measure._Progress(), on_step=_said_step)
        except KeyboardInterrupt:
            cancel.set()
            raise
    _say(f"stopped: {outcome.message}; summary in {outcome.summary_path}")
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
        _print_json(doc)
    elif text:
        print(text)
    if outcome.stopped_by in ("fault", "cancelled"):
        raise CliError(f"{outcome.message} (the steps before are kept; summary in {outcome.summary_path})")
    return 0


def _said_step(step) -> None:
    m = step.measures
    peak = "no displacement" if m.peak_m is None else f"peak {m.peak_m * 1e3:.2f} mm"
    _say(f"step {step.index} at {step.level_v:.3g} V: {peak}, current distortion {m.current_distortion_db:.1f} dB, "
         f"RE {m.re_ohm:.3f} ohm -> {step.recording_path}")


def _say(text: str) -> None:
    print(f"linpar measure: {text}", file=sys.stderr, flush=True)
