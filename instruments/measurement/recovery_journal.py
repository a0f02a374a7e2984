"""The journal of a running measurement: its files, and the writer that fills them as the input arrives.

The layout of ``OUT/NAME.unfinished/`` and why it is written as it is are in
instruments.measurement.recovery, which runs a measurement with a Journal;
instruments.measurement.recovery_replay reads journals back.
"""
from __future__ import annotations

import json
import os
import queue
import shutil
import socket
import threading
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from analysis import file_lock
from analysis.archive.atomic import write_atomic
from instruments.audio.stream_core import InputBlock
from instruments.laser.sensor import LaserBlock
from instruments.measurement.plan import MeasurementPlan

FORMAT = "linpar-journal/1"
SUFFIX = ".unfinished"
FADE_S = 0.1                 # capture()'s fade-in, which run_measurement keeps
FSYNC_EVERY_S = 1.0
QUEUE_ITEMS = 8192           # blocks waiting for the disk; beyond, the journal gives up rather than the audio
# audio.idx holds one INDEX_RECORD per block; laser.bin one LASER_HEAD per block, then its LASER_COLUMNS in turn.
INDEX_RECORD = np.dtype([("start", "<i8"), ("frames", "<i8"), ("flags", "<i8"), ("time", "<f8")])
LASER_HEAD = np.dtype([("n", "<i8"), ("time", "<f8")])
LASER_COLUMNS = (("counter", "<i8"), ("timestamp_ms", "<f8"), ("distance_m", "<f8"), ("error_code", "<i4"),
                 ("in_range", "u1"))


def journal_path(out_dir: Path | str, name: str) -> Path:
    return Path(out_dir) / f"{name}{SUFFIX}"


class Journal:
    """The journal of one running measurement; ``audio`` and ``laser`` wrap the devices so that it sees their data."""

    def __init__(self, path: Path):
        self.path = path
        self.failure: str | None = None      # NB: set by the writer thread
        self.dropped = 0                     # NB: blocks the queue had no room for (counted by device threads)
        self._queue: queue.Queue = queue.Queue(maxsize=QUEUE_ITEMS)
        self._files: dict[str, int] = {}
        self._lock = None                    # held while the measurement runs (analysis.file_lock)
        self._thread: threading.Thread | None = None

    @classmethod
    def create(cls, out_dir: Path, name: str, plan: MeasurementPlan, audio, serial_laser: bool) -> "Journal":
        path = journal_path(out_dir, name)
        path.mkdir()                         # FileExistsError: a journal of that name is still there
        journal = cls(path)
        try:
            journal._lock = file_lock.take(path / "lock", wait_s=0)
            if journal._lock is None:
                raise FileExistsError(f"{path}: another measurement holds this journal")
            meta = {"format": FORMAT, "name": name, "started_at": now_utc(), "host": socket.gethostname(),
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
        if self._lock is not None:
            self._lock.release()             # from now on find_unfinished sees the journal
            self._lock = None
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
                record = np.array([(block.start, frames.shape[0], block.flags, host_time)], dtype=INDEX_RECORD)
                _write_all(self._files["audio.idx"], record.tobytes())     # after the samples it describes
        else:
            block: LaserBlock = payload
            head = np.array([(len(block), block.host_time)], dtype=LASER_HEAD).tobytes()
            body = b"".join(np.ascontiguousarray(getattr(block, name), dtype=dtype).tobytes()
                            for name, dtype in LASER_COLUMNS)
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


# --- small helpers -------------------------------------------------------------------------------------

def in_use(journal: Path) -> bool:
    """True while the measuring process holds the journal's lock."""
    return file_lock.held(journal / "lock")


def recording_written(stem: Path) -> bool:
    return stem.with_name(stem.name + ".wav").is_file() and stem.with_name(stem.name + ".json").is_file()


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def now_utc() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds").replace("+00:00", "Z")
