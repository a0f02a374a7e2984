"""Lasers by specification: ``open_laser(LaserSpec(...))`` is the one place a
sensor object is made, real or simulated, whatever its model.

The models are the subpackages of instruments.laser that define ``MODEL``
(model.py); a new model is found without touching this module.
"""
from __future__ import annotations

import pkgutil
import threading
from dataclasses import dataclass, field
from importlib import import_module
from typing import Any, Mapping

from instruments.laser.model import LaserModel
from instruments.laser.sensor import DisplacementSensor, LaserError

DEFAULT_MODEL = "ild1420"

_models: dict[str, LaserModel] = {}
_searched = False      # the subpackages are looked through once, on first use
_search_lock = threading.Lock()     # NB: a measurement thread and the GUI may both ask first
_unloadable: dict[str, str] = {}    # subpackage -> why it did not import (named when a model is unknown)


@dataclass(frozen=True)
class LaserSpec:
    """Which laser, where. ``port`` is a pyserial URL (a device such as
    /dev/ttyUSB0 or COM3, a pty, ``loop://``) or an already made pyserial
    port; a simulated laser ignores it. ``baudrate`` None: the model's
    default. ``options`` go to the driver (reply_timeout_s, queue_blocks) or,
    simulated, to the model's physics (displacement, clock_ppm, error_plan,
    connected, ...)."""

    model: str = DEFAULT_MODEL
    port: Any = ""
    baudrate: int | None = None
    simulated: bool = False
    options: Mapping[str, Any] = field(default_factory=dict)


def laser_models() -> dict[str, LaserModel]:
    """Every known model by name: the subpackages' MODELs and any registered."""
    global _searched
    with _search_lock:
        if not _searched:
            package = import_module("instruments.laser")
            for info in pkgutil.iter_modules(package.__path__):
                if info.ispkg:
                    try:
                        module = import_module(f"instruments.laser.{info.name}")
                    except ImportError as exc:      # one model's missing library must not hide the others
                        _unloadable[info.name] = str(exc)
                        continue
                    model = getattr(module, "MODEL", None)
                    if isinstance(model, LaserModel):
                        _models.setdefault(model.name, model)
            _searched = True
        return dict(_models)


def register_laser_model(model: LaserModel) -> None:
    """Add a model that does not live in a subpackage of instruments.laser (a plug-in, a test's fake)."""
    laser_models()
    _models[model.name] = model


def laser_model(name: str) -> LaserModel:
    models = laser_models()
    if name not in models:
        unloadable = "".join(f"; {package} did not load: {why}" for package, why in sorted(_unloadable.items()))
        raise LaserError(f"unknown laser model {name!r}; known: {', '.join(sorted(models)) or 'none'}{unloadable}")
    return models[name]


def open_laser(spec: LaserSpec) -> DisplacementSensor:
    """The sensor ``spec`` names, not yet opened (its ``open()`` connects)."""
    model = laser_model(spec.model)
    baudrate = spec.baudrate or model.default_baudrate
    if spec.simulated:
        from instruments.laser.simulated import SimulatedLaser
        return SimulatedLaser(model, spec.port or None, baudrate, **spec.options)
    if not spec.port:
        from instruments.serial_ports import port_example
        raise LaserError(f"give the laser's serial port (a device such as {port_example()})")
    return model.make_driver(spec.port, baudrate, **spec.options)
