"""Recordings: the raw signals of one multitone measurement, and their files.

A recording is NAME.wav (the samples) and NAME.json (the sidecar: what each
channel is and how to scale it); the format is docs/recording-format.md.
A Recording in memory always satisfies every rule of the format: the checks run
when it is built, whether from files (read_recording), from signals
(make_recording) or directly, so code that holds one need not check again.

Messages name the file (or "<in memory>"), the sidecar key or the channel, what
was found and what was expected, on one line: they are shown to the user as is.

The JSON of the sidecar is read and written by analysis.recording.sidecar, the
samples by analysis.recording.wav; this module holds the rules and the files.
"""
from __future__ import annotations

import json
import math
import numbers
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

# The sidecar's vocabulary (FORMAT, UNITS, Channel, RecordingError) is defined there and importable from here.
from analysis.bounds import CHANNEL_SCALE, PERIOD_SAMPLES, SAMPLE_RATE, SD
from analysis.files import mapped, regular_file, write_atomic
from analysis.recording.sidecar import (CHANNEL_KEYS, EXCITATION_KEYS, FORMAT, TOP_KEYS, UNITS, Channel,
                                        RecordingError, format_sidecar, json_default, load_sidecar, parse_sidecar,
                                        show, unit_wanted)
from analysis.recording.wav import WavFormatError, decode_wav, encode_float32_wav

__all__ = ["FORMAT", "IN_MEMORY", "MIN_PERIODS", "REQUIRED_SIGNALS", "UNITS", "Channel", "Recording",
           "RecordingError", "make_recording", "read_recording", "recording_paths", "write_recording"]

REQUIRED_SIGNALS = ("voltage", "current")
# Two periods are the fewest from which the noise on a line can be estimated.
MIN_PERIODS = 2
IN_MEMORY = "<in memory>"


