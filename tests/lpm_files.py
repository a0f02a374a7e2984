"""Klippel dB-Lab curve exports written from a synthetic driver (the format described in issue 29; no real export).

    "Magnitude of electric impedance Z(f)"
    "Measured"		"Fitted"
    "Frequency [Hz]"	"[Ohm]"	"Frequency [Hz]"	"[Ohm]"
    1.953125	6.1234	1.953125	6.1207
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from analysis.effects import parse_effects
from analysis.model import Model
from tests.builders import PAPER

TITLES = {"impedance": "Magnitude of electric impedance Z(f)", "displacement": "Magnitude of transfer function Hx(f)"}
UNITS = {"impedance": ("Ohm", 1.0), "displacement": ("mm/V", 1e3)}
# Linearly spaced as dB-Lab's FFT lines: 1.953125 Hz apart up to 2 kHz (1024 lines).
FREQS = 1.953125 * np.arange(1, 1025)


def curve(kind: str, values: dict | None = None, effects: str = "lr2,creep-log", freqs=FREQS,
          noise: float = 0.0, seed: int = 0) -> np.ndarray:
    """|Z| in ohm or |Hx| in m/V of a driver (default: the paper's), with a relative noise."""
    model = Model(parse_effects(effects))
    s = 2j * np.pi * freqs
    values = PAPER.parameters if values is None else values
    v = np.abs(model.impedance(s, values) if kind == "impedance" else model.displacement(s, values))
    if noise:
        v = v * (1 + noise * np.random.default_rng(seed).standard_normal(len(v)))
    return v


def lpm_text(kind: str, measured: np.ndarray | None, fitted: np.ndarray | None = None, freqs=FREQS,
             unit: str | None = None) -> str:
    """The export's text; values in SI, written in the unit of the units line (Ohm; mm/V for Hx)."""
    name, scale = UNITS[kind]
    unit = unit or name
    curves = [(g, c) for g, c in (("Measured", measured), ("Fitted", fitted)) if c is not None]
    lines = [f'"{TITLES[kind]}"', "\t\t".join(f'"{g}"' for g, _ in curves) + "\t",
             "\t".join(f'"Frequency [Hz]"\t"[{unit}]"' for _ in curves) + "\t"]
    for i, f in enumerate(freqs):      # a shorter curve leaves its pair of fields empty
        lines.append("\t".join(f"{f:.6f}\t{c[i] * scale:.6g}" if i < len(c) else "\t" for _, c in curves) + "\t")
    return "\r\n".join(lines) + "\r\n"


def write_lpm(path: Path, kind: str, measured, fitted=None, freqs=FREQS, unit: str | None = None) -> Path:
    path.write_text(lpm_text(kind, measured, fitted, freqs, unit), encoding="latin-1")
    return path
