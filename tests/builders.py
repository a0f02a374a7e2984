"""Synthetic recordings for tests: known drivers, a multitone, chosen noise."""
from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from analysis.drivers import load_driver
from analysis.effects import parse_effects
from analysis.model.composed import Model
from analysis.multitone import design_multitone
from analysis.synthesis import ChannelNoise, synthesize_recording

PAPER = load_driver("paper")


def electrical(RE, LE, Mms, Cms, Rms, Bl, **extra) -> dict[str, float]:
    """Electrical-analogue values from mechanical ones (docs/physics.md section 1)."""
    return {"RE": RE, "LE": LE, "CMES": Mms / Bl**2, "LCES": Cms * Bl**2, "RES": Bl**2 / Rms, "Bl": Bl, **extra}


# Drivers from a 2-inch full-range to an 18-inch woofer (typical catalogue values).
DRIVERS = {
    "fullrange-2in": electrical(3.6, 0.03e-3, 1.2e-3, 0.8e-3, 0.3, 2.5, L2=0.05e-3, R2=2.0, **{"lambda": 0.1}),
    "midwoofer-6in": electrical(5.7, 0.4e-3, 15e-3, 0.84e-3, 1.1, 7.0, L2=0.6e-3, R2=8.0, **{"lambda": 0.12}),
    "paper": dict(PAPER.parameters),
    "woofer-12in": electrical(6.3, 1.0e-3, 80e-3, 0.25e-3, 2.5, 15.0, L2=1.2e-3, R2=9.0, **{"lambda": 0.08}),
    "woofer-18in": electrical(5.2, 1.5e-3, 250e-3, 0.12e-3, 4.0, 25.0, L2=2.0e-3, R2=10.0, **{"lambda": 0.06}),
}


def multitone(sample_rate=48000, period_samples=16384, f_min=5.0, f_max=10000.0, rms=1.0):
    return design_multitone(sample_rate, period_samples, f_min, f_max, rms=rms)


def recording(values=None, effects="lr2,creep-log", *, n_periods=8, settle=1, noise=ChannelNoise(),
              seed=0, mt=None, displacement=True, write_excited_bins=True, sd_m2=0.0133):
    values = dict(PAPER.parameters if values is None else values)
    mt = mt or multitone()
    model = Model(parse_effects(effects), with_displacement=displacement)
    return synthesize_recording(model, values, mt.waveform, mt.excited_bins, mt.sample_rate, n_periods,
                                settle, noise, seed=seed, write_excited_bins=write_excited_bins,
                                driver={"name": "synthetic", "sd_m2": sd_m2})


# Noise that gives a realistic measurement: ~60-70 dB SNR on the lines.
TYPICAL_NOISE = ChannelNoise(voltage=1e-4, current=1e-4, displacement=1e-8)


# Real drivers measured by others: a data set kept beside the repository (its sibling folder
# "shared", data/real; or $LINPAR_SHARED/data/real), in CI too. Tests skip, saying why, without it.
REPO_ROOT = Path(__file__).resolve().parent.parent
REAL_DATA = Path(os.environ.get("LINPAR_SHARED", REPO_ROOT.parent / "shared")) / "data" / "real"


needs_pdftotext = pytest.mark.skipif(shutil.which("pdftotext") is None,
                                     reason="pdftotext is missing: install poppler-utils (tools/system-packages.sh)")


def pdf_text(pdf) -> str:
    """The text of a PDF as pdftotext lays it out (poppler-utils)."""
    return subprocess.run(["pdftotext", "-layout", str(pdf), "-"], check=True, capture_output=True,
                          text=True).stdout


class QuietJob:
    """What a job's work function uses of app.jobs.book.Job, for calling it outside a job: it says nothing and is
    never cancelled."""

    def say(self, text: str) -> None:
        pass

    def check(self) -> None:
        pass
