"""Recordings at rising drive levels from the nonlinear driver, offline: the input of a level series.

The driver is instruments.simulation.nonlinear_driver's default, the paper's
driver softening with excursion (Kms(x), Bl(x), Le(x)); the measurement is a
faults.Bench (48 kHz, the project multitone 5 Hz - 10 kHz, periods of 16,384
samples, the bench's sensor noise). DEFAULT_LEVELS_V span what the paper
measured, ~0.15 mm to ~8.5 mm peak:

    V RMS      0.3    1      3      6      10     14
    peak mm    0.15   0.51   1.55   3.17   5.56   8.49

Cost: the driver takes ~1.4 us per sample, so a level of 8 + 2 periods of
16,384 samples takes ~0.5 s; the multitone's design (~1 s) is shared by every
level.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Sequence

from analysis.errors import LinparError
from analysis.recording.format import Recording, write_recording
from instruments.simulation.faults import DEFAULT_BENCH, Bench, clean_nonlinear

DEFAULT_LEVELS_V = (0.3, 1.0, 3.0, 6.0, 10.0, 14.0)
# Above ~16 V RMS the default driver's cone passes 11.5 mm, where its Kms(x) turns up again and
# the polynomials stop meaning anything (nonlinear_driver: they are clipped at 12 mm).
MAX_LEVEL_V = 16.0


class LevelsError(LinparError, ValueError):
    """Drive levels the simulated driver cannot take; one line."""


def simulate_level(level_v_rms: float, bench: Bench = DEFAULT_BENCH, index: int = 0) -> Recording:
    """One recording of the nonlinear driver at level_v_rms (the multitone's RMS, V).

    Each index gets its own noise (seed + index): repeated noise would be
    correlated across the series and hide how much of the drift is noise.
    """
    check_levels((level_v_rms,))
    return clean_nonlinear(replace(bench, level_rms=float(level_v_rms), seed=bench.seed + index))


def simulate_level_series(levels_v: Sequence[float] = DEFAULT_LEVELS_V,
                          bench: Bench = DEFAULT_BENCH) -> list[Recording]:
    """One recording per level, in the given order."""
    check_levels(levels_v)
    return [simulate_level(level, bench, i) for i, level in enumerate(levels_v)]


def write_level_series(folder: str | Path, levels_v: Sequence[float] = DEFAULT_LEVELS_V,
                       bench: Bench = DEFAULT_BENCH, progress=None) -> list[Path]:
    """Simulate and write each level as FOLDER/level-NN-<V>V.wav/.json; the .wav paths.

    progress(i, n, level_v), if given, is called before each level (a level takes ~0.5 s).
    """
    check_levels(levels_v)
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for i, level in enumerate(levels_v):
        if progress is not None:
            progress(i, len(levels_v), level)
        wav, _ = write_recording(out / f"level-{i + 1:02d}-{level:g}V", simulate_level(level, bench, i))
        paths.append(wav)
    return paths


def check_levels(levels_v: Sequence[float]) -> None:
    """LevelsError (one line) unless every level is one the simulated driver can take."""
    if len(levels_v) == 0:
        raise LevelsError("no levels: give at least one drive level in V RMS")
    for level in levels_v:
        if not 0 < level <= MAX_LEVEL_V:
            raise LevelsError(f"level {level:g} V RMS: expected above 0 and at most {MAX_LEVEL_V:g} V "
                             f"(beyond, the simulated driver's cone leaves the range of its polynomials)")
