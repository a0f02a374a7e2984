"""Fuzzing the importers: whatever the text, a curve or an ImportFormatError, nothing else."""
import tempfile
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings, strategies as st

from analysis.importers import ImportFormatError, read_curve, read_uiv

SETTINGS = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
TOKENS = st.sampled_from(["1", "2.5", "-3", "1e3", "1e999", "nan", "inf", "0", "10,5", "abc", "Freq", "Z_rad",
                          "deg", "phase", "mm/V", "dB", "U_re", "I_im", "V_re", "f_Hz", "", " ", "*", "#", "\t",
                          ",", ";", "\r", "\n", "\x00", "°", "\ufeff", ".", "e", "+", "1_0", "0x1F", "١"])
CHUNKS = st.lists(TOKENS | st.text(max_size=5), max_size=60).map("".join)


def _table_text(data) -> str:
    """Valid tables (increasing frequencies, positive magnitudes, phases in range), half of them spoilt."""
    n_rows = data.draw(st.integers(1, 12))
    n_cols = data.draw(st.sampled_from([2, 3, 3, 7]))
    sep = data.draw(st.sampled_from([" ", "\t", ",", ";", "  "]))
    steps = data.draw(st.lists(st.floats(1e-3, 1e3), min_size=n_rows, max_size=n_rows))
    freqs = np.cumsum(steps)
    table = [[f] + [data.draw(st.floats(0.01, 100.0)) for _ in range(n_cols - 1)] for f in freqs]
    lines = [sep.join(repr(float(v)) for v in row) for row in table]
    if data.draw(st.booleans()):
        i = data.draw(st.integers(0, n_rows - 1))
        cells = lines[i].split(sep)
        cells[data.draw(st.integers(0, n_cols - 1))] = data.draw(TOKENS)
        lines[i] = data.draw(st.sampled_from([sep, " ", "\t"])).join(cells)
    if data.draw(st.booleans()):
        lines.insert(0, data.draw(st.sampled_from(["Freq Z_abs Z_rad", "* Freq(Hz) SPL(dB) Phase(degrees)",
                                                   "f_Hz,U_re,U_im,I_re,I_im,V_re,V_im", "a b", "# x"])))
    return "\n".join(lines)


def _check_everything_reads_or_refuses(raw: bytes) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "fuzz.txt"
        path.write_bytes(raw)
        for kind, phase, unit in (("impedance", None, None), ("impedance", "rad", None),
                                  ("displacement", "deg", "mm/V")):
            try:
                curve = read_curve(path, kind, phase, unit)
            except ImportFormatError as exc:
                assert "\n" not in str(exc) and str(path) in str(exc)
                continue
            tf = curve.transfer
            assert len(tf.freqs) >= 1 and np.all(tf.freqs > 0) and np.all(np.diff(tf.freqs) > 0)
            assert np.all(np.isfinite(tf.value.real)) and np.all(np.isfinite(tf.value.imag))
        try:
            uiv = read_uiv(path)
        except ImportFormatError as exc:
            assert "\n" not in str(exc)
        else:
            assert np.all(np.isfinite(uiv.impedance.value)) and np.all(np.isfinite(uiv.displacement.value))


@SETTINGS
@given(st.text(max_size=400))
def test_random_text(text):
    _check_everything_reads_or_refuses(text.encode("utf-8", "surrogatepass"))


@SETTINGS
@given(CHUNKS)
def test_random_tokens(text):
    _check_everything_reads_or_refuses(text.encode("utf-8", "surrogatepass"))


@SETTINGS
@given(st.binary(max_size=300))
def test_random_bytes(raw):
    _check_everything_reads_or_refuses(raw)


@SETTINGS
@given(st.data())
def test_nearly_valid_tables(data):
    _check_everything_reads_or_refuses(_table_text(data).encode("utf-8", "surrogatepass"))
