"""Journals whose measurement never finished: found, described, turned into recordings, or discarded.

``find_unfinished(OUT)`` lists the journals in OUT whose process has ended;
``recover`` replays one through capture()'s own PeriodCollector and the
runner's laser alignment and writes NAME.wav + NAME.json, marked partial
("ended_by": "crash"), the raw laser stream as NAME.laser.npz; ``discard``
removes one. The journal's files are instruments.measurement.recovery_journal's.
"""
from __future__ import annotations

import dataclasses
import json
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from analysis.recording.format import make_recording, write_recording
from analysis.serial_laser import DISPLACEMENT_MAX_KEY, SERIAL_LASER
from instruments.audio.captured import CLIP_LEVEL
from instruments.audio.config import Calibration, ChannelMap
from instruments.audio.periods import PeriodCollector
from instruments.audio.stream_core import XRUN_FLAGS, InputBlock
from instruments.laser.sensor import LaserBlock
from instruments.measurement.errors import MeasurementError
from instruments.measurement.plan import MeasurementPlan
from instruments.measurement.recovery_journal import (FADE_S, FORMAT, INDEX_RECORD, LASER_COLUMNS, LASER_HEAD,
                                                      SUFFIX, in_use, now_utc, recording_written)


class RecoveryError(MeasurementError):
    """A journal that cannot be turned into a recording (still running, too short, unreadable); one line."""


@dataclass(frozen=True)
class Unfinished:
    """A measurement whose process ended before its recording was written."""

    journal: Path
    name: str
    started_at: str            # ISO 8601, UTC
    periods: int               # whole periods of sound (with the serial laser, those it covers are kept)
    seconds: float             # of input in the journal
    serial_laser: bool
    driver: str
    problem: str = ""          # why it cannot become a recording; "" when it can

    @property
    def recording_path(self) -> Path:
        return self.journal.parent / f"{self.name}.wav"

    def describe(self) -> str:
        what = f"{self.name} ({self.driver or 'no driver name'}, started {self.started_at})"
        if self.problem:
            return f"{what}: {self.problem}"
        return f"{what}: {self.periods} whole period(s), {self.seconds:.1f} s of input, not yet a recording"


def find_unfinished(directory: Path | str) -> list[Unfinished]:
    """The journals in ``directory`` whose measuring process has ended, oldest first."""
    directory = Path(directory)
    if not directory.is_dir():
        return []
    found = [inspect(p) for p in sorted(directory.glob(f"*{SUFFIX}")) if p.is_dir() and not in_use(p)]
    return sorted(found, key=lambda u: u.started_at)


def inspect(journal: Path) -> Unfinished:
    """What a journal holds (whether or not its process still runs)."""
    journal = Path(journal)
    name = journal.name[:-len(SUFFIX)] if journal.name.endswith(SUFFIX) else journal.name
    try:
        meta = _meta(journal)
        replay = _replay(journal, meta)
    except (OSError, ValueError, KeyError, TypeError) as exc:
        return Unfinished(journal, name, "", 0, 0.0, False, "", f"the journal cannot be read ({exc})")
    periods = len(replay.collector.kept[:replay.plan.n_periods])
    problem = "" if periods >= 2 else f"only {periods} whole period(s) were measured: too few for a recording (2)"
    if recording_written(journal.parent / meta["name"]):
        problem = f"its recording {meta['name']}.wav was written; the journal is left over"
    return Unfinished(journal, meta["name"], meta["started_at"], periods, replay.samples / meta["sample_rate"],
                      meta["serial_laser"], str(meta["plan"].get("driver", {}).get("name", "")), problem)


def recover(unfinished: Unfinished) -> Path:
    """Write the journal's whole periods as a recording (partial, "ended_by": "crash"); its .wav. The journal goes.

    RecoveryError (one line) when it cannot be: still running, too short, or a journal that cannot be read.
    """
    journal = unfinished.journal
    if in_use(journal):
        raise RecoveryError(f"{journal}: the measurement is still running")
    try:        # the journal is a file like any other: what it holds is read here, once
        meta = _meta(journal)
        stem = journal.parent / meta["name"]
        if recording_written(stem):
            shutil.rmtree(journal)
            return stem.with_name(stem.name + ".wav")
        replay = _replay(journal, meta)
        recording, laser_info, blocks, starts = _recording_of(replay, meta)
    except (ValueError, KeyError, TypeError) as exc:
        raise RecoveryError(f"{journal}: the journal cannot be read ({type(exc).__name__}: {exc})") from None
    if recording is None:
        raise RecoveryError(f"{journal}: {inspect(journal).problem or 'nothing to recover'}")
    stem = _free_stem(stem)
    if laser_info is not None:
        from instruments.measurement.raw_stream import raw_capture_path, write_raw_capture
        write_raw_capture(raw_capture_path(stem), blocks, replay.arrivals, starts,
                          {"plan": meta["plan"], "audio_rate": meta["sample_rate"], "laser": laser_info,
                           "ended_by": "crash", "message": "recovered from the journal"})
    wav, _ = write_recording(stem, recording)
    shutil.rmtree(journal)
    return wav


