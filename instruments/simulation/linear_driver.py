"""The small-signal loudspeaker as two FIR filters, streamed block by block.

    current      = u * h_Y      Y(s) = 1 / Z(s)   (admittance, Model.impedance)
    displacement = u * h_Hx     Hx(s)             (Model.displacement)

Filter design: frequency sampling. The responses are evaluated on the
``fir_length`` bins of an FFT of that length and brought back to the time
domain with one inverse FFT; no window. Why no window: a periodic excitation
whose period divides ``fir_length`` (every multitone of 2**k samples up to
``fir_length``) only ever meets the filter at those bins, so the steady state
is then exact to rounding, whatever the length of the true impulse response
(its tail folds back onto the same bins). A window would trade that exactness
for smaller errors between the bins, which only a non-dividing period sees;
tests/instruments/simulation/test_linear_driver.py measures both cases.

DC: the creep laws diverge at w = 0 (log10(w) -> -inf), so bin 0 takes the
real part of bin 1 (at 48 kHz and 65,536 taps, 0.73 Hz). Nyquist: the real
part is used (a real filter cannot have an imaginary value there).

Causality: the filters are causal up to their circular wrap. A response that
is not causal (the real-valued creep-log law is not) puts its anticausal part
at the end of the FIR: a periodic steady state is still exact, a transient
shows that part ``fir_length`` samples late.

Convolution: uniformly partitioned overlap-save (UPOLS; Wefers, "Partitioned
convolution algorithms for real-time auralization", 2015). The FIR is cut into
partitions of ``partition_size`` taps; each input partition is transformed
once and kept in a frequency-domain delay line, and the contribution of every
older partition is summed once per completed partition. Calls whose blocks do
not line up with the partitions recompute only the newest partition's product
on the zero-padded partial block, so the output has no latency and a call
costs about one FFT pair plus, when it completes a partition, one
multiply-accumulate over the delay line: independent of how the stream is cut.

Silence: once the input has been zero for longer than the whole delay line
and the frame, every spectrum held is zero, and so is the output, exactly,
until the input is not. Such calls return zeros without transforming
anything: a virtual rig nobody plays to (2.5 ms of FFTs every 85 ms cycle
otherwise) leaves the cores to the window.
"""
from __future__ import annotations

from typing import Callable, Mapping

import numpy as np
import scipy.fft

from analysis.model.composed import Model
from instruments.simulation.block_driver import DriverBlock

DEFAULT_FIR_LENGTH = 65536
DEFAULT_PARTITION = 1024


