"""The large-signal model (analysis.large_signal.model) that a NonlinearBlockDriver is: the truth of the tests."""
from __future__ import annotations

import numpy as np

from analysis.large_signal.curves import Curve
from analysis.large_signal.model import LargeSignalModel, Scalar


def truth_model(driver, x_range=(-4e-3, 4e-3)) -> LargeSignalModel:
    """The simulator's curves and constants as a LargeSignalModel (no creep: the simulator's creep acts on its
    small-signal part only, which no large-signal model matches)."""
    p = driver.values
    bl0, le0 = p["Bl"], p["LE"]
    k0, l20 = bl0**2 / p["LCES"], p.get("L2", 0.0)

    def curve(name, c0, relative):
        c = np.concatenate([[c0], c0 * np.asarray(relative, dtype=float)])
        return Curve(name, c, np.zeros((c.size, c.size)), x_range)
    curves = {"Bl": curve("Bl", bl0, driver.bl_poly), "Kms": curve("Kms", k0, driver.kms_poly),
              "Le": curve("Le", le0, driver.le_poly)}
    if l20:
        curves["L2"] = curve("L2", l20, driver.l2_poly)
    rms = bl0**2 / p["RES"]
    scalars = {"RE": Scalar(p["RE"], 0.0), "R2": Scalar(p.get("R2", 0.0), 0.0),
               "Mms": Scalar(p["CMES"] * bl0**2, 0.0), "Rms": Scalar(rms, 0.0)}
    tau2 = l20 / p["R2"] if l20 else 1e-4
    return LargeSignalModel(curves, scalars, tau2, 0.0, 1.0, (le0 * driver.le_i_poly[0], le0 * driver.le_i_poly[1]),
                            rms * driver.rms_v2, 0.0, x_range)
