"""`linpar measure`: play, record, write the recording, then analyse it.

    linpar measure --out DIR [--rig virtual|soundcard] [--device NAME] [--calibration FILE]
                   [--laser URL|analog|none] [--template woofer|woofer-line|midrange|tweeter|microspeaker]
                   [--level VOLT] [--periods N] [--period SAMPLES] [--name NAME] [--model EFFECTS] [--sd M2]
                   [--on-xrun end|restart] [--serial TEXT] [--operator TEXT] [--station TEXT]
                   [--archive URL|DIR | --archive-root DIR | --no-archive] [--json]
                   [--plan single|large-signal [the plan's limits: app/cli/large_signal.py]]

With ``--rig virtual`` (the default) the virtual rig named ``--rig-name`` is
used, started first if it is not running and stopped at the end if this
command started it; the displacement comes from the rig's serial laser
emulator (its pty) unless ``--laser`` says otherwise (``analog``: the rig's
laser input on the sound card; ``none``: no displacement). With ``--rig
soundcard``, ``--device`` names the sound card and ``--calibration`` a JSON
file {"calibration": {...}, "channel_map": {...}} (instruments.audio.config).

The recording (NAME.wav + NAME.json, and NAME.laser.npz with the serial
laser) is written before anything is analysed. stdout gets what `linpar
analyze` prints (the same JSON with --json, validity included); progress and
the files written go to stderr. A measurement that a device ends (or Ctrl-C)
keeps what was recorded and exits with 2 and a message that says what
happened and where the data are.

The measurement is then stored in the measurement archive, a broken one too
(judged red with its remedies, as the GUI stores it)
(analysis.archive: ``--archive`` a postgresql:// URL or a folder, or
``--archive-root`` a folder; default $LINPAR_ARCHIVE_URL, else $LINPAR_ARCHIVE,
else the archive folder in the platform's data folder; ``--no-archive``: not stored) and stderr says
its id; when the archive has limits, the QA verdict it recorded is printed under the result, each
parameter's line too; with --json the printed object gets "archive": {"id", "root", "qa"} ("root":
the folder or the server's URL without its password; "queued": true when the
server could not be reached and the measurement waits in the station's local
queue, which is sent with the next store or `linpar archive sync`). When
storing fails (a read-only or full disk ...), nothing is lost, since the
recording is already written: a warning on stderr says why and how to store it
later (a ``linpar archive store`` command, shell-quoted, that keeps the time of
measuring), --json gets "archive": {"error", "root"},
and the exit code is 3 (EXIT_NOT_STORED): measured and analysed, not archived.
"""
from __future__ import annotations

import argparse
import dataclasses
import shlex
import signal
import sys
import threading
from contextlib import ExitStack, contextmanager
from datetime import datetime, timezone
from pathlib import Path
from typing import Iterator

from analysis.bounds import LEVEL_V_RMS, PERIOD_SAMPLES, PERIODS
from analysis.config_folder import data_folder
from analysis.errors import is_user_error, user_message
from app.cli import devices, large_signal
from app.cli.devices import LASER_ANALOG, say
from app.cli.options import (SERIAL_LASER_MODEL, CliError, add_json_option, add_model_option, add_sd_option,
                             model_effects, name_text, number)
from app.cli.output import print_json
from instruments.measurement.plan import TEMPLATES, MeasurementPlan

EXIT_NOT_STORED, EXIT_INTERRUPTED = 3, 130


