"""--only verdicts: the Results page and the QA page's five verdicts on a driver the default model does not describe
exactly (fit error a few %), at 1280x720 and 1920x1080 (tools/screenshots.py).

results-real-unit-WxH.png: the Results page with each curve's fit error; qa-pass-, qa-uncertain-, qa-fail-,
qa-invalid-WxH.png: the QA page against limits at the truth ±15 % (PASS), ±3 % (RE's interval across a limit:
UNCERTAIN), Bl ≥ 5.5 T·m (FAIL, naming Bl and its margin), and the unit's current lead broken (INVALID).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from PySide6.QtWidgets import QApplication

from analysis.drivers import load_driver
from analysis.effects import parse_effects
from analysis.model import Model
from analysis.multitone import design_multitone
from analysis.recording import make_recording, write_recording
from analysis.synthesis import ChannelNoise, synthesize_recording
from tools.screenshot_kit import ANALYSIS_TIMEOUT_S, grab_small_and_large, wait_for

# Four physics the default model (lr2, creep-log) lacks; the default fit misses |Z| by ~3 %, Hx by ~4 %.
PHYSICS = "leach,creep-fractional,damping-power,bl-eddy"
EXTRA = {"K": 0.002, "n": 0.7, "beta": 0.06, "r_v": 0.3, "n_v": 0.5, "dBl": 0.05, "f_Bl": 2000.0}


def real_unit(folder: Path, broken_current: bool = False) -> Path:
    driver = load_driver("paper")
    truth = {**{k: v for k, v in driver.parameters.items() if k not in ("L2", "R2", "lambda")}, **EXTRA}
    mt = design_multitone(48000, 16384, 5.0, 10000.0, rms=1.0)
    rec = synthesize_recording(Model(parse_effects(PHYSICS)), truth, mt.waveform, mt.excited_bins, mt.sample_rate,
                               8, 1, ChannelNoise(1e-4, 1e-4, 1e-8), seed=5,
                               driver={"name": "W18 (several physics)", "sd_m2": driver.sd_m2})
    name = "w18-unit"
    if broken_current:
        signals = {c.signal: rec.signal(c.signal) for c in rec.channels}
        signals["current"] = np.zeros_like(signals["current"])
        rec = make_recording(rec.sample_rate, signals, rec.period_samples, rec.settle_periods, rec.excited_bins,
                             dict(rec.driver))
        name = "w18-unit-current-broken"
    wav, _ = write_recording(folder / name, rec)
    return wav


def limits_file(folder: Path, name: str, parameters: dict) -> Path:
    path = folder / f"{name}.json"
    path.write_text(json.dumps({"format": "linpar-limits/1", "name": name, "parameters": parameters}, indent=1))
    return path


def around_truth(percent: float) -> dict:
    driver = load_driver("paper")
    p = driver.parameters
    return {"RE": {"nominal": p["RE"], "tolerance": f"{percent:g}%", "unit": "ohm"},
            "Bl": {"nominal": p["Bl"], "tolerance": f"{percent:g}%", "unit": "T*m"},
            "Mms": {"nominal": round(p["CMES"] * p["Bl"] ** 2 * 1e3, 3), "tolerance": f"{percent:g}%", "unit": "g"}}


def verdict_screenshots(app: QApplication, window, folder: Path, out: Path) -> list[Path]:
    written = []
    window.open_path(real_unit(folder))
    if not wait_for(window.analysis_shown, ANALYSIS_TIMEOUT_S):
        return []
    window.pages.setCurrentWidget(window.results)
    written += grab_small_and_large(app, window, out, "results-real-unit")
    window.pages.setCurrentWidget(window.qa)
    for stem, parameters in (("qa-pass", around_truth(15)), ("qa-uncertain", around_truth(3)),
                             ("qa-fail", {**around_truth(15), "Bl": {"min": 5.5, "unit": "T*m"}})):
        window.qa.load_limits(limits_file(folder, f"W18 QA {stem.removeprefix('qa-')}", parameters))
        written += grab_small_and_large(app, window, out, stem)
    window.qa.load_limits(limits_file(folder, "W18 QA pass", around_truth(15)))
    window.open_path(real_unit(folder, broken_current=True))
    if wait_for(window.analysis_shown, ANALYSIS_TIMEOUT_S):
        window.pages.setCurrentWidget(window.qa)
        written += grab_small_and_large(app, window, out, "qa-invalid")
    return written
