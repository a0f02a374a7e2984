"""A measurement from start to finish: plan, play and record, align the serial laser, write, analyse.

No Qt: the GUI runs ``run_measurement`` in a worker thread and forwards its
progress and LiveFrames. See runner.py for the flow, alignment.py and
clocks.py for how the laser's clock is put on the audio's, raw_stream.py
for the raw laser file beside each recording.
"""
from instruments.measurement.plan import TEMPLATES, MeasurementPlan, MeasurementTemplate
from instruments.measurement.runner import (
    MeasurementCancelled, MeasurementError, MeasurementFailed, MeasurementOutcome, MeasurementProgress,
    run_measurement)

__all__ = ["TEMPLATES", "MeasurementCancelled", "MeasurementError", "MeasurementFailed", "MeasurementOutcome",
           "MeasurementPlan", "MeasurementProgress", "MeasurementTemplate", "run_measurement"]
