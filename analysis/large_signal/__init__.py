"""Large-signal parameters: Bl(x), Kms(x), Le(x) (and L2(x), Le(i), Rms(v), creep) from multitone recordings
with the laser, the coil's rest offset and the excursion limits (docs/physics.md section 6).

    data.py         what a recording gives: periods, bands          columns.py   the equations as regressions
    weights.py      each line's noise and misfit                    solve.py     weighted least squares
    fitting.py      the state the searches share                    covariance.py  the coefficients' covariance
    identify.py     the identification (orders by BIC)              model.py     the result in SI, rest-centred
    curves.py       a curve with its band and range                 limits.py    offset, asymmetry, X_Bl, X_C, X_L
    simulate.py     the model's periodic steady state               distortion.py  residuals, predictions
    result.py       everything for one driver, and its JSON         words.py     the text a technician reads
    trust.py        whether a serial laser's delay was found (red when not)
"""
from analysis.large_signal.data import LargeSignalError
from analysis.large_signal.limits import LimitThresholds
from analysis.large_signal.result import LargeSignalResult, Prediction, large_signal

__all__ = ["LargeSignalError", "LargeSignalResult", "LimitThresholds", "Prediction", "large_signal"]
