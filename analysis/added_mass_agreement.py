"""Where the added-mass methods disagree beyond their uncertainties, said beside their tables.

`linpar addedmass` prints the joint fit and, as cross-checks, the model-free dual mass and the classical single
masses. On the SEAS L16RNX's three curves the joint fit gave Rms 1.395 ± 0.024 kg/s and Qms 3.12, the model-free
method Rms 2.1112 ± 0.0023 (Speakerbench's 2.1101), and nothing said which to believe. They measure different
things: the joint fit's model puts part of the suspension's loss in its creep, whose loss grows below fs; the
model-free and classical methods count every loss at fs in Rms, as the tools a user compares with report it.
Each uncertainty holds its own fit's scatter only; the spread between the methods is the model's part.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from analysis.added_mass import DISAGREE_PERCENT, DISAGREE_SIGMA, REPORTED, AddedMassResult, _units

LOSSES = ("Rms", "Qms")
LOSS_WHY = ("the joint fit's model ({model}) puts part of the suspension's loss in the creep (its loss grows "
            "below fs); {other} every loss at fs in Rms, as most tools report Rms and Qms: compare those with them")
MODEL_WHY = ("each 1-sigma holds its own fit's scatter only: the spread between the methods is what their models "
             "leave open (band, blocked impedance, creep): read it as the model's part of the uncertainty")


def _label(result: AddedMassResult) -> str:
    """The method's name, with its mass where several results share one (the classical method per mass)."""
    if result.method.startswith("single added mass") and result.masses_kg:
        return f"single added mass of {max(result.masses_kg) * 1e3:g} g"
    return result.method


def disagreements(primary: AddedMassResult, checks: Sequence[AddedMassResult]) -> list[str]:
    """A line per parameter on which a cross-check and the joint fit differ by more than DISAGREE_SIGMA combined
    sigmas and DISAGREE_PERCENT, then why they may (once per kind); [] when they agree."""
    lines, losses, others = [], [], []
    for name in REPORTED:
        a = primary.parameters.get(name)
        if a is None or a.value is None or a.value == 0:
            continue
        apart = []
        for check in checks:
            b = check.parameters.get(name)
            if b is None or b.value is None:
                continue
            diff = abs(a.value - b.value)
            combined = float(np.hypot(a.std or 0.0, b.std or 0.0))
            if 100 * diff / abs(a.value) > DISAGREE_PERCENT and (combined == 0 or diff > DISAGREE_SIGMA * combined):
                apart.append(check)
        if not apart:
            continue
        _, display, scale = _units(name)
        unit = f" {display}" if display not in ("", "-") else ""
        values = ", ".join(f"{r.parameters[name].value * scale:.4g}{unit} ({_label(r)})" for r in (primary, *apart))
        lines.append(f"{name} {values}")
        (losses if name in LOSSES else others).append(name)
    if losses:
        lines.append(f"{', '.join(losses)}: " + LOSS_WHY.format(
            model=primary.fit.model.describe() if primary.fit else "its model", other="other methods count"))
    if others:
        lines.append(f"{', '.join(others)}: {MODEL_WHY}")
    return lines