def frequency_sampled_fir(response: Callable[[np.ndarray], np.ndarray], sample_rate: float,
                          length: int) -> np.ndarray:
    """The real FIR of ``length`` taps whose DFT equals ``response(j w)`` on every bin (see module doc)."""
    if length < 4 or length % 2:
        raise ValueError(f"the FIR length must be an even number >= 4, got {length}")
    k = np.arange(length // 2 + 1)
    s = 2j * np.pi * k[1:] * sample_rate / length
    spectrum = np.empty(k.size, dtype=np.complex128)
    spectrum[1:] = response(s)
    spectrum[0] = spectrum[1].real
    spectrum[-1] = spectrum[-1].real
    if not np.all(np.isfinite(spectrum)):
        bad = int(np.flatnonzero(~np.isfinite(spectrum))[0])
        raise ValueError(f"the response is not finite at {bad * sample_rate / length:g} Hz")
    return scipy.fft.irfft(spectrum, length)


def _trailing_zeros(x: np.ndarray) -> int:
    """How many samples at the end of `x` are zero (all of them for a silent block). A block being played ends
    on a sample that is not zero: answered without a search, which would index every sample of every block."""
    if x.size == 0 or x[-1] != 0.0:
        return 0
    if not x.any():
        return x.size
    return x.size - 1 - int(np.flatnonzero(x)[-1])


class PartitionedConvolver:
    """Several FIRs of equal length applied to one input stream, UPOLS, no latency.

    ``filters`` is (n_filters, n_taps); ``process(x)`` returns (n_filters, len(x)).
    """

    def __init__(self, filters: np.ndarray, partition_size: int = DEFAULT_PARTITION):
        filters = np.atleast_2d(np.asarray(filters, dtype=np.float64))
        if partition_size < 1:
            raise ValueError(f"partition_size must be positive, got {partition_size}")
        n_filters, taps = filters.shape
        self._B = B = int(partition_size)
        self._P = P = max(1, -(-taps // B))
        padded = np.zeros((n_filters, P * B))
        padded[:, :taps] = filters
        parts = np.zeros((n_filters, P, 2 * B))
        parts[:, :, :B] = padded.reshape(n_filters, P, B)
        self._H = scipy.fft.rfft(parts, axis=-1)           # (F, P, B+1)
        self._H0 = np.ascontiguousarray(self._H[:, 0])
        self._H_rest = np.ascontiguousarray(self._H[:, 1:])
        self._n_filters = n_filters
        # NB: the delay line is stored twice over (rows i and i+P) so that the
        # P newest spectra are always the contiguous rows head .. head+P-1.
        self._fdl = np.zeros((2 * P, B + 1), dtype=np.complex128)
        self._frame = np.zeros(2 * B)                      # [previous partition | current partition]
        self._tail = np.zeros((n_filters, B + 1), dtype=np.complex128)
        self._head = 0
        self._fill = 0
        # Zero input samples in a row up to now; from _quiet of them on, every spectrum held is zero (module doc).
        self._zero_run = self._quiet = (P + 2) * B

    @property
    def partition_size(self) -> int:
        return self._B

    def reset(self) -> None:
        self._fdl[:] = 0
        self._frame[:] = 0
        self._tail[:] = 0
        self._head = 0
        self._fill = 0
        self._zero_run = self._quiet

    def process(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=np.float64).ravel()
        trailing = _trailing_zeros(x)
        if trailing == x.size and self._zero_run >= self._quiet:
            # Silence into a silent state (module doc): the partitions it completes are zero, as is all held.
            self._fill = (self._fill + x.size) % self._B
            self._zero_run += x.size
            return np.zeros((self._n_filters, x.size))
        self._zero_run = self._zero_run + x.size if trailing == x.size else trailing
        out = np.empty((self._n_filters, x.size))
        B, pos = self._B, 0
        while pos < x.size:
            take = min(B - self._fill, x.size - pos)
            start = self._fill
            self._frame[B + start:B + start + take] = x[pos:pos + take]
            self._fill += take
            X = scipy.fft.rfft(self._frame)
            y = scipy.fft.irfft(X * self._H0 + self._tail, 2 * B, axis=-1)
            out[:, pos:pos + take] = y[:, B + start:B + start + take]
            pos += take
            if self._fill == B:
                self._complete_partition(X)
        return out

    def _complete_partition(self, X: np.ndarray) -> None:
        P, B = self._P, self._B
        self._head = (self._head - 1) % P
        self._fdl[self._head] = X
        self._fdl[self._head + P] = X
        if P > 1:
            # Contribution of the P-1 newest complete partitions to the next one.
            newest = self._fdl[self._head:self._head + P - 1]
            np.einsum("pk,fpk->fk", newest, self._H_rest, out=self._tail)
        self._frame[:B] = self._frame[B:]
        self._frame[B:] = 0.0
        self._fill = 0


class LinearBlockDriver:
    """A BlockDriver for the linear model: ``Model`` and its parameter values, as FIRs.

    ``fir_length`` taps per filter (65,536 at 48 kHz: 1.37 s, longer than the
    decay of any driver in resources/drivers except for the creep tail; see
    the module doc for what that length means for accuracy).
    """

    def __init__(self, model: Model, values: Mapping[str, float], sample_rate: int,
                 fir_length: int = DEFAULT_FIR_LENGTH, partition_size: int = DEFAULT_PARTITION):
        if sample_rate <= 0:
            raise ValueError(f"sample_rate must be positive, got {sample_rate}")
        if not model.with_displacement:
            raise ValueError("LinearBlockDriver needs a model with displacement (it simulates the laser too)")
        missing = [p.name for p in model.param_specs if p.name not in values]
        if missing:
            raise ValueError(f"values lack the model's parameters: {', '.join(missing)}")
        self.sample_rate = int(sample_rate)
        self.fir_length = int(fir_length)
        self.values = dict(values)
        self.model = model
        with np.errstate(divide="ignore", invalid="ignore"):
            h_admittance = frequency_sampled_fir(lambda s: 1.0 / model.impedance(s, self.values),
                                                 sample_rate, self.fir_length)
            h_displacement = frequency_sampled_fir(lambda s: model.displacement(s, self.values),
                                                   sample_rate, self.fir_length)
        self._convolver = PartitionedConvolver(np.stack([h_admittance, h_displacement]), partition_size)

    def process(self, voltage: np.ndarray) -> DriverBlock:
        u = np.array(voltage, dtype=np.float64).ravel()   # a copy: the block keeps it
        u.flags.writeable = False
        current, displacement = self._convolver.process(u)
        current.flags.writeable = False
        displacement.flags.writeable = False
        return DriverBlock(u, current, displacement)

    def reset(self) -> None:
        self._convolver.reset()

    def __repr__(self) -> str:
        return (f"LinearBlockDriver({self.model.describe()}, {self.sample_rate} Hz, "
                f"{self.fir_length} taps)")
