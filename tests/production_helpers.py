"""What the archive back-end and production QA tests share: a small measurement, stored many times over.

One short synthetic recording (8 kHz, 3 periods of 1,024 samples) is analysed
once; a "unit" is that measurement with its key parameters set to chosen
values, so that a population of hundreds is stored in seconds and its
statistics are known exactly.
"""
from __future__ import annotations

import copy
import json
from pathlib import Path

LIMITS = {"format": "linpar-limits/1", "name": "6-inch woofer",
          "parameters": {"fs": {"nominal": 70.0, "tolerance": 6.0, "unit": "Hz"},
                         "RE": {"min": 2.5, "max": 3.5, "unit": "ohm"}}}


def small_recording():
    from analysis.drivers import load_driver
    from analysis.multitone import design_multitone
    from analysis.synthesis import ChannelNoise, synthesize_recording
    driver = load_driver("paper")
    mt = design_multitone(8000, 1024, 8.0, 3000.0, rms=1.0)
    return synthesize_recording(driver.model(), driver.parameters, mt.waveform, mt.excited_bins, 8000, 3, 0,
                                ChannelNoise(1e-4, 1e-4, 1e-8), seed=1, driver={"name": "paper", "sd_m2": 0.0133})


def small_measurement(folder: Path) -> tuple[Path, dict]:
    """(recording path, results document) of the small measurement, written into `folder`."""
    from analysis.archive.results import results_document
    from analysis.pipeline import analyze_recording
    from analysis.recording.format import write_recording
    rec = small_recording()
    path = Path(folder) / "unit"
    write_recording(path, rec)
    doc = results_document(analyze_recording(rec), rec)
    assert doc["validity"]["overall"] != "red", doc["validity"]
    return path, json.loads(json.dumps(doc))


def unit(doc: dict, **values) -> dict:
    """The results document with parameters set to `values` (SI) and their std kept."""
    out = copy.deepcopy(doc)
    for name, value in values.items():
        out["parameters"][name]["value"] = float(value)
    return out