def register(sub) -> None:
    m = sub.add_parser("measure", help="measure a driver: play, record, write the recording, analyse it")
    m.add_argument("--out", required=True, type=Path, metavar="DIR", help="folder for the recording")
    m.add_argument("--name", help="file name of the recording (default: measurement-DATE-TIME)")
    m.add_argument("--rig", choices=("virtual", "soundcard"), default="virtual",
                   help="the virtual rig (default), or a real sound card")
    m.add_argument("--rig-name", default="linpar", help="name of the virtual rig (default %(default)s)")
    m.add_argument("--runtime-dir", type=Path, help=argparse.SUPPRESS)
    m.add_argument("--device", metavar="NAME", help="sound card name (with --rig soundcard)")
    m.add_argument("--calibration", type=Path, metavar="FILE",
                   help='JSON {"calibration": {...}, "channel_map": {...}} of the sound card (--rig soundcard)')
    m.add_argument("--laser", metavar="URL", help="serial laser port or pyserial URL; 'analog': the laser's "
                                                  "analog output on the sound card; 'none': no displacement")
    m.add_argument("--template", choices=tuple(TEMPLATES),
                   help="driver class (default woofer; large-signal with --plan large-signal)")
    m.add_argument("--level", type=number(LEVEL_V_RMS), metavar="VOLT",
                   help="excitation level, V RMS at the terminals")
    m.add_argument("--periods", type=number(PERIODS), metavar="N", help="periods averaged")
    m.add_argument("--period", type=number(PERIOD_SAMPLES), metavar="SAMPLES", help="period length, a power of two")
    add_sd_option(m)
    m.add_argument("--on-xrun", choices=("end", "restart"),
                   help="an xrun while periods are kept: end the measurement, keeping them (the default with the "
                        "serial laser), or average again")
    add_model_option(m, why=SERIAL_LASER_MODEL)
    for field in ("serial", "operator", "station"):
        m.add_argument(f"--{field}", default="", metavar="TEXT", type=name_text, help=f"the {field} kept with it in the archive")
    where = m.add_mutually_exclusive_group()
    where.add_argument("--archive", metavar="URL|DIR",
                       help="archive to store in: postgresql://USER@HOST[:PORT]/DB (the line's server) or a folder "
                            f"(default: $LINPAR_ARCHIVE_URL, else $LINPAR_ARCHIVE, else {data_folder() / 'archive'})")
    where.add_argument("--archive-root", type=Path, metavar="DIR",
                       help=f"archive to store the measurement in (default: $LINPAR_ARCHIVE or "
                            f"{data_folder() / 'archive'}); exit 3 when it cannot be stored")
    where.add_argument("--no-archive", action="store_true", help="do not store the measurement in the archive")
    add_json_option(m)
    large_signal.add_plan_options(m)
    m.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """One measurement (the single plan), or the large-signal plan's steps (app.cli.large_signal)."""
    if args.plan == "large-signal":
        return large_signal.run_plan(args)
    from instruments.measurement.recovery import find_unfinished, run_journaled
    from instruments.measurement.runner import MeasurementCancelled

    large_signal.plan_options_checked(args)     # a large-signal limit given to this single measurement is refused
    effects = model_effects(args.model)
    if not args.no_archive:     # a mistyped archive is said now, not after the measurement (nothing connects yet)
        from analysis.archive.backends import archive_spec, check_spec
        if args.archive is not None and not args.archive.strip():
            raise CliError("--archive: empty: give a folder or postgresql://USER@HOST[:PORT]/DATABASE")
        check_spec(archive_spec(args.archive or (str(args.archive_root) if args.archive_root else None)))
    for unfinished in find_unfinished(args.out):
        say(f"note: a measurement was cut short: {unfinished.describe()}; its data are in {unfinished.journal} "
            f"('linpar recover {args.out}' keeps, analyses or discards it)")
    # The plan first: a plan that cannot work must not start a rig.
    plan = MeasurementPlan.from_template(args.template or "woofer", level_v_rms=args.level, n_periods=args.periods,
                                         period_samples=args.period, on_xrun=args.on_xrun)
    with ExitStack() as stack:
        audio, laser, driver = devices.open_devices(args, stack)
        if args.sd is not None:
            driver = {**driver, "sd_m2": args.sd}
        if args.serial:
            driver = {**driver, "serial": args.serial}
        # Who, where, when, with what: into the recording's sidecar (analysis.session), and from there on.
        from analysis.session import new_session
        plan = dataclasses.replace(plan, driver={k: v for k, v in driver.items() if v is not None},
                                   session=new_session(args.operator or "", args.station or "", plan.template))
        cancel = _Cancel()
        say(f"measuring: {plan.template}, {plan.level_v_rms:g} V RMS, {plan.n_periods} periods of "
            f"{plan.period_samples} samples after {plan.settle} to settle (~{plan.duration_s(audio.sample_rate):.0f} s"
             f" of sound) on {audio.describe()}" + (f", laser {laser!r}" if laser is not None else ""))
        try:
            with _ctrl_c_cancels(cancel):
                outcome = run_journaled(plan, audio, devices.laser_sensor(laser), args.out, name=args.name,
                                        cancel=cancel, progress=devices.Progress(), effects=effects)
            # The recording carries no date, and a store later would be dated then (--measured-at).
            measured_at = datetime.now(timezone.utc).isoformat(timespec="seconds")
        except MeasurementCancelled as exc:
            if not cancel.interrupted:
                raise
            # Ctrl-C: what was captured is written (marked partial), as when a device fails.
            print(f"linpar: interrupted: {exc}", file=sys.stderr)
            return EXIT_INTERRUPTED
        except KeyboardInterrupt:       # a second Ctrl-C: the journal keeps what was measured
            cancel.set()
            say(f"interrupted twice: what was measured is in the journal in {args.out}; 'linpar recover "
                f"{args.out}' makes it a recording")
            raise
    for path in (outcome.recording_path, outcome.sidecar_path, outcome.raw_path):
        if path is not None:
            say(f"wrote {path}")
    outcome = _with_model_part(outcome)
    archived = None if args.no_archive else _store(args, outcome, plan, measured_at)
    result = outcome.result
    words = archived.pop("qa_words", "") if archived is not None else ""
    if args.json:
        doc = result.as_json()
        if archived is not None:
            doc = {**doc, "archive": archived}
        print_json(doc)
    else:
        print(result.report())
        if words:                   # the verdict the archive recorded, under the numbers it judged
            print("\n" + words)
    return EXIT_NOT_STORED if archived is not None and "error" in archived else 0


