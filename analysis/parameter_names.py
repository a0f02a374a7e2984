"""What people call the parameters, and the order they read them in: the GUI's table and the reports share it.

The Thiele-Small set comes first, in the order a speaker engineer reads a data sheet; the model's own
quantities (CMES, LCES, RES, L2, ...) follow under their code names.
"""
from __future__ import annotations

THIELE_SMALL = ("fs", "Qts", "Qes", "Qms", "Vas", "RE", "LE", "Bl", "Mms", "Cms", "Rms", "Kms", "Sd",
                "SPL_2.83V_1m", "SPL_1W_1m", "eta0")
# Where the code's name is not the customary one.
DISPLAY_NAMES = {"RE": "Re", "LE": "Le", "SPL_2.83V_1m": "Sensitivity (2.83 V, 1 m)",
                 "SPL_1W_1m": "Sensitivity (1 W into Re, 1 m)", "eta0": "η₀ (efficiency)"}


# The shown names that are a name too (a limits file may say Re for RE): not the sentences.
CODE_NAMES = {shown: name for name, shown in DISPLAY_NAMES.items() if shown.isidentifier()}


def display_name(name: str) -> str:
    return DISPLAY_NAMES.get(name, name)


def reading_order(names) -> list[str]:
    """`names` with the Thiele-Small ones first in THIELE_SMALL's order, then the others as given."""
    names = list(names)
    return [n for n in THIELE_SMALL if n in names] + [n for n in names if n not in THIELE_SMALL]