# eq=False: comparing recordings field by field would compare numpy arrays,
# which has no single truth value; a Recording is compared by identity.
@dataclass(frozen=True, eq=False)
class Recording:
    sample_rate: int
    channels: tuple[Channel, ...]
    data: np.ndarray            # (n_channels, n_samples) float64, C-contiguous, physical units, read-only
    period_samples: int
    settle_periods: int = 0
    excited_bins: tuple[int, ...] | None = None    # sorted
    driver: Mapping[str, Any] = field(default_factory=dict)
    extra: Mapping[str, Any] = field(default_factory=dict)     # other top-level sidecar keys
    source: Path | None = None  # the .wav it was read from
    # Other keys of the sidecar's "excitation" object, written back unchanged.
    excitation_extra: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name, value in _checked_fields(self).items():
            object.__setattr__(self, name, value)

    def signal(self, name: str) -> np.ndarray | None:
        """The row of that signal in physical units, or None if the recording has none."""
        for row, channel in enumerate(self.channels):
            if channel.signal == name:
                return self.data[row]
        return None

    @property
    def n_samples(self) -> int:
        return self.data.shape[1]

    @property
    def n_periods(self) -> int:
        """Whole periods after the settle periods; a trailing partial period does not count."""
        analysed = self.n_samples - self.settle_periods * self.period_samples
        return max(analysed // self.period_samples, 0)

    def periods(self, name: str) -> np.ndarray:
        """(n_periods, period_samples) read-only view of the analysed part of one signal."""
        row = self.signal(name)
        if row is None:
            raise KeyError(f"no {name!r} channel in this recording "
                           f"(it has {', '.join(c.signal for c in self.channels)})")
        start = self.settle_periods * self.period_samples
        stop = start + self.n_periods * self.period_samples
        return row[start:stop].reshape(self.n_periods, self.period_samples)

    @property
    def duration_s(self) -> float:
        return self.n_samples / self.sample_rate


def not_a_folder(path: str | Path) -> None:
    """RecordingError when `path` is a folder: read as a stem, FOLDER.wav and FOLDER.json were said missing."""
    if Path(path).is_dir():
        held = len(list(Path(path).glob("*.wav")))
        raise RecordingError(f"{path}: a folder, not a recording: give one recording in it (NAME, NAME.wav or "
                             f"NAME.json){'; it holds ' + str(held) + ' WAV file(s)' if held else ''}")


def read_recording(path: str | Path) -> Recording:
    """Read NAME.wav + NAME.json; `path` is the stem, NAME.wav or NAME.json.

    Every rule of the format is checked; a file that breaks one raises
    RecordingError and nothing is returned.
    """
    not_a_folder(path)
    wav_path, json_path = recording_paths(path)
    # A FIFO, folder or device is named as what it is; a file beyond its size limit is refused unread.
    regular_file(json_path, "sidecar", f"the sidecar of the recording next to {wav_path.name}", RecordingError)
    regular_file(wav_path, "wav", f"the signals of the recording next to {json_path.name}", RecordingError)
    sidecar = parse_sidecar(load_sidecar(json_path), str(json_path))
    channels = _checked_channels(sidecar["channels"], str(json_path))
    try:
        with mapped(wav_path, "wav", "a WAV file", RecordingError) as blob:      # decoded out of the map
            wav = decode_wav(blob)
    except WavFormatError as err:
        raise RecordingError(f"{wav_path}: {err}") from None
    _check_channel_count(wav.samples.shape[0], len(channels), str(wav_path), str(json_path))
    data = wav.samples          # ours alone: scaled in place, no second copy of a long recording
    with np.errstate(over="ignore", invalid="ignore"):   # a scale that overflows is refused below
        data *= np.array([c.scale for c in channels])[:, None]
    data.flags.writeable = False
    return Recording(sample_rate=wav.sample_rate, channels=channels, data=data, source=wav_path, **sidecar["rest"])


def write_recording(path: str | Path, recording: Recording) -> tuple[Path, Path]:
    """Write NAME.wav (32-bit float, samples = data / scale) and NAME.json; return their paths.

    Each file is written atomically. Nothing is written unless both can be:
    the samples and the sidecar are encoded in memory first. The .wav is
    replaced before the .json, so a new sidecar never points at a missing file.
    RecordingError if the data do not fit the format; OSError if the folder
    cannot be written.
    """
    wav_path, json_path = recording_paths(path)
    scales = np.array([c.scale for c in recording.channels])[:, None]
    with np.errstate(over="ignore"):
        samples = (recording.data / scales).astype(np.float32)
    _check_finite(samples, recording.channels, f"{wav_path} (as 32-bit float, data / scale)")
    try:
        wav_bytes = encode_float32_wav(recording.sample_rate, samples)
    except WavFormatError as err:
        raise RecordingError(f"{wav_path}: {err}") from None
    try:
        json_bytes = format_sidecar(sidecar_of(recording)).encode("utf-8")
    except UnicodeEncodeError as err:
        raise RecordingError(f"{json_path}: a string holds {err.object[err.start:err.end]!r}, half of a UTF-16 "
                             f"surrogate pair, expected Unicode text") from None
    write_atomic(wav_path, wav_bytes)
    write_atomic(json_path, json_bytes)
    return wav_path, json_path


def make_recording(sample_rate: int, signals: Mapping[str, np.ndarray], period_samples: int,
                   settle_periods: int = 0, excited_bins=None, driver=None, extra=None) -> Recording:
    """A Recording of physical signals (V, A, m) computed or measured in this program.

    Every channel gets scale 1.0: float32 keeps 24 significant bits at any
    magnitude, so no scale would make the written file more precise. Signals
    that the analysis does not know get the unit "" (unknown). The data stay
    float64 in memory; a written and re-read copy is rounded to float32.
    """
    if not isinstance(signals, Mapping):
        raise RecordingError(f"{IN_MEMORY}: signals: found {show(signals)}, expected a mapping of name -> samples")
    rows = []
    for name, values in signals.items():
        try:
            # A complex array would be cast silently, dropping its imaginary part.
            row = None if np.iscomplexobj(values) else np.asarray(values, dtype=np.float64)
        except (TypeError, ValueError):
            row = None
        if row is None or row.ndim != 1:
            raise RecordingError(f"{IN_MEMORY}: signal {name!r}: found {show(values)}, "
                                 f"expected a 1-D array of real numbers")
        if rows and len(row) != len(rows[0]):
            raise RecordingError(f"{IN_MEMORY}: signal {name!r}: {len(row)} samples, expected {len(rows[0])} "
                                 f"like {next(iter(signals))!r}")
        rows.append(row)
    data = np.stack(rows) if rows else np.empty((0, 0))
    data.flags.writeable = False    # ours alone: the Recording may keep it without a copy
    channels = tuple(Channel(name, UNITS.get(name, ""), 1.0) for name in signals)
    return Recording(sample_rate=sample_rate, channels=channels, data=data, period_samples=period_samples,
                     settle_periods=settle_periods, excited_bins=excited_bins,
                     driver={} if driver is None else driver, extra={} if extra is None else extra)


def sidecar_of(rec: Recording) -> dict[str, Any]:
    """The sidecar document of `rec`: the format's keys first, then what it kept of other keys."""
    excitation: dict[str, Any] = {"period_samples": rec.period_samples, "settle_periods": rec.settle_periods}
    if rec.excited_bins is not None:
        excitation["excited_bins"] = list(rec.excited_bins)
    doc: dict[str, Any] = {
        "format": FORMAT,
        "channels": [{"signal": c.signal, "unit": c.unit, "scale": c.scale, **c.extra} for c in rec.channels],
        "excitation": {**excitation, **rec.excitation_extra},
    }
    if rec.driver:
        doc["driver"] = dict(rec.driver)
    doc.update(rec.extra)
    return doc


def recording_paths(path: str | Path) -> tuple[Path, Path]:
    """(NAME.wav, NAME.json) for a stem, NAME.wav or NAME.json."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".wav":
        return path, path.with_suffix(".json")
    if suffix == ".json":
        return path.with_suffix(".wav"), path
    # A stem may hold dots ("sweep.2024-05-01"): add the suffix, never replace.
    return path.with_name(path.name + ".wav"), path.with_name(path.name + ".json")


# --- the rules, shared by every way of building a Recording -----------------

def _checked_fields(rec: Recording) -> dict[str, Any]:
    """The fields of `rec`, normalised, or RecordingError for the first broken rule."""
    source = None if rec.source is None else Path(rec.source)
    wav_label, json_label = ((IN_MEMORY, IN_MEMORY) if source is None
                             else tuple(str(p) for p in recording_paths(source)))
    channels = _checked_channels(rec.channels, json_label)
    data = _checked_data(rec.data, channels, wav_label, json_label)
    sample_rate = _bounded(rec.sample_rate, SAMPLE_RATE, wav_label, "sample rate")
    period = _bounded(rec.period_samples, PERIOD_SAMPLES, json_label, "excitation.period_samples")
    settle = _integer(rec.settle_periods, 0, json_label, "excitation.settle_periods", "a non-negative integer")
    _check_length(data.shape[1], period, settle, json_label, wav_label)
    return {
        "sample_rate": sample_rate, "channels": channels, "data": data, "period_samples": period,
        "settle_periods": settle, "source": source,
        "excited_bins": _checked_bins(rec.excited_bins, period, json_label),
        "driver": _checked_driver(rec.driver, json_label),
        "extra": _checked_mapping(rec.extra, TOP_KEYS, json_label, ""),
        "excitation_extra": _checked_mapping(rec.excitation_extra, EXCITATION_KEYS, json_label, "excitation."),
    }


def _checked_channels(channels, label: str) -> tuple[Channel, ...]:
    if not isinstance(channels, (list, tuple)) or not channels:
        raise RecordingError(f"{label}: channels: found {show(channels)}, "
                             f"expected a non-empty list of {{signal, unit, scale}}")
    checked: list[Channel] = []
    first_seen: dict[str, int] = {}
    for i, channel in enumerate(channels):
        key = f"channels[{i}]"
        if not isinstance(channel, Channel):
            raise RecordingError(f"{label}: {key}: found {show(channel)}, expected a Channel")
        signal, unit, scale = channel.signal, channel.unit, channel.scale
        if not isinstance(signal, str) or not signal:
            raise RecordingError(f"{label}: {key}.signal: found {show(signal)}, expected a non-empty string")
        if signal in first_seen:
            raise RecordingError(f"{label}: {key}.signal: {signal!r} again (first in channels[{first_seen[signal]}]), "
                                 f"expected each signal once")
        first_seen[signal] = i
        expected_unit = UNITS.get(signal)
        if not isinstance(unit, str) or (expected_unit is not None and unit != expected_unit):
            raise RecordingError(f"{label}: {key}.unit: found {show(unit)} for signal {signal!r}, "
                                 f"expected {unit_wanted(signal)}")
        if not _is_finite_real(scale) or scale == 0:
            raise RecordingError(f"{label}: {key}.scale: found {show(scale)} for signal {signal!r}, "
                                 f"expected a finite nonzero number")
        CHANNEL_SCALE.check(abs(scale), f"{label}: {key}.scale of signal {signal!r}", RecordingError)
        extra = _checked_mapping(channel.extra, CHANNEL_KEYS, label, f"{key}.")
        checked.append(Channel(signal, unit, float(scale), extra))
    for required in REQUIRED_SIGNALS:
        if required not in first_seen:
            raise RecordingError(f"{label}: channels: no {required!r} channel (found {', '.join(map(repr, first_seen))}), "
                                 f"expected a 'voltage' and a 'current' channel")
    return tuple(checked)


def _checked_data(data, channels: tuple[Channel, ...], wav_label: str, json_label: str) -> np.ndarray:
    if np.iscomplexobj(data):
        raise RecordingError(f"{wav_label}: data: found complex samples, expected real numbers")
    if not (isinstance(data, np.ndarray) and data.dtype == np.float64 and data.flags.c_contiguous
            and not data.flags.writeable):
        try:
            data = np.array(data, dtype=np.float64, order="C")
        except (TypeError, ValueError):
            raise RecordingError(f"{wav_label}: data: found {show(data)}, expected an array of numbers") from None
        data.flags.writeable = False
    if data.ndim != 2:
        raise RecordingError(f"{wav_label}: data: found shape {data.shape}, expected (n_channels, n_samples)")
    _check_channel_count(data.shape[0], len(channels), wav_label, json_label)
    _check_finite(data, channels, wav_label)
    return data


def _check_channel_count(found: int, expected: int, wav_label: str, json_label: str) -> None:
    if found != expected:
        per = "channel" if json_label == IN_MEMORY else f"entry of 'channels' in {Path(json_label).name}"
        raise RecordingError(f"{wav_label}: {found} channels, expected {expected}, one per {per}")


def _check_finite(data: np.ndarray, channels: tuple[Channel, ...], label: str) -> None:
    bad = ~np.isfinite(data)
    if bad.any():
        row = int(np.flatnonzero(bad.any(axis=1))[0])
        index = int(np.argmax(bad[row]))
        what = "NaN" if np.isnan(data[row, index]) else "infinite"
        raise RecordingError(f"{label}: channel {channels[row].signal!r} (channel {row + 1}): sample {index} is {what}, "
                             f"expected finite samples")


def _check_length(n_samples: int, period: int, settle: int, json_label: str, wav_label: str) -> None:
    if period > n_samples:
        raise RecordingError(f"{json_label}: excitation.period_samples: {period} samples is longer than the recording "
                             f"({n_samples} samples in {wav_label}), expected at most {n_samples // MIN_PERIODS}")
    left = max(n_samples // period - settle, 0)
    if left < MIN_PERIODS:
        raise RecordingError(f"{json_label}: excitation: {n_samples} samples hold {n_samples // period} whole periods "
                             f"of {period} samples, {settle} to settle, which leaves {left}; expected at least "
                             f"{MIN_PERIODS} whole periods after the settle periods")


def _checked_bins(bins, period: int, label: str) -> tuple[int, ...] | None:
    if bins is None:
        return None
    top = period // 2
    expected = f"a non-empty list of distinct integers in 1..{top} (period_samples // 2)"
    try:
        if isinstance(bins, (str, bytes, Mapping)):
            raise TypeError
        bins = list(bins)
    except TypeError:
        raise RecordingError(f"{label}: excitation.excited_bins: found {show(bins)}, expected {expected}") from None
    if not bins:
        raise RecordingError(f"{label}: excitation.excited_bins: found an empty list, expected {expected}")
    seen: set[int] = set()
    for i, b in enumerate(bins):
        if not _is_integer(b) or not 1 <= b <= top or b in seen:
            problem = f"{b!r} again" if _is_integer(b) and b in seen else f"found {show(b)}"
            raise RecordingError(f"{label}: excitation.excited_bins[{i}]: {problem}, expected {expected}")
        seen.add(int(b))
    return tuple(sorted(seen))


def _checked_driver(driver, label: str) -> Mapping[str, Any]:
    driver = _checked_mapping(driver, (), label, "driver.", whole_key="driver")
    if "name" in driver and not isinstance(driver["name"], str):
        raise RecordingError(f"{label}: driver.name: found {show(driver['name'])}, expected a string")
    if "sd_m2" in driver:
        SD.check(driver["sd_m2"], f"{label}: driver.sd_m2", RecordingError)
    return driver


def _checked_mapping(mapping, reserved, label: str, prefix: str, whole_key: str | None = None) -> Mapping[str, Any]:
    """A read-only copy of a mapping that must stay writable as JSON beside the keys in `reserved`."""
    where = whole_key or (prefix + "extra" if prefix else "extra")
    if not isinstance(mapping, Mapping):
        raise RecordingError(f"{label}: {where}: found {show(mapping)}, expected an object (a mapping)")
    for key, value in mapping.items():
        if not isinstance(key, str) or key in reserved:
            other_than = f" other than {', '.join(reserved)}" if reserved else ""
            raise RecordingError(f"{label}: {where}: key {show(key)}, expected a string{other_than}")
        try:
            json.dumps(value, allow_nan=False, default=json_default)
        except (TypeError, ValueError, RecursionError):
            raise RecordingError(f"{label}: {prefix}{key}: found {show(value)}, "
                                 f"expected a JSON value (no NaN or infinity)") from None
    return MappingProxyType(dict(mapping))


# --- files and small helpers -------------------------------------------------

def _bounded(value, bound, label: str, key: str) -> int:
    """An integer field within its bound (analysis.bounds); a non-integer is refused as such, not rounded."""
    if not _is_integer(value):
        raise RecordingError(f"{label}: {key}: found {show(value)}, expected {bound.expected()}")
    return bound.check(value, f"{label}: {key}", RecordingError)


def _integer(value, minimum: int, label: str, key: str, expected: str) -> int:
    if not _is_integer(value) or value < minimum:
        raise RecordingError(f"{label}: {key}: found {show(value)}, expected {expected}")
    return int(value)


def _is_integer(value) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, (bool, np.bool_))


def _is_finite_real(value) -> bool:
    if not isinstance(value, numbers.Real) or isinstance(value, (bool, np.bool_)):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:       # a JSON integer beyond the float range
        return False
