"""The streaming interface every simulated loudspeaker implements.

A block driver turns the voltage at the terminals into the current it draws
and the displacement of its cone, one block at a time, keeping its state
between blocks: a stream cut into blocks of any sizes gives the same samples
as the whole stream in one call. The virtual rig calls ``process`` from the
JACK process callback, so an implementation keeps the per-block cost small
and bounded (no allocation that grows with the stream, no I/O, no locks that
a non-realtime thread may hold for long).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np


@dataclass(frozen=True, slots=True, eq=False)
class DriverBlock:
    """One block of the driver's three signals, same length, float64, SI units.

    ``voltage`` (V) is the voltage at the terminals that produced the block,
    ``current`` (A) the current into the driver, ``displacement`` (m) the cone
    position (positive outwards, zero at rest). Arrays are read-only, so a
    block can be handed to another thread as is. Compared by identity.
    """

    voltage: np.ndarray
    current: np.ndarray
    displacement: np.ndarray

    def __post_init__(self) -> None:
        lengths = set()
        for name in ("voltage", "current", "displacement"):
            value = getattr(self, name)
            # A read-only float64 array is taken as handed over (no copy in the audio thread);
            # anything else is copied, so the caller keeps no handle that could change it.
            if not (isinstance(value, np.ndarray) and value.dtype == np.float64 and not value.flags.writeable):
                value = np.array(value, dtype=np.float64)
                value.flags.writeable = False
            if value.ndim != 1:
                raise ValueError(f"DriverBlock.{name} must be 1-D, got shape {value.shape}")
            object.__setattr__(self, name, value)
            lengths.add(value.size)
        if len(lengths) != 1:
            raise ValueError(f"DriverBlock arrays differ in length: {sorted(lengths)}")

    def __len__(self) -> int:
        return self.voltage.size


@runtime_checkable
class BlockDriver(Protocol):
    """A loudspeaker simulated sample by sample, driven by its terminal voltage."""

    sample_rate: int

    def process(self, voltage: np.ndarray) -> DriverBlock:
        """The next block: ``voltage`` (V, 1-D, any length >= 0) in, the three signals out."""
        ...

    def reset(self) -> None:
        """Back to rest: as if no voltage had ever been applied."""
        ...
