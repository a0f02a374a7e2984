"""The raw capture beside a recording: NAME.laser.npz, what the alignment was computed from.

A recording holds the displacement already aligned and resampled; this file
keeps what the serial laser actually sent, and when things arrived, so the
alignment can be checked or redone. Format "linpar-raw-capture/1": a numpy
.npz (a zip of .npy files) holding only numeric arrays and strings, read with
``numpy.load(path, allow_pickle=False)`` (``read_raw_capture`` does): no
pickle, nothing executable.

    format                 str            "linpar-raw-capture/1"
    info                   str            JSON: sensor (name, serial, range), laser rate, audio rate,
                                          the plan, the alignment found, how the measurement ended
    counter                int64 (n)      measurement counter, unwrapped; -1 when not sent
    timestamp_ms           float64 (n)    the sensor's time stamp; NaN when not sent
    distance_m             float64 (n)    distance; NaN where an error code came instead
    error_code             int32 (n)      0 for a distance, else the sensor's code (262075 ...)
    in_range               bool (n)       False for errors and distances in the reserves
    block_size             int64 (b)      measurements per laser block, in arrival order
    block_host_time        float64 (b)    time.monotonic() when each block arrived
    audio_block_start      int64 (a)      sound-card input blocks: first sample index
    audio_block_stop       int64 (a)      ... the index after their last sample
    audio_block_host_time  float64 (a)    ... when each arrived
    period_starts          int64 (p)      input index of each period kept by the capture
    voltage, current       float64        (only when no recording could be written: fewer than 2 periods)
                                          the captured periods, V and A

Written atomically (a temporary file in the same folder, then renamed).
"""
from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from analysis.files import write_atomic
from instruments.laser.sensor import LaserBlock

FORMAT = "linpar-raw-capture/1"
SUFFIX = ".laser.npz"


def raw_capture_path(stem: Path) -> Path:
    return stem.with_name(stem.name + SUFFIX)


def write_raw_capture(path: Path, blocks: Sequence[LaserBlock], audio_arrivals: tuple, period_starts,
                      info: Mapping[str, Any], extra_arrays: Mapping[str, np.ndarray] | None = None) -> Path:
    """Write the file atomically; its path."""
    blocks = [b for b in blocks if len(b)]

    def column(name: str, dtype) -> np.ndarray:
        if not blocks:
            return np.zeros(0, dtype=dtype)
        return np.concatenate([np.asarray(getattr(b, name)) for b in blocks]).astype(dtype)

    start, stop, arrived = audio_arrivals
    arrays = {
        "format": np.array(FORMAT), "info": np.array(json.dumps(info, default=_plain)),
        "counter": column("counter", np.int64), "timestamp_ms": column("timestamp_ms", np.float64),
        "distance_m": column("distance_m", np.float64), "error_code": column("error_code", np.int32),
        "in_range": column("in_range", bool),
        "block_size": np.array([len(b) for b in blocks], dtype=np.int64),
        "block_host_time": np.array([b.host_time for b in blocks], dtype=np.float64),
        "audio_block_start": np.asarray(start, dtype=np.int64), "audio_block_stop": np.asarray(stop, dtype=np.int64),
        "audio_block_host_time": np.asarray(arrived, dtype=np.float64),
        "period_starts": np.asarray(period_starts, dtype=np.int64),
    }
    for name, value in (extra_arrays or {}).items():
        arrays[name] = np.asarray(value, dtype=np.float64)
    encoded = io.BytesIO()
    np.savez(encoded, **arrays)
    return write_atomic(Path(path), encoded.getvalue())


def read_raw_capture(path: Path) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """(arrays, info) of a raw capture file; ValueError for a file of another format."""
    with np.load(Path(path), allow_pickle=False) as data:
        arrays = {name: data[name] for name in data.files}
    if str(arrays.get("format", "")) != FORMAT:
        raise ValueError(f"{path}: format {str(arrays.get('format'))!r}, expected {FORMAT!r}")
    info = json.loads(str(arrays.pop("info")))
    arrays.pop("format")
    return arrays, info


def blocks_of(arrays: Mapping[str, np.ndarray]) -> list[LaserBlock]:
    """The laser blocks back from a file's arrays (to redo the alignment)."""
    edges = np.concatenate([[0], np.cumsum(arrays["block_size"])])
    out = []
    for i, host_time in enumerate(arrays["block_host_time"]):
        s = slice(int(edges[i]), int(edges[i + 1]))
        out.append(LaserBlock(arrays["counter"][s].copy(), arrays["timestamp_ms"][s].copy(),
                              arrays["distance_m"][s].copy(), arrays["error_code"][s].copy(),
                              arrays["in_range"][s].copy(), float(host_time)))
    return out


def _plain(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"cannot store {type(value).__name__} in the raw capture's info")
