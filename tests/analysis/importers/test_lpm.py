"""Klippel dB-Lab exports in (analysis.importers.lpm): the measured curve fitted, the fitted one kept; bad input
refused with one line naming the file and the line."""
from __future__ import annotations

import numpy as np
import pytest

from analysis.curves.fitting import FitRange, fit_curves
from analysis.importers import ImportFormatError, read_curve
from tests.builders import PAPER
from tests.lpm_files import FREQS, curve, lpm_text, write_lpm


@pytest.fixture(scope="module")
def exports(tmp_path_factory):
    """The paper's driver measured with 0.3 % noise, beside a 'fitted' curve of a driver 2 % stiffer."""
    d = tmp_path_factory.mktemp("lpm")
    stiffer = {**PAPER.parameters, "LCES": PAPER.parameters["LCES"] / 1.02}
    z = write_lpm(d / "Z.txt", "impedance", curve("impedance", noise=0.003, seed=1), curve("impedance", stiffer))
    hx = write_lpm(d / "HX.txt", "displacement", curve("displacement", noise=0.003, seed=2),
                   curve("displacement", stiffer))
    return z, hx


def test_an_export_is_recognised_its_measured_curve_read_magnitude_only_the_fitted_kept(exports):
    z_path, hx_path = exports
    z, hx = read_curve(z_path, "impedance"), read_curve(hx_path, "displacement")
    assert not z.transfer.has_phase and not hx.transfer.has_phase
    assert np.allclose(z.transfer.freqs, FREQS)
    assert np.allclose(np.abs(z.transfer.value), curve("impedance", noise=0.003, seed=1), rtol=1e-5)
    assert np.allclose(np.abs(hx.transfer.value), curve("displacement", noise=0.003, seed=2), rtol=1e-5)  # mm/V -> m/V
    assert z.reference is not None and not np.allclose(z.reference.value.real, z.transfer.value.real)
    said = z.describe()
    assert "magnitude only" in said and "the export has no phase" in said and "kept for comparison" in said
    assert "mm/V" in hx.describe()


def test_the_measured_columns_give_the_driver_back_not_the_fitted_ones(exports):
    z, hx = (read_curve(p, k).transfer for p, k in zip(exports, ("impedance", "displacement")))
    result = fit_curves(z, hx, "lr2,creep-log", 0.0133, FitRange(hx_f_max=500.0))
    truth = PAPER.parameters
    for name in ("RE", "Bl", "LCES", "CMES"):
        assert result.fit.values[name] == pytest.approx(truth[name], rel=0.01), name
    assert 0.1 < result.validity.fit_error_percent["impedance"] < 1.0       # the 0.3 % noise, not the model


def test_a_shorter_fitted_curve_leaves_its_fields_empty_and_is_read(tmp_path):
    path = write_lpm(tmp_path / "Z.txt", "impedance", Z[:40], Z[:25], FREQS[:40])
    curve_read = read_curve(path, "impedance")
    assert len(curve_read.transfer.freqs) == 40 and len(curve_read.reference.freqs) == 25


def test_an_hx_export_given_as_impedance_says_which_option(exports):
    with pytest.raises(ImportFormatError, match=r"HX.txt: a Klippel export of Hx .* give it as --hx"):
        read_curve(exports[1], "impedance")


Z = curve("impedance")


def broken(kind="impedance", measured=Z, fitted=Z, **replace):
    text = lpm_text(kind, measured, fitted)
    lines = text.split("\r\n")
    for number, new in replace.items():
        lines[int(number.removeprefix("line")) - 1] = new
    return "\r\n".join(lines)


BAD = [
    ("missing column", broken(line5="3.906250\t6.2\t3.906250\t"), r"line 5: column 4 is missing"),
    ("missing value column", broken(line3='"Frequency [Hz]"\t"[Ohm]"\t"Frequency [Hz]"'),
     r"line 3: 3 unit fields: expected a frequency and a value column per curve"),
    ("unknown unit", broken(line3='"Frequency [Hz]"\t"[kOhm]"\t"Frequency [Hz]"\t"[kOhm]"'),
     r"line 3: column 2: unknown unit 'kOhm'"),
    ("text for a number", broken(line7="7.812500\tn/a\t7.812500\t6.1"),
     r"line 7: column 2: non-numeric field 'n/a': expected a number"),
    ("fitted only", lpm_text("impedance", None, Z), r"line 2: only a fitted curve: expected a \"Measured\" column"),
    ("groups for pairs", broken(line2='"Measured"'), r"line 2: 1 column groups .* for 2 frequency/value pairs"),
    ("no frequency", broken(line3='"f"\t"[Ohm]"\t"Frequency [Hz]"\t"[Ohm]"'),
     r"line 3: column 1: 'f': expected \"Frequency \[Hz\]\""),
    ("decreasing", broken(line6="1.000000\t6.2\t1.000000\t6.2"), r"line 6: frequency 1 Hz is not above"),
]


@pytest.mark.parametrize("what, text, message", BAD, ids=[b[0] for b in BAD])
def test_bad_exports_give_one_line_naming_the_file_and_the_line(tmp_path, what, text, message):
    path = tmp_path / "Z.txt"
    path.write_text(text, encoding="latin-1")
    with pytest.raises(ImportFormatError, match=message) as err:
        read_curve(path, "impedance")
    assert str(err.value).startswith(f"{path}: ") and "\n" not in str(err.value)


def test_the_tools_own_fit_error_is_said(tmp_path):
    path = write_lpm(tmp_path / "Z.txt", "impedance", Z, Z * 1.02)
    assert "misses the measured curve by 2 % rms (its fit error)" in read_curve(path, "impedance").describe()


def test_a_mangled_export_is_read_or_refused_in_one_line_never_crashes(tmp_path):
    """300 exports with lines dropped, fields cut, characters replaced: each is read whole or gives one line."""
    rng = np.random.default_rng(7)
    base = lpm_text("impedance", Z[:40], Z[:30], FREQS[:40]).split("\r\n")
    path = tmp_path / "Z.txt"
    refused = 0
    for _ in range(300):
        lines = list(base)
        for _ in range(int(rng.integers(1, 4))):
            i = int(rng.integers(0, len(lines)))
            kind = rng.integers(0, 4)
            if kind == 0:
                del lines[i]
            elif kind == 1 and lines[i]:
                lines[i] = lines[i][: int(rng.integers(0, len(lines[i])))]
            elif kind == 2 and lines[i]:
                j = int(rng.integers(0, len(lines[i])))
                lines[i] = lines[i][:j] + str(rng.choice(list('\t"x-.e[]0;, '))) + lines[i][j + 1:]
            else:
                lines.insert(i, lines[int(rng.integers(0, len(lines)))])
        path.write_text("\r\n".join(lines), encoding="latin-1")
        try:
            read_curve(path, "impedance")
        except ImportFormatError as exc:
            refused += 1
            assert "\n" not in str(exc) and str(exc).startswith(str(path))
    assert 30 < refused < 300
