"""A measurement from start to finish: plan, play and record, align the serial laser, write, analyse.

No Qt: the GUI runs ``run_measurement`` in a worker thread and forwards its
progress and LiveFrames. See runner.py for the flow, alignment.py and
clocks.py for how the laser's clock is put on the audio's, raw_stream.py
for the raw laser file beside each recording.

Names are loaded on first use (PEP 562), as in instruments.audio: the CLI
builds its parser from TEMPLATES without loading the runner (and the fit's scipy.optimize).
"""
from importlib import import_module

_EXPORTS = {
    "TEMPLATES": "plan", "MeasurementPlan": "plan", "MeasurementTemplate": "plan",
    "MeasurementCancelled": "runner", "MeasurementError": "errors", "MeasurementFailed": "runner",
    "MeasurementOutcome": "runner", "MeasurementProgress": "runner", "run_measurement": "runner",
}
__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module 'instruments.measurement' has no attribute {name!r}")
    value = getattr(import_module(f"instruments.measurement.{_EXPORTS[name]}"), name)
    globals()[name] = value
    return value


def __dir__():
    return __all__