def discard(unfinished: Unfinished) -> None:
    if in_use(unfinished.journal):
        raise RecoveryError(f"{unfinished.journal}: the measurement is still running")
    shutil.rmtree(unfinished.journal)


@dataclass
class _Replay:
    journal: Path
    plan: MeasurementPlan
    collector: PeriodCollector
    arrivals: tuple[np.ndarray, np.ndarray, np.ndarray]
    samples: int


def _meta(journal: Path) -> dict[str, Any]:
    meta = json.loads((journal / "journal.json").read_text(encoding="utf-8"))
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise ValueError(f"format {meta.get('format') if isinstance(meta, dict) else meta!r}, expected {FORMAT!r}")
    return meta


def _plan(meta: dict) -> MeasurementPlan:
    names = {f.name for f in dataclasses.fields(MeasurementPlan)}
    return MeasurementPlan(**{k: v for k, v in meta["plan"].items() if k in names})


def _replay(journal: Path, meta: dict) -> _Replay:
    """The journal's input through the collector capture() uses, as far as the files are whole."""
    plan = _plan(meta)
    n_inputs = ChannelMap.from_dict(meta["channel_map"]).n_inputs
    index = _read_records(journal / "audio.idx", INDEX_RECORD)
    data = np.fromfile(journal / "audio.f32", dtype="<f4")
    data = data[:data.size // n_inputs * n_inputs].reshape(-1, n_inputs)
    collector = PeriodCollector(plan.period_samples, n_inputs, plan.n_periods, plan.settle * plan.period_samples,
                                int(round(meta.get("fade_s", FADE_S) * meta["sample_rate"])))
    end_on_xrun = plan.end_on_xrun(meta["serial_laser"])
    offset, used = 0, 0
    for record in index:
        frames = int(record["frames"])
        if offset + frames > data.shape[0]:
            break                           # the samples of this block never reached the disk
        if end_on_xrun and record["flags"] & XRUN_FLAGS:
            break                           # the runner withholds the block of an xrun and what follows
        collector.add(InputBlock(int(record["start"]), data[offset:offset + frames], int(record["flags"])))
        offset += frames
        used += 1
    arrivals = (index["start"][:used].astype(np.int64), (index["start"] + index["frames"])[:used].astype(np.int64),
                index["time"][:used].astype(np.float64))
    return _Replay(journal, plan, collector, arrivals, offset)


def _recording_of(replay: _Replay, meta: dict):
    """(Recording or None, laser info or None, laser blocks, period starts) of a replayed journal."""
    plan, collector, fs = replay.plan, replay.collector, int(meta["sample_rate"])
    cm, cal = ChannelMap.from_dict(meta["channel_map"]), Calibration.from_dict(meta["calibration"])
    n = min(len(collector.kept), plan.n_periods)
    if n < 2:
        return None, None, [], np.zeros(0, np.int64)
    raw = collector.data()[:n * plan.period_samples]
    signals = {signal: cal.to_si(signal, raw[:, ch]) for signal, ch in cm.input_channels().items()}
    capture = {"full_scale_fraction": {s: float(np.max(np.abs(raw[:, ch]))) for s, ch in cm.input_channels().items()},
               "clipped_samples": {s: int(np.count_nonzero(np.abs(raw[:, ch]) >= CLIP_LEVEL))
                                   for s, ch in cm.input_channels().items()},
               "dropouts": {s: 0 for s in cm.input_channels()}, "xruns": 0}
    excited = plan.excitation(fs).excited_bins
    starts = (collector.kept_start + plan.period_samples * np.arange(n, dtype=np.int64)
              if collector.gaps == 0 else np.zeros(0, np.int64))
    extra: dict[str, Any] = {}
    laser_info, blocks, note = None, [], ""
    if meta["serial_laser"]:
        signals.pop("displacement", None)
        blocks = _laser_blocks(replay.journal / "laser.bin")
        laser_info, aligned, note = _aligned(blocks, replay, starts, plan, fs, excited)
        if aligned is not None:
            n = min(n, aligned.periods)
            signals = {s: v[:n * plan.period_samples] for s, v in signals.items()}
            signals["displacement"] = aligned.displacement[:n * plan.period_samples]
            capture.update(aligned.counts.capture_json())
            extra[DISPLACEMENT_MAX_KEY] = aligned.max_hz
            extra["laser_alignment"] = aligned.as_json(fs, plan.laser_rate_hz)
    message = (f"the workstation stopped during the measurement (started {meta['started_at']}); {n} whole "
               f"period(s) recovered from its journal{note}")
    extra = {"capture": capture, "measurement": {
        "plan": meta["plan"], "partial": True, "ended_by": "crash", "message": message, "periods": n,
        "audio": meta.get("device", ""), "recovered_at": now_utc(),
        "displacement_source": (SERIAL_LASER if "displacement" in signals and meta["serial_laser"] else
                                "sound card (laser analog)" if "displacement" in signals else "none"),
        "laser": laser_info}, **extra}
    if meta["plan"].get("calibration"):
        extra["calibration"] = dict(meta["plan"]["calibration"])
    recording = make_recording(fs, signals, plan.period_samples, 0, tuple(int(b) for b in excited),
                               dict(plan.driver), extra)
    return recording, laser_info, blocks, starts


def _aligned(blocks, replay: _Replay, starts: np.ndarray, plan: MeasurementPlan, fs: int, excited):
    from instruments.measurement.alignment import align_laser, stream_of_blocks
    info: dict[str, Any] = {"rate_hz": plan.laser_rate_hz, "failure": None}
    if starts.size == 0:
        return info, None, "; without displacement (the audio had gaps: its periods cannot be placed)"
    try:
        aligned = align_laser(stream_of_blocks(blocks), replay.arrivals[1], replay.arrivals[2], starts,
                              plan.period_samples, fs, plan.laser_rate_hz, excited, sign=plan.laser_sign,
                              latency_s=plan.laser_latency_s)
    except ValueError as exc:
        return info, None, f"; without displacement (the laser's stream cannot be aligned: {exc})"
    if aligned.periods < 2:
        return info, None, "; without displacement (the laser's stream covers fewer than 2 periods)"
    info["alignment"] = aligned.as_json(fs, plan.laser_rate_hz)
    info["counts"] = aligned.counts.capture_json()
    return info, aligned, ""


def _laser_blocks(path: Path) -> list[LaserBlock]:
    """The laser blocks of a journal, up to the first one the kill cut short."""
    raw = path.read_bytes() if path.exists() else b""
    blocks, at = [], 0
    width = sum(np.dtype(d).itemsize for _, d in LASER_COLUMNS)
    while at + LASER_HEAD.itemsize <= len(raw):
        n, host_time = np.frombuffer(raw, LASER_HEAD, 1, at)[0]
        body = at + LASER_HEAD.itemsize
        if n < 0 or body + int(n) * width > len(raw):
            break                            # the last block was cut by the kill
        columns, cursor = {}, body
        for name, dtype in LASER_COLUMNS:
            columns[name] = np.frombuffer(raw, dtype, int(n), cursor).copy()
            cursor += int(n) * np.dtype(dtype).itemsize
        columns["in_range"] = columns["in_range"].astype(bool)
        blocks.append(LaserBlock(host_time=float(host_time), **columns))
        at = cursor
    return blocks


# --- small helpers -------------------------------------------------------------------------------------

def _read_records(path: Path, dtype: np.dtype) -> np.ndarray:
    raw = path.read_bytes() if path.exists() else b""
    return np.frombuffer(raw[:len(raw) // dtype.itemsize * dtype.itemsize], dtype=dtype)


def _free_stem(stem: Path) -> Path:
    """``stem``, or stem-recovered, stem-recovered-2 ... when a recording of that name exists."""
    candidates = [stem] + [stem.with_name(f"{stem.name}-recovered" + (f"-{k}" if k > 1 else "")) for k in range(1, 100)]
    return next(c for c in candidates if not any(c.with_name(c.name + s).exists() for s in (".wav", ".json")))
