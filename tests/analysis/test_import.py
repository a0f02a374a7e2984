"""Importing curves: the formats tools write, the phase unit and why, refusals with file and line."""
import numpy as np
import pytest

from analysis.importers import ImportFormatError, read_curve, read_hx, read_impedance, read_uiv

F = np.array([10.0, 20.0, 45.0, 100.0, 1000.0])
MAG = np.array([7.1, 9.5, 29.0, 8.2, 12.0])
DEG = np.array([25.2, 40.1, 0.3, -30.5, 45.0])


def write(tmp_path, text, name="curve.txt"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def rows(sep=" ", phase=DEG, fmt="{:g}"):
    return "\n".join(sep.join(fmt.format(v) for v in row) for row in zip(F, MAG, phase)) + "\n"


def assert_curve(tf, phase_deg=DEG):
    assert tf.freqs.tolist() == F.tolist()
    np.testing.assert_allclose(np.abs(tf.value), MAG, rtol=1e-12)
    np.testing.assert_allclose(np.degrees(np.angle(tf.value)), phase_deg, rtol=1e-9, atol=1e-9)
    assert tf.has_phase and not tf.noise_known
    assert tf.bins.tolist() == list(range(len(F))) and np.all(np.isnan(tf.std))


def test_zma_with_star_comments_takes_degrees_from_the_comment(tmp_path):
    text = "*****\n* FILE: x.zma\n* Data: Impedance (ohms), Phase (degrees)\n*****\n" + rows("   ")
    curve = read_curve(write(tmp_path, text, "x.zma"))
    assert_curve(curve.transfer)
    assert curve.transfer.name == "impedance" and curve.transfer.unit == "ohm"
    assert any("degrees" in n and "comments" in n for n in curve.notes)


def test_frd_without_any_unit_assumes_degrees_and_says_so(tmp_path):
    curve = read_curve(write(tmp_path, rows("\t"), "x.frd"))
    assert_curve(curve.transfer)
    assert any("assumed" in n for n in curve.notes)


@pytest.mark.parametrize("header, sep", [
    ("* Freq(Hz), Impedance(ohms), Phase(degrees)", ", "),   # REW, comma
    ("* Freq(Hz)\tImpedance(ohms)\tPhase(degrees)", "\t"),    # REW, tab
    ("Frequency [Hz] ; |Z| [ohm] ; phase [deg]", " ; "),
])
def test_rew_and_headed_exports(tmp_path, header, sep):
    text = "* Measurement data measured by REW V5.20\n* Dated: 21 Feb, 2023\n" + header + "\n" + rows(sep)
    curve = read_curve(write(tmp_path, text))
    assert_curve(curve.transfer)
    assert any("header" in n for n in curve.notes), curve.notes


def test_radians_from_a_header_like_the_dayton_files(tmp_path):
    text = "Freq\tZ_abs\tZ_rad\r\n" + rows("\t", np.radians(DEG), "{:.15E}").replace("\n", "\r\n")
    curve = read_curve(write(tmp_path, text))
    assert_curve(curve.transfer)
    assert any("radians" in n and "Z_rad" in n for n in curve.notes)


def test_the_option_overrides_the_header_and_the_note_says_so(tmp_path):
    text = "f\tmag\tphase (rad)\n" + rows("\t")      # in fact degrees
    curve = read_curve(write(tmp_path, text), phase="deg")
    assert_curve(curve.transfer)
    assert any("overrides" in n for n in curve.notes)


@pytest.mark.parametrize("sep", [";", " ", "\t"])
def test_decimal_commas(tmp_path, sep):
    text = rows(sep, fmt="{:.4f}").replace(".", ",")
    assert_curve(read_impedance(write(tmp_path, text)), np.round(DEG, 4))


def test_real_and_imaginary_columns(tmp_path):
    z = MAG * np.exp(1j * np.radians(DEG))
    text = "freq,Re(Z),Im(Z)\n" + "\n".join(f"{float(f)!r},{float(v.real)!r},{float(v.imag)!r}" for f, v in zip(F, z))
    assert_curve(read_impedance(write(tmp_path, text)))


def test_magnitude_only(tmp_path):
    tf = read_impedance(write(tmp_path, "\n".join(f"{f} {m}" for f, m in zip(F, MAG))))
    assert not tf.has_phase
    np.testing.assert_array_equal(tf.value.real, MAG)


def test_a_bom_blank_lines_and_trailing_separators(tmp_path):
    text = "\ufeff# comment\n\n" + rows(",").replace("\n", ",\n") + "\n\n"
    assert_curve(read_impedance(write(tmp_path, text)))


def test_hx_in_mm_per_volt_by_option_or_header(tmp_path):
    hx_mm = np.array([0.3, 0.25, 0.1, 0.02, 0.001])
    body = "\n".join(f"{f} {m} {p}" for f, m, p in zip(F, hx_mm, -np.abs(DEG) * 3))
    by_option = read_hx(write(tmp_path, body), unit="mm/V")
    np.testing.assert_allclose(np.abs(by_option.value), hx_mm * 1e-3)
    assert by_option.name == "displacement" and by_option.unit == "m/V"
    by_header = read_curve(write(tmp_path, "f Hx(mm/V) phase(deg)\n" + body, "h.txt"), "displacement")
    np.testing.assert_allclose(np.abs(by_header.transfer.value), hx_mm * 1e-3)
    assert any("mm/V" in n for n in by_header.notes)
    assert np.abs(read_hx(write(tmp_path, body, "si.txt")).value)[0] == pytest.approx(0.3)   # m/V by default


@pytest.mark.parametrize("header, scale", [("Freq[Hz] Z[mOhm] Phase[deg]", 1e3), ("f |Z|(kΩ) phase(deg)", 1e-3),
                                           ("Freq[Hz] Z[Ohm] Phase[deg]", 1.0), ("f Impedance(ohms) deg", 1.0)])
def test_an_impedance_column_in_milliohm_or_kiloohm_is_converted_as_its_header_says(tmp_path, header, scale):
    """Z[mOhm] was read as ohm: RE 995 ohm, and the fit's fs and Q moved with it, with no word said."""
    body = "\n".join(f"{f} {m * scale} {p}" for f, m, p in zip(F, MAG, DEG))
    curve = read_curve(write(tmp_path, f"{header}\n{body}\n"), "impedance")
    assert_curve(curve.transfer)
    assert any("converted to ohm" in n for n in curve.notes) == (scale != 1.0)


def test_a_comment_that_quotes_milliohm_leaves_the_column_in_ohm(tmp_path):
    curve = read_curve(write(tmp_path, "# Rdc 5600 mOhm\nf Z phase\n" + rows()), "impedance")
    assert_curve(curve.transfer)


def test_a_table_written_from_the_top_of_the_band_down_is_read_turned_with_a_note(tmp_path):
    descending = "\n".join(rows().strip().splitlines()[::-1]) + "\n"
    curve = read_curve(write(tmp_path, descending), "impedance")
    assert_curve(curve.transfer)
    assert any("descending" in n for n in curve.notes)
    with pytest.raises(ImportFormatError, match="sort the file by frequency"):
        read_curve(write(tmp_path, rows() + "20 7.0 1\n", "dup.txt"), "impedance")


def test_hx_phase_may_be_unwrapped(tmp_path):
    body = "\n".join(f"{f} 1e-4 {p}" for f, p in zip(F, [-10, -90, -200, -400, -700]))
    assert read_hx(write(tmp_path, body)).has_phase


# --- complex U, I, V spectra -------------------------------------------------------------------------

def uiv_text(header=True, motion="V"):
    f = np.array([5.0, 50.0, 163.0, 500.0])
    U = np.array([1.0 + 0.1j, 0.9 - 0.2j, 1.1 + 0.0j, 0.8 + 0.3j])
    Z = np.array([5.0 + 0.5j, 8.0 + 3.0j, 50.0 + 0.0j, 6.0 - 2.0j])
    Hx = np.array([3e-4 - 1e-5j, 2e-4 - 1e-4j, -1e-4j, -1e-5 - 1e-6j])
    I, X = U / Z, Hx * U
    M = X * 2j * np.pi * f if motion == "V" else X
    lines = ["# converted spectra"] + ([f"f_Hz,U_re,U_im,I_re,I_im,{motion}_re,{motion}_im"] if header else [])
    lines += [",".join(repr(float(v)) for v in (fi, u.real, u.imag, i.real, i.imag, m.real, m.imag))
              for fi, u, i, m in zip(f, U, I, M)]
    return "\n".join(lines) + "\n", Z, Hx


@pytest.mark.parametrize("header, motion", [(True, "V"), (False, "V"), (True, "X")])
def test_uiv_gives_z_and_hx(tmp_path, header, motion):
    text, Z, Hx = uiv_text(header, motion)
    uiv = read_uiv(write(tmp_path, text, "m.csv"))
    np.testing.assert_allclose(uiv.impedance.value, Z, rtol=1e-12)
    np.testing.assert_allclose(uiv.displacement.value, Hx, rtol=1e-12)
    assert uiv.impedance.has_phase and not uiv.displacement.noise_known
    assert ("velocity" if motion == "V" else "displacement") in uiv.describe()


# --- refusals: one line, the file, the line number, what was expected ---------------------------------

GOOD = "10 7.1 25\n20 9.5 40\n"
BAD_FILES = [
    ("non-numeric", GOOD + "30 abc 1\n", 3, "non-numeric"),
    ("column count", GOOD + "30 7.0\n", 3, "columns"),
    ("not increasing", GOOD + "20 7.0 1\n", 3, "increasing"),
    ("zero frequency", "0 7.1 25\n" + "20 9.5 40\n", 1, "positive frequency"),
    ("negative frequency", "* c\n-10 7.1 25\n", 2, "positive frequency"),
    ("nan", GOOD + "30 nan 1\n", 3, "NaN"),
    ("infinite", GOOD + "30 1e999 1\n", 3, "finite"),
    ("negative magnitude", GOOD + "30 -7 1\n", 3, "positive value"),
    ("phase beyond 180 deg", GOOD + "30 7 200\n", 3, "out of range"),
    ("text after data", GOOD + "end of data\n", 3, "non-numeric"),
    ("one column", "10\n20\n", 1, "one column"),
    ("binary", "10 7 1\n\x00\x01", 2, "binary"),
    ("too many columns", "10 7 1 2 3\n", 1, "expected 2 or 3"),
    ("dB magnitude", "Freq(Hz) SPL(dB) Phase(deg)\n" + GOOD, 1, "dB"),
    ("U/I/V spectra", "f_Hz,U_re,U_im,I_re,I_im,V_re,V_im\n10,1,0,0.1,0,0.01,0\n", 1,
     "are all real: expected one; the header names voltage, current and laser spectra: read it as U/I/V spectra "
     "(linpar analyze --uiv FILE"),
    ("two real parts", "f,Z_re,Z_im,Y_re\n10,7,1,0.1\n", 1, "are all real: expected one"),
]


@pytest.mark.parametrize("name, text, line, words", BAD_FILES, ids=[b[0] for b in BAD_FILES])
def test_bad_files_are_refused_with_file_and_line(tmp_path, name, text, line, words):
    path = write(tmp_path, text, "bad.zma")
    with pytest.raises(ImportFormatError) as info:
        read_curve(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: line {line}: ") and words in message, message
    assert info.value.line == line and isinstance(info.value, ValueError)


@pytest.mark.parametrize("text, words", [("", "empty file"), ("* only\n# comments\n", "no data rows")])
def test_empty_files(tmp_path, text, words):
    with pytest.raises(ImportFormatError, match=words):
        read_curve(write(tmp_path, text))


def test_declared_radians_refuse_degree_values(tmp_path):
    with pytest.raises(ImportFormatError, match=r"line 2: phase 25 is out of range for radians.*degrees"):
        read_curve(write(tmp_path, "f |Z| Z_rad\n" + GOOD))


def test_a_missing_file(tmp_path):
    with pytest.raises(ImportFormatError, match="nope.zma: missing, expected a text file"):
        read_curve(tmp_path / "nope.zma")


@pytest.mark.parametrize("text, line, words", [
    ("f_Hz,U_re,U_im,I_re,I_im\n1,1,0,1,0\n", 1, "missing"),
    ("f_Hz,U_re,U_im,I_re,I_im,V_re,V_im,Q\n1,1,0,1,0,1,0,1\n", 1, "'Q' is not understood"),
    ("f_Hz,U_re,U_im,I_re,I_im,V_re,V_im\n1,1,0,0,0,1,0\n", 2, "current is zero"),
    ("1,1,0,1,0,1\n", 1, "no header"),
])
def test_bad_uiv_files(tmp_path, text, line, words):
    with pytest.raises(ImportFormatError) as info:
        read_uiv(write(tmp_path, text, "u.csv"))
    assert f"line {line}: " in str(info.value) and words in str(info.value)
