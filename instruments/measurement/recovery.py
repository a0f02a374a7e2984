"""Measurements cut short by a crash: their input on disk as it arrives, found again on the next start.

run_measurement writes the recording once the capture has ended. A process
that dies before (killed, a power cut, a crash inside a library) would leave
nothing of what it measured. ``run_journaled`` runs it with a journal beside
the recording-to-be, ``OUT/NAME.unfinished/``:

    journal.json   what is measured and how: the plan, sample rate, channel map, calibration, device
    audio.f32      every input block from the sound card as it arrives: frames x inputs, float32 full scale
    audio.idx      per block: first sample index, frames, status flags, host arrival time
    laser.bin      each block of the serial laser as it arrives (only with a serial laser)
    lock           held (flock) by the measuring process while it runs

A writer thread appends and flushes what the device threads hand it (they
only enqueue, never wait for the disk) and fsyncs about once a second: a
kill loses only what was still queued (milliseconds), a power cut about the
last second. A journal that cannot be written (disk full) stops quietly;
the measurement goes on.

When run_measurement returns, or raises MeasurementError (it then either
recorded nothing, or wrote what it kept, marked partial), the journal is
removed. Any other end (an exception, Ctrl-C, a kill) leaves it. On the
next start ``find_unfinished(OUT)`` lists such journals, skipping those
whose process still runs (the lock is free only once it is gone);
``recover`` replays the input through capture()'s own PeriodCollector and
the runner's laser alignment and writes NAME.wav + NAME.json, marked partial
("ended_by": "crash"), the raw laser stream as NAME.laser.npz; ``discard``
removes a journal.

The journal's writer is recovery_journal.py, its reader recovery_replay.py;
their public names are importable from here.
"""
from __future__ import annotations

from datetime import datetime
from pathlib import Path

from analysis.errors import LinparError
from instruments.measurement.plan import MeasurementPlan
from instruments.measurement.recovery_journal import (FADE_S, FORMAT, FSYNC_EVERY_S, QUEUE_ITEMS, SUFFIX, Journal,
                                                      journal_path, recording_written)
from instruments.measurement.recovery_replay import (CLIP_LEVEL, RecoveryError, Unfinished, discard, find_unfinished,
                                                     inspect, recover)
from instruments.measurement.runner import MeasurementError, MeasurementOutcome, run_measurement

__all__ = ["CLIP_LEVEL", "FADE_S", "FORMAT", "FSYNC_EVERY_S", "QUEUE_ITEMS", "SUFFIX", "Journal", "JournalKept",
           "RecoveryError", "Unfinished", "default_name", "discard", "find_unfinished", "inspect", "journal_path", "recover",
           "run_journaled"]


class JournalKept(LinparError, OSError):
    """The recording could not be written (a full disk ...): the measurement is in its journal. One line."""


def default_name() -> str:
    """As run_measurement names a recording when it is given no name."""
    return datetime.now().strftime("measurement-%Y%m%d-%H%M%S")


def run_journaled(plan: MeasurementPlan, audio, laser=None, out_dir: Path | str = ".", *, name: str | None = None,
                  **kwargs) -> MeasurementOutcome:
    """run_measurement (same arguments and outcome) with a journal that survives the process (module doc).

    A folder that cannot be written is a MeasurementError before anything plays; a recording that cannot
    be written at the end (disk full, read-only) is a JournalKept (an OSError) saying where the data are.
    """
    out_dir = Path(out_dir)
    name = name or default_name()
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        journal = Journal.create(out_dir, name, plan, audio, serial_laser=laser is not None)
    except OSError as exc:
        if isinstance(exc, FileExistsError) and journal_path(out_dir, name).is_dir():
            raise MeasurementError(f"{journal_path(out_dir, name)}: an unfinished measurement of that name is "
                                   f"there; recover or discard it first, or choose another name") from None
        raise MeasurementError(f"{out_dir}: cannot be written ({exc.strerror or exc}); nothing was measured") from exc
    try:
        outcome = run_measurement(plan, journal.audio(audio), journal.laser(laser), out_dir, name=name, **kwargs)
    except MeasurementError:
        journal.close(keep=False)     # nothing was recorded, or what was kept is written (partial)
        raise
    except OSError as exc:
        if not journal.close(keep=not recording_written(out_dir / name)):
            raise
        where = (f"kept in {journal.path}: make room and recover it" if journal.failure is None else
                 f"only partly kept in {journal.path} ({journal.failure})")
        raise JournalKept(exc.errno, f"the recording could not be written ({exc.strerror or exc}"
                                     f"{': ' + str(exc.filename) if exc.filename else ''}); what was measured is "
                                     f"{where}") from exc
    except BaseException:
        journal.close(keep=not recording_written(out_dir / name))
        raise
    journal.close(keep=False)
    return outcome
