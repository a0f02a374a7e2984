"""Whether the numbers fitted to imported curves can be a driver's, judged as a recording's are
(analysis.validity.plausibility): red (or yellow) with the likely cause and its remedy.

Imported curves hold no signals to check (analysis.validity.imported_curves), but their numbers can still be
no driver's. A plain |Hx| table in mm/V read as m/V (a table does not say its unit) fits cleanly to Bl 0.014
T·m, Mms 0.06 mg and eta0 56,000 %; printed as they are, beside "validity: unknown", they read as a result.
"""
from __future__ import annotations

from typing import Mapping

from analysis.curves.findings import with_curve_findings
from analysis.derived import ParameterValue
from analysis.validity.plausibility import mechanical_findings
from analysis.validity.result import ResultValidity

HX_SCALE = ("the Hx curve's magnitude looks like mm/V read as m/V (a plain table does not say its unit): give "
            "--mm-per-volt (in the window: Open curves, 'Hx in mm/V') and fit again")


def judged_plausible(validity: ResultValidity, parameters: Mapping[str, ParameterValue],
                     sd_m2: float | None) -> ResultValidity:
    """`validity` with the findings of numbers no driver has on the displacement (the channel the mass and the
    efficiency come from); its overall light the worst of them where there are any."""
    return with_curve_findings(validity, mechanical_findings(parameters, sd_m2, None, x_scale=HX_SCALE))