def _with_model_part(outcome):
    """The outcome with its result's model part (analysis.fit.model_uncertainty), inline: what is printed and
    what is stored are then the same numbers `linpar analyze` and the GUI give for this recording."""
    from analysis.fit.model_uncertainty import model_uncertainty, pending
    if outcome.result is None:
        return outcome
    if pending(outcome.result):
        say("the model misses the measurement beyond its noise: refitting with the other forms of its "
            "inductance and creep for the model part of the uncertainties")
    return dataclasses.replace(outcome, result=model_uncertainty(outcome.result))


class _Cancel(threading.Event):
    """The measurement's cancel event, which knows whether Ctrl-C set it."""

    interrupted = False


@contextmanager
def _ctrl_c_cancels(cancel: _Cancel) -> Iterator[None]:
    """The first Ctrl-C cancels the measurement (its periods are written, marked partial); a second one
    interrupts at once (the journal keeps the data). Only in the main thread, where signals arrive."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def on_sigint(signum, frame):
        if cancel.is_set():
            raise KeyboardInterrupt
        cancel.interrupted = True
        cancel.set()
        say("Ctrl-C: stopping; the periods measured so far are written (Ctrl-C again to stop at once)")
    previous = signal.signal(signal.SIGINT, on_sigint)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _store(args: argparse.Namespace, outcome, plan: MeasurementPlan, measured_at: str) -> dict:
    """Store the measurement in the archive: {"id", "root"}, or {"error", "root"} and a warning (module doc)."""
    from analysis.archive.backends import archive_spec, open_archive, shown
    spec = archive_spec(args.archive or (str(Path(args.archive_root).expanduser()) if args.archive_root else None))
    root = shown(spec)
    # A broken measurement (nothing fitted) is stored too, judged red with its remedies, as the GUI stores it.
    meta = {"serial": args.serial, "operator": args.operator, "station": args.station, "measured_at": measured_at,
            "settings": {"template": plan.template, "rig": args.rig,
                         "laser": "serial" if outcome.raw_path is not None else (args.laser or LASER_ANALOG)}}
    archive = None
    try:
        archive = open_archive(spec)
        root = archive.location
        mid = archive.store(outcome.recording_path, outcome.result, meta, laser_stream=outcome.raw_path)
    except Exception as exc:  # noqa: BLE001 - whatever went wrong, the recording is on disk: say so, lose nothing
        if is_user_error(exc):
            why = user_message(exc)
        else:
            from app.crash_report import internal_error_line
            why = internal_error_line(exc, "storing the measurement in the archive")
        if getattr(exc, "queued_id", None):     # refused by the server, kept in the station's queue: not twice
            say(f"warning: not stored in the archive {root}: {why}")
            return {"error": why, "root": str(root), "queued": exc.queued_id}
        say(f"warning: not stored in the archive {root}: {why}. The recording is kept in "
            f"{outcome.recording_path}; store it later with: {_store_later(args, outcome, root, measured_at)}")
        return {"error": why, "root": str(root)}
    finally:
        for note in archive.notes if archive is not None else ():
            say(f"note: {note}")
    if archive.pending:
        say(f"measured as {mid}; it waits in this station's queue until the server {root} can be reached")
        return {"id": mid, "root": str(root), "queued": True}
    judged = "" if outcome.result.fit is not None else f" (judged {outcome.result.validity.overall}: nothing " \
                                                       "could be fitted)"
    say(f"stored in the archive {root} as {mid}{judged}")
    from app.cli.stored_verdict import stored_verdict
    qa, words = stored_verdict(archive, mid, outcome.result)
    return {"id": mid, "root": str(root), **({"qa": qa, "qa_words": words} if qa is not None else {})}


def _store_later(args: argparse.Namespace, outcome, root: str, measured_at: str) -> str:
    """The `linpar archive store` command that stores this measurement as this command would have (shell-quoted)."""
    fit = outcome.result.fit
    effects = ",".join(fit.model.effect_ids if fit is not None else ()) or "none"
    command = ["linpar", "archive", "store", str(outcome.recording_path.with_suffix("")), "--model", effects]
    if outcome.raw_path is not None:
        command += ["--laser-stream", str(outcome.raw_path)]
    for key in ("serial", "operator", "station"):
        command += [f"--{key}", getattr(args, key)] if getattr(args, key) else []
    where = "--archive" if "://" in root else "--root"
    return shlex.join(command + ["--measured-at", measured_at, where, str(root)])
