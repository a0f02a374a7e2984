"""What a large-signal identification reads from a recording: its periods of u, i and x, and their bands.

Each recording gives its analysed periods (P x N) of voltage, current and
displacement, the excitation's lines (the sidecar's, or found in the voltage
spectrum as the linear analysis finds them: the format makes the list
optional), and the frequencies at which each equation is trusted:

- both equations from the first bin to the highest excited line (the
  excitation's band; beyond it there is only noise), and no higher than
  the laser's band (the sidecar's displacement_max_hz, with the serial
  laser): the mechanical equation is written on x, and the electrical one
  holds the back-EMF Bl(x) v, which beyond the laser's band is not
  measured. Written there with v missing, its lines read the back-EMF left
  out (0.2 ohm at 2 kHz for the demo driver, 5 % of |Z|) as resistance and
  inductance: at the lowest step of a plan, where that misfit stays below
  the noise's significance (weights.misfit_variance), RE came out +3 to
  +10 % and Bl(0), Kms(0) -0.7 to -2.9 %; cut at the band, within 0.01 %.

The displacement is band-limited to those lines before it is
differentiated (v = dx/dt, a = dv/dt in the frequency domain, exact for a
periodic signal): the laser's noise above it would otherwise rise as f and
f^2 into the velocity and the acceleration, where no signal is.

x is taken as the laser gives it: an arbitrary offset (the serial laser's
stream has its mean removed) is the identification's to find (identify.py:
the rest position from the static force balance).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from analysis.errors import LinparError
from analysis.recording.format import MIN_PERIODS, Recording
from analysis.spectra import SpectrumError, displacement_max_hz, excited_lines
from analysis.serial_laser import from_serial_laser


class LargeSignalError(LinparError, ValueError):
    """Recordings, options or limits that cannot give large-signal curves (no laser, too few periods, ...).
    One line."""


@dataclass(frozen=True, slots=True, eq=False)
class RecordingData:
    """The periods of one recording, in SI units, ready for the regressors."""

    label: str
    sample_rate: float
    u: np.ndarray               # (P, N) V
    i: np.ndarray               # (P, N) A
    x: np.ndarray               # (P, N) m, as measured (offset unknown), band-limited
    electrical_bins: np.ndarray  # 1 .. highest excited bin, cut at the laser's band (module doc)
    mechanical_bins: np.ndarray  # the same
    excited_bins: np.ndarray
    laser_delay_possible: bool  # the displacement came from a serial laser, on a clock of its own

    @property
    def n_periods(self) -> int:
        return self.u.shape[0]

    @property
    def period_samples(self) -> int:
        return self.u.shape[1]

    @property
    def bin_width(self) -> float:
        return self.sample_rate / self.period_samples

    def mean(self, name: str) -> np.ndarray:
        return getattr(self, name).mean(axis=0)


def recording_data(recording: Recording, label: str | None = None) -> RecordingData:
    """The periods and bands of one recording; LargeSignalError when it cannot serve (one line)."""
    name = label or (recording.source.name if recording.source else "recording")
    if recording.signal("displacement") is None:
        raise LargeSignalError(f"{name}: no displacement channel: the large-signal curves are identified "
                               f"from the measured cone position, which needs the laser")
    if recording.n_periods < MIN_PERIODS:
        raise LargeSignalError(f"{name}: {recording.n_periods} analysed period(s); at least {MIN_PERIODS} are "
                               f"needed for the noise of each line")
    u, i, x = (np.array(recording.periods(s), dtype=np.float64) for s in ("voltage", "current", "displacement"))
    for signal, values in (("voltage", u), ("current", i), ("displacement", x)):
        if not np.all(np.isfinite(values)):
            raise LargeSignalError(f"{name}: the {signal} holds samples that are not finite numbers")
    n = recording.period_samples
    try:
        excited = excited_lines(recording)
    except SpectrumError as exc:
        raise LargeSignalError(f"{name}: {exc}") from None
    top = int(excited[-1])
    bin_width = recording.sample_rate / n
    x_max_hz = displacement_max_hz(recording, LargeSignalError)
    x_top = top if x_max_hz is None else min(top, int(math.floor(x_max_hz / bin_width)))
    if x_top < 4:
        raise LargeSignalError(f"{name}: the displacement's band ({x_max_hz} Hz) holds no line of the excitation")
    spectrum = np.fft.rfft(x, axis=1)
    spectrum[:, x_top + 1:] = 0.0         # nothing of the driver's motion is measured beyond either band
    x = np.fft.irfft(spectrum, n, axis=1)
    lines = np.arange(1, x_top + 1)
    return RecordingData(name, float(recording.sample_rate), u, i, x, lines, lines, excited,
                         from_serial_laser(recording))


def peak_to_peak(data: RecordingData, offset: float = 0.0) -> tuple[float, float]:
    """(min, max) of the coherent mean period's x + offset, m: the range the curves rest on."""
    x = data.mean("x") + offset
    return float(x.min()), float(x.max())
