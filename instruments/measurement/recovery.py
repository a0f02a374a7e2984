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
"""
from __future__ import annotations

import dataclasses
import fcntl
import json
import os
import queue
import shutil
import socket
import threading
import time
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np

from analysis.archive.atomic import write_atomic
from analysis.recording import make_recording, write_recording
from instruments.audio.config import Calibration, ChannelMap
from instruments.audio.periods import PeriodCollector
from instruments.audio.stream_core import XRUN_FLAGS, InputBlock
from instruments.laser.sensor import LaserBlock
from instruments.measurement.plan import MeasurementPlan
from instruments.measurement.runner import MeasurementError, MeasurementOutcome, run_measurement

FORMAT = "linpar-journal/1"
SUFFIX = ".unfinished"
FADE_S = 0.1                 # capture()'s fade-in, which run_measurement keeps
CLIP_LEVEL = 0.999           # as instruments.audio.capture
FSYNC_EVERY_S = 1.0
QUEUE_ITEMS = 8192           # blocks waiting for the disk; beyond, the journal gives up rather than the audio
_IDX = np.dtype([("start", "<i8"), ("frames", "<i8"), ("flags", "<i8"), ("time", "<f8")])
_LASER_HEAD = np.dtype([("n", "<i8"), ("time", "<f8")])
_LASER_COLUMNS = (("counter", "<i8"), ("timestamp_ms", "<f8"), ("distance_m", "<f8"), ("error_code", "<i4"),
                  ("in_range", "u1"))


class JournalKept(OSError):
    """The recording could not be written (a full disk ...): the measurement is in its journal. One line."""


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


def journal_path(out_dir: Path | str, name: str) -> Path:
    return Path(out_dir) / f"{name}{SUFFIX}"


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
        if not journal.close(keep=not _recording_written(out_dir / name)):
            raise
        where = (f"kept in {journal.path}: make room and recover it" if journal.failure is None else
                 f"only partly kept in {journal.path} ({journal.failure})")
        raise JournalKept(exc.errno, f"the recording could not be written ({exc.strerror or exc}"
                                     f"{': ' + str(exc.filename) if exc.filename else ''}); what was measured is "
                                     f"{where}") from exc
    except BaseException:
        journal.close(keep=not _recording_written(out_dir / name))
        raise
    journal.close(keep=False)
    return outcome


def _recording_written(stem: Path) -> bool:
    return stem.with_name(stem.name + ".wav").is_file() and stem.with_name(stem.name + ".json").is_file()


# --- writing ----------------------------------------------------------------------------------------------

class Journal:
    """The journal of one running measurement; ``audio`` and ``laser`` wrap the devices so that it sees their data."""

    def __init__(self, path: Path):
        self.path = path
        self.failure: str | None = None      # NB: set by the writer thread
        self.dropped = 0                     # NB: blocks the queue had no room for (counted by device threads)
        self._queue: queue.Queue = queue.Queue(maxsize=QUEUE_ITEMS)
        self._files: dict[str, int] = {}
        self._lock_fd: int | None = None
        self._thread: threading.Thread | None = None

    @classmethod
    def create(cls, out_dir: Path, name: str, plan: MeasurementPlan, audio, serial_laser: bool) -> "Journal":
        path = journal_path(out_dir, name)
        path.mkdir()                         # FileExistsError: a journal of that name is still there
        journal = cls(path)
        try:
            journal._lock_fd = os.open(path / "lock", os.O_CREAT | os.O_RDWR, 0o644)
            fcntl.flock(journal._lock_fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            meta = {"format": FORMAT, "name": name, "started_at": _now(), "host": socket.gethostname(),
                    "pid": os.getpid(), "plan": plan.as_json(), "sample_rate": int(audio.sample_rate),
                    "channel_map": audio.channel_map.to_dict(), "calibration": audio.calibration.to_dict(),
                    "device": audio.describe(), "serial_laser": bool(serial_laser), "fade_s": FADE_S}
            write_atomic(path / "journal.json", json.dumps(meta, indent=1))
            for role in ("audio.f32", "audio.idx") + (("laser.bin",) if serial_laser else ()):
                journal._files[role] = os.open(path / role, os.O_CREAT | os.O_WRONLY | os.O_APPEND, 0o644)
        except BaseException:
            journal.close(keep=False)        # no writer yet: only what was opened is released
            raise
        journal._thread = threading.Thread(target=journal._run, name="measurement-journal", daemon=True)
        journal._thread.start()
        return journal

    def audio(self, audio) -> "_Tee":
        return _Tee(audio, self)

    def laser(self, laser) -> "_Tee | None":
        return None if laser is None else _Tee(laser, self)

    def put(self, item) -> None:
        try:
            self._queue.put_nowait(item)
        except queue.Full:
            self.dropped += 1

    def close(self, keep: bool) -> bool:
        """Stop writing; remove the journal unless ``keep``. True when the journal was kept."""
        self._queue.put(None)
        if self._thread is not None:
            self._thread.join(10.0)
        for fd in self._files.values():
            try:
                os.fsync(fd)
            except OSError:
                pass
            os.close(fd)
        self._files.clear()
        if self._lock_fd is not None:
            os.close(self._lock_fd)          # frees the lock: from now on find_unfinished sees the journal
            self._lock_fd = None
        if not keep:
            shutil.rmtree(self.path, ignore_errors=True)
        return keep

    def _run(self) -> None:
        synced = time.monotonic()
        while (item := self._queue.get()) is not None:
            if self.failure is not None:
                continue
            try:
                self._write(*item)
                if time.monotonic() - synced > FSYNC_EVERY_S:
                    for fd in self._files.values():
                        os.fsync(fd)
                    synced = time.monotonic()
            except OSError as exc:           # a full disk must not end the measurement: the journal gives up
                self.failure = f"the journal {self.path} could not be written: {exc.strerror or exc}"

    def _write(self, kind: str, payload, host_time: float) -> None:
        if kind == "audio":
            for block in payload:
                frames = np.ascontiguousarray(block.samples, dtype="<f4")
                _write_all(self._files["audio.f32"], frames.tobytes())
                record = np.array([(block.start, frames.shape[0], block.flags, host_time)], dtype=_IDX)
                _write_all(self._files["audio.idx"], record.tobytes())     # after the samples it describes
        else:
            block: LaserBlock = payload
            head = np.array([(len(block), block.host_time)], dtype=_LASER_HEAD).tobytes()
            body = b"".join(np.ascontiguousarray(getattr(block, name), dtype=dtype).tobytes()
                            for name, dtype in _LASER_COLUMNS)
            _write_all(self._files["laser.bin"], head + body)


class _Tee:
    """The device it wraps (an AudioInterface or a DisplacementSensor), whose blocks the journal sees too."""

    def __init__(self, inner, journal: Journal):
        self._inner = inner
        self._journal = journal

    def __getattr__(self, name: str):
        return getattr(self._inner, name)

    def read_blocks(self, timeout: float) -> tuple[InputBlock, ...]:
        blocks = self._inner.read_blocks(timeout)
        if blocks:
            self._journal.put(("audio", blocks, time.monotonic()))
        return blocks

    def read_block(self, timeout: float) -> LaserBlock | None:
        block = self._inner.read_block(timeout)
        if block is not None and len(block):
            self._journal.put(("laser", block, block.host_time))
        return block


# --- finding and recovering ---------------------------------------------------------------------------

def find_unfinished(directory: Path | str) -> list[Unfinished]:
    """The journals in ``directory`` whose measuring process has ended, oldest first."""
    directory = Path(directory)
    if not directory.is_dir():
        return []
    found = [inspect(p) for p in sorted(directory.glob(f"*{SUFFIX}")) if p.is_dir() and not _in_use(p)]
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
    if _recording_written(journal.parent / meta["name"]):
        problem = f"its recording {meta['name']}.wav was written; the journal is left over"
    return Unfinished(journal, meta["name"], meta["started_at"], periods, replay.samples / meta["sample_rate"],
                      meta["serial_laser"], str(meta["plan"].get("driver", {}).get("name", "")), problem)


def recover(unfinished: Unfinished) -> Path:
    """Write the journal's whole periods as a recording (partial, "ended_by": "crash"); its .wav. The journal goes."""
    journal = unfinished.journal
    if _in_use(journal):
        raise ValueError(f"{journal}: the measurement is still running")
    meta = _meta(journal)
    stem = journal.parent / meta["name"]
    if _recording_written(stem):
        shutil.rmtree(journal)
        return stem.with_name(stem.name + ".wav")
    replay = _replay(journal, meta)
    recording, laser_info, blocks, starts = _recording_of(replay, meta)
    if recording is None:
        raise ValueError(f"{journal}: {inspect(journal).problem or 'nothing to recover'}")
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
    if _in_use(unfinished.journal):
        raise ValueError(f"{unfinished.journal}: the measurement is still running")
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
    index = _read_records(journal / "audio.idx", _IDX)
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
            counts = aligned.counts.capture_json()
            capture["dropouts"] = {**capture["dropouts"], **counts.pop("dropouts")}
            capture.update(counts)
            from instruments.measurement.analysis_step import DISPLACEMENT_MAX_KEY
            extra[DISPLACEMENT_MAX_KEY] = aligned.max_hz
            extra["laser_alignment"] = aligned.as_json(fs, plan.laser_rate_hz)
    message = (f"the workstation stopped during the measurement (started {meta['started_at']}); {n} whole "
               f"period(s) recovered from its journal{note}")
    extra = {"capture": capture, "measurement": {
        "plan": meta["plan"], "partial": True, "ended_by": "crash", "message": message, "periods": n,
        "audio": meta.get("device", ""), "recovered_at": _now(),
        "displacement_source": ("serial laser" if "displacement" in signals and meta["serial_laser"] else
                                "sound card (laser analog)" if "displacement" in signals else "none"),
        "laser": laser_info}, **extra}
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
    width = sum(np.dtype(d).itemsize for _, d in _LASER_COLUMNS)
    while at + _LASER_HEAD.itemsize <= len(raw):
        n, host_time = np.frombuffer(raw, _LASER_HEAD, 1, at)[0]
        body = at + _LASER_HEAD.itemsize
        if n < 0 or body + int(n) * width > len(raw):
            break                            # the last block was cut by the kill
        columns, cursor = {}, body
        for name, dtype in _LASER_COLUMNS:
            columns[name] = np.frombuffer(raw, dtype, int(n), cursor).copy()
            cursor += int(n) * np.dtype(dtype).itemsize
        columns["in_range"] = columns["in_range"].astype(bool)
        blocks.append(LaserBlock(host_time=float(host_time), **columns))
        at = cursor
    return blocks


# --- small helpers -------------------------------------------------------------------------------------

def _in_use(journal: Path) -> bool:
    """True while the measuring process holds the journal's lock."""
    try:
        fd = os.open(journal / "lock", os.O_RDWR)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return True
    finally:
        os.close(fd)
    return False


def _read_records(path: Path, dtype: np.dtype) -> np.ndarray:
    raw = path.read_bytes() if path.exists() else b""
    return np.frombuffer(raw[:len(raw) // dtype.itemsize * dtype.itemsize], dtype=dtype)


def _free_stem(stem: Path) -> Path:
    """``stem``, or stem-recovered, stem-recovered-2 ... when a recording of that name exists."""
    candidates = [stem] + [stem.with_name(f"{stem.name}-recovered" + (f"-{k}" if k > 1 else "")) for k in range(1, 100)]
    return next(c for c in candidates if not any(c.with_name(c.name + s).exists() for s in (".wav", ".json")))


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds").replace("+00:00", "Z")
