"""Did the displacement repeat from period to period, as the voltage that drove it did? Before its peak is trusted.

A step's peak excursion (analysis.excursion) is the peak of the coherent
mean of its periods. That is only the cone's peak when every period holds
the same motion: a laser stream placed at the wrong time for some periods
(the host times it is aligned by were late: a starved machine) averages one
period of the drive with a stretch that was not driven the same way, and the
mean's peak comes out low. The large-signal plan predicts its next level
from that peak, so a low one steps past the user's excursion limit.

The voltage's periods repeat (the card's own clock); the driver answers each
in the same way, so at the excited lines b each period's displacement is
H(b) times its voltage, H = mean(X) / mean(U). What is left,

    e_p = X_p - H U_p,   change^2 = (sum_b sum_p |e_p - mean(e)|^2 / (P - 1) - n_b s^2 (1 + 3 / sqrt(n_b (P - 1))))
                                   / sum_b |mean(X)|^2

is the relative rms change of one period's displacement that the drive does
not explain, less what the laser's noise explains: s^2, the scatter of one
line between periods, from the lines not excited (their distortion repeats,
so their scatter is noise), and three standard deviations of that noise's
own scatter over the n_b lines (so a displacement buried in noise is not
judged changed by chance). A voice coil that warms during a step changes the
displacement by a few percent at most; a misplaced stream by tens of percent.
"""
from __future__ import annotations

import numpy as np

from analysis.recording.format import Recording

# More than this and the step's displacement is not trusted (module doc).
MAX_DISPLACEMENT_CHANGE = 0.05


def displacement_change(recording: Recording) -> float | None:
    """The relative change of the displacement from period to period (module doc); None without a
    displacement channel or with fewer than two periods."""
    if recording.signal("displacement") is None or recording.n_periods < 2:
        return None
    x = np.fft.rfft(recording.periods("displacement"), axis=1)
    u = np.fft.rfft(recording.periods("voltage"), axis=1)
    excited = np.asarray(recording.excited_bins, dtype=np.int64)
    # Lines the displacement does not carry (above the laser's band: zero) weigh nothing either way.
    mean_x = x[:, excited].mean(axis=0)
    signal = float(np.sum(np.abs(mean_x) ** 2))
    if signal <= 0.0:
        return None
    p = x.shape[0]
    mean_u = u[:, excited].mean(axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = np.where(np.abs(mean_u) > 0, mean_x / mean_u, 0.0)
    e = x[:, excited] - h[None, :] * u[:, excited]
    scatter = float(np.sum(np.abs(e - e.mean(axis=0)) ** 2)) / (p - 1)
    noise = excited.size * _line_noise(x, excited) * (1.0 + 3.0 / np.sqrt(excited.size * (p - 1)))
    return float(np.sqrt(max(scatter - noise, 0.0) / signal))


def _line_noise(x: np.ndarray, excited: np.ndarray) -> float:
    """The scatter of one line between periods, from the lines within the band that are not excited."""
    others = np.setdiff1d(np.arange(excited[0], excited[-1] + 1), excited)
    carried = others[np.any(x[:, others] != 0, axis=0)] if others.size else others
    if carried.size == 0:
        return 0.0
    spread = np.sum(np.abs(x[:, carried] - x[:, carried].mean(axis=0)) ** 2, axis=0) / (x.shape[0] - 1)
    return float(np.mean(spread))
