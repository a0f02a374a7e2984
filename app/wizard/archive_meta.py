"""What the archive keeps about a measurement the wizard made: who, which driver, how it was measured.

The main window hands this with the recording and its result to the archive's worker
(app.archive.worker); the archive stores it beside them (analysis.archive).
"""
from __future__ import annotations


def measurement_meta(request) -> dict:
    """The archive's metadata of a wizard's measurement request (app.wizard.tasks.MeasurementRequest): the
    driver, serial, operator and station, the settings (template, level and why, hardware) and the
    calibration's corrections."""
    driver = request.driver
    return {"driver": driver.name, "serial": driver.serial, "operator": driver.operator, "station": driver.station,
            "settings": {"template": request.template.as_json(), "level_v_rms": request.level_v,
                         "level_reason": request.level_reason, "hardware": request.hardware.describe()},
            "calibration": {"corrections": request.corrections.to_dict()}}
