"""Other tools' curves (.zma, .frd, text tables, complex U/I/V CSV): a curve or one ImportFormatError line.

tests/analysis/test_import_fuzz.py feeds random text, tokens, bytes and
nearly valid tables to read_curve and read_uiv. This adds what it cannot
reach: the U/I/V header vocabulary in random orders with random spectra
(zeros, overflows), inputs big enough to expose super-linear parsing (a
field of 200,000 digits took minutes before the number pattern was made
unambiguous), things that are not files (a FIFO used to block forever), and
the command line: `linpar analyze --impedance/--uiv` on garbage exits 2
with one line on stderr, never a traceback.
"""
from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from analysis.importers import ImportFormatError, read_curve, read_uiv
from app.cli import main as linpar
from tests.reliability.fuzzing import FUZZ, FUZZ_FEW, one_line

pytestmark = pytest.mark.timeout(60)

READERS = {
    "impedance": lambda p: read_curve(p, "impedance"),
    "impedance-rad": lambda p: read_curve(p, "impedance", "rad"),
    "hx-mm": lambda p: read_curve(p, "displacement", "deg", "mm/V"),
    "uiv": read_uiv,
}


def read_all(path) -> None:
    """Every reader on one file: a complete, finite curve or a one-line error naming the file."""
    for name, read in READERS.items():
        try:
            out = read(path)
        except ImportFormatError as exc:
            one_line(exc, str(path))
            continue
        curves = (out.impedance, out.displacement) if name == "uiv" else (out.transfer,)
        for tf in curves:
            assert len(tf.freqs) >= 1 and np.all(np.diff(tf.freqs) > 0) and np.all(tf.freqs > 0)
            assert np.all(np.isfinite(tf.value))


UIV_NAMES = ["f_Hz", "Freq", "f", "U_re", "U_im", "I_re", "I_im", "V_re", "V_im", "X_re", "X_im", "Re(U)",
             "Im(I)", "u.real", "i imag", "V-re", "x_im", "U_re", "phase", "Z", ""]
NUMBERS = st.one_of(st.floats(-1e3, 1e3, allow_nan=False), st.sampled_from([0.0, 1e308, -1e308, 1e-308, 5e-324]))


@FUZZ
@given(names=st.lists(st.sampled_from(UIV_NAMES), min_size=1, max_size=9),
       rows=st.lists(st.lists(NUMBERS, min_size=9, max_size=9), min_size=1, max_size=6),
       sep=st.sampled_from([",", ";", "\t", " "]), increasing=st.booleans(),
       suffix=st.sampled_from([".csv", ".txt", ".zma", ".frd"]))
def test_uiv_headers_in_any_order_with_any_spectra(tmp_path_factory, names, rows, sep, increasing, suffix):
    path = tmp_path_factory.mktemp("uiv") / f"spectra{suffix}"
    lines = [sep.join(names)]
    for i, row in enumerate(rows):
        if increasing:
            row = [10.0 * (i + 1)] + row[1:]
        lines.append(sep.join(repr(v) for v in row[:len(names)]))
    path.write_text("\n".join(lines))
    read_all(path)


LONG_INPUTS = {
    "a field of 200000 digits then a letter": "f Z\n10 " + "1" * 200_000 + "x\n",
    "a field of digits, a dot and digits then a letter": "f Z\n10 " + "1" * 100_000 + "." + "2" * 100_000 + "x\n",
    "an exponent of 100000 digits": "10 1e" + "9" * 100_000 + "\n20 1\n",
    "a header of 100000 names": "\t".join(["U_re"] * 100_000) + "\n1\t2\n",
    "100000 columns": " ".join(["1"] * 100_000) + "\n",
    "200000 lines of one column": "1\n" * 200_000,
    "one line of 1 MB of separators": ";" * 1_000_000,
    "blanks then a letter": "10" + " " * 500_000 + "x\n",
    "200000 comment lines": "*\n" * 200_000 + "10 5\n20 6\n",
}


@pytest.mark.timeout(30)
@pytest.mark.parametrize("text", LONG_INPUTS.values(), ids=LONG_INPUTS.keys())
def test_large_hostile_files_are_handled_in_linear_time(tmp_path, text):
    path = tmp_path / "big.txt"
    path.write_text(text)
    read_all(path)


@FUZZ_FEW
@given(line=st.text(alphabet="0123456789.eE+-,; \t", min_size=1000, max_size=4000))
def test_long_lines_of_number_characters(tmp_path_factory, line):
    path = tmp_path_factory.mktemp("line") / "curve.frd"
    path.write_text(f"10 {line}\n20 {line}\n")
    read_all(path)


def test_things_that_are_not_text_files_are_refused_at_once(tmp_path):
    fifo = tmp_path / "curve.zma"
    os.mkfifo(fifo)            # with no writer, reading would block forever
    (tmp_path / "folder.frd").mkdir()
    for path in (fifo, tmp_path / "folder.frd", tmp_path / "missing.zma", "/dev/null"):
        for read in READERS.values():
            with pytest.raises(ImportFormatError) as info:
                read(path)
            one_line(info.value, str(path))


GARBAGE = {
    "binary": b"\x00\x01\x02\xff" * 10,
    "latin-1 text": "F\xe9q Z\n10 a\n".encode("latin-1"),
    "a table with NaN": b"10 5 0\n20 nan 0\n",
    "a header only": b"Freq Z Phase\n",
    "decreasing frequencies": b"20 5 0\n10 5 0\n",
    "a lying BOM": b"\xef\xbb\xbf\xef\xbb\xbf10 5\n",
}


@pytest.mark.parametrize("option", ["--impedance", "--uiv"])
@pytest.mark.parametrize("raw", GARBAGE.values(), ids=GARBAGE.keys())
def test_the_command_line_says_one_line_and_exits_2(tmp_path, capsys, option, raw):
    path = tmp_path / "curve.txt"
    path.write_bytes(raw)
    assert linpar(["analyze", option, str(path)]) == 2
    out, err = capsys.readouterr()
    assert err.startswith("linpar: error: ") and err.count("\n") == 1, err
    assert "Traceback" not in out + err
