"""What one laser model tells the rest of the workstation, and nothing more.

Each model lives in its own subpackage (``instruments/laser/ild1420/``) whose
``__init__`` defines ``MODEL``, a ``LaserModel``; the factory finds it there
(factory.py). The driver is made through ``make_driver`` so that knowing a
model costs no serial import; the simulation runs on the model's own physics
and refuses what the model's ``check_configuration`` refuses, so the real and
the simulated sensor say no to the same settings.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

from instruments.laser.sensor import DisplacementSensor, LaserBlock


class SimulatedPhysics(Protocol):
    """What a virtual sensor measures, on the host's clock (SimulatedLaser's view of it)."""

    rate_hz: float
    measuring_range_m: float
    t0: float | None

    @property
    def disconnect_after(self) -> int | None: ...

    def begin(self, t0: float) -> None: ...

    def reset_counter(self) -> None: ...

    def due(self, now: float) -> int: ...

    def arrival_time(self, k): ...

    def decoded_block(self, k0: int, k1: int, layout: tuple[str, ...], host_time: float) -> LaserBlock: ...


@dataclass(frozen=True)
class LaserModel:
    """A laser model as the factory and the simulation see it.

    name: the key of a LaserSpec ("ild1420"); family: how the sensor names
    itself ("ILD1420"); check_configuration(baudrate, rate_hz, outputs)
    raises LaserError for what the sensor cannot do; layout(outputs) names
    the values of one measurement (its length is the values per measurement);
    make_driver(port, baudrate, **options) the real sensor, not yet open;
    make_physics(**options) the simulation's physics.
    """

    name: str
    family: str
    default_baudrate: int
    rates_hz: tuple[float, ...]
    check_configuration: Callable[[int, float, tuple[str, ...]], None]
    layout: Callable[[tuple[str, ...]], tuple[str, ...]]
    make_driver: Callable[..., DisplacementSensor]
    make_physics: Callable[..., SimulatedPhysics]
