"""The paper driver (lr2, creep-log) as File > Open curves… takes it: a CSV of complex U, I and laser velocity
spectra (`linpar analyze --uiv`) and the same impedance as a .zma, noise-free, 300 log-spaced lines 5 Hz-20 kHz."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from analysis.effects import parse_effects
from analysis.model.composed import Model
from tests.builders import PAPER, REAL_DATA

FREQS = np.logspace(np.log10(5.0), np.log10(20e3), 300)
# A real woofer's spectra (a laser on the cone), kept outside the repository: tests skip without it.
REAL_UIV = REAL_DATA / "woofer_uiv_laser" / "meas_data_UIV_spectra_1Hz-10kHz.csv"


def write_uiv_and_zma(folder: Path) -> tuple[Path, Path]:
    """(uiv.csv, z.zma) in `folder`."""
    model, p = Model(parse_effects("lr2,creep-log")), PAPER.parameters
    s = 2j * np.pi * FREQS
    z, hx = model.impedance(s, p), model.displacement(s, p)
    u = np.full(len(FREQS), 0.5 + 0.1j)
    rows = [f"{f!r},{x.real!r},{x.imag!r},{i.real!r},{i.imag!r},{v.real!r},{v.imag!r}"
            for f, x, i, v in zip(FREQS.tolist(), u.tolist(), (u / z).tolist(), (hx * u * s).tolist())]
    uiv, zma = folder / "uiv.csv", folder / "z.zma"
    uiv.write_text("# synthetic\nf_Hz,U_re,U_im,I_re,I_im,V_re,V_im\n" + "\n".join(rows) + "\n")
    zma.write_text("* Data: Impedance (ohms), Phase (degrees)\n" + "".join(
        f"{f:.9e} {abs(v):.12e} {np.degrees(np.angle(v)):.12e}\n" for f, v in zip(FREQS, z)))
    return uiv, zma
