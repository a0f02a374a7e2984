"""The GUI's Open curves… job reads and fits curves as `linpar analyze --impedance` (and `--uiv`) does (both
through analysis.curves.imported.import_curves): the same lines, the same numbers; a file given as the other kind
is named for what it is (app.jobs.curve_kinds)."""
import json
from pathlib import Path

import numpy as np
import pytest

from analysis.effects import parse_effects
from analysis.model.composed import Model
from app.cli import main
from analysis.importers import ImportFormatError
from app.jobs.curve_kinds import CURVES_CHOICE, UIV_CHOICE, CurvesKindError
from app.jobs.curves import CurvesRequest, analyse_curves
from tests.builders import PAPER, QuietJob
from tests.uiv_files import REAL_UIV, write_uiv_and_zma

# A linearly spaced export (1 Hz steps, as many analyzers write): the CLI thins it to 100 lines per decade.
FREQS = np.arange(5.0, 5001.0, 1.0)


@pytest.fixture(scope="module")
def linear_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("linear")
    model, p = Model(parse_effects("lr2,creep-log")), PAPER.parameters
    s = 2j * np.pi * FREQS
    wobble = 1 + 0.01 * np.random.default_rng(5).standard_normal((2, len(FREQS)))   # 1 % scatter
    z, hx = model.impedance(s, p) * wobble[0], model.displacement(s, p) * wobble[1]
    for name, curve, scale in (("z.txt", z, 1.0), ("hx.txt", hx, 1e3)):
        (d / name).write_text("".join(f"{f:.9e} {abs(v) * scale:.12e} {np.degrees(np.angle(v)):.12e}\n"
                                      for f, v in zip(FREQS, curve)))
    return d


def test_the_gui_job_fits_the_thinned_lines_the_cli_fits_and_finds_the_same_numbers(linear_files, capsys):
    gui = analyse_curves(QuietJob(), CurvesRequest(linear_files / "z.txt", linear_files / "hx.txt", True))
    code = main(["analyze", "--impedance", str(linear_files / "z.txt"), "--hx", str(linear_files / "hx.txt"),
                 "--mm-per-volt", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    cli = json.loads(out)["parameters"]

    decades = np.log10(FREQS[-1] / FREQS[0])
    assert len(gui.data.impedance.freqs) <= 100 * decades + 2        # not the file's 4,996 lines
    assert gui.files == (linear_files / "z.txt", linear_files / "hx.txt")
    gui_table = {name: p.value for name, p in gui.parameters.items()}
    for name in ("RE", "Bl", "fs", "Mms", "Kms", "Qts"):
        assert gui_table[name] == pytest.approx(cli[name]["value"], rel=1e-9), name


# -- U, I and laser spectra (File > Open curves…'s second kind, `linpar analyze --uiv`) -------------------------
@pytest.fixture(scope="module")
def uiv_files(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("uiv")
    write_uiv_and_zma(folder)
    return folder


def _same_as_the_cli(gui, uiv: Path, capsys) -> None:
    code = main(["analyze", "--uiv", str(uiv), "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    cli = json.loads(out)["parameters"]
    assert gui.files == (uiv,)
    for name in ("RE", "Bl", "fs", "Mms", "Kms", "Qts"):
        assert gui.parameters[name].value == pytest.approx(cli[name]["value"], rel=1e-9), name


def test_the_gui_job_fits_uiv_spectra_as_the_cli_does(uiv_files, capsys):
    request = CurvesRequest(uiv=uiv_files / "uiv.csv")
    assert request.path == request.uiv and request.name == "uiv.csv"
    gui = analyse_curves(QuietJob(), request)
    assert gui.data.displacement is not None          # Hx from the laser's velocity: Bl and the mechanics
    assert gui.parameters["Bl"].value == pytest.approx(PAPER.parameters["Bl"], rel=1e-3)
    _same_as_the_cli(gui, uiv_files / "uiv.csv", capsys)


@pytest.mark.skipif(not REAL_UIV.exists(), reason=f"the real U/I/V spectra are kept outside the repository and "
                                                    f"missing here: {REAL_UIV}")
def test_the_gui_job_fits_a_real_woofers_uiv_spectra_as_the_cli_does(capsys):
    _same_as_the_cli(analyse_curves(QuietJob(), CurvesRequest(uiv=REAL_UIV)), REAL_UIV, capsys)


@pytest.mark.parametrize("role", ["impedance", "hx"])
def test_uiv_spectra_given_as_a_curve_are_named_for_what_they_are(uiv_files, role):
    uiv = uiv_files / "uiv.csv"
    request = (CurvesRequest(uiv) if role == "impedance" else CurvesRequest(uiv_files / "z.zma", uiv))
    with pytest.raises(CurvesKindError) as caught:
        analyse_curves(QuietJob(), request)
    text = str(caught.value)
    assert text.startswith("uiv.csv holds complex U, I and laser spectra (f_Hz, U_re, U_im, I_re, I_im, V_re, V_im)")
    assert f"not {'an impedance' if role == 'impedance' else 'an Hx'} curve" in text
    assert f"choose “{UIV_CHOICE}”" in text and "--uiv" not in text and "\n" not in text


def test_an_impedance_curve_given_as_uiv_spectra_is_named_for_what_it_is(uiv_files):
    with pytest.raises(CurvesKindError) as caught:
        analyse_curves(QuietJob(), CurvesRequest(uiv=uiv_files / "z.zma"))
    text = str(caught.value)
    assert text.startswith("z.zma holds an impedance curve, not complex U, I and laser spectra")
    assert f"choose “{CURVES_CHOICE}” and give it as the impedance" in text and "\n" not in text


def test_a_file_of_neither_kind_keeps_the_importers_line(tmp_path):
    bad = tmp_path / "notes.csv"
    bad.write_text("f_Hz,colour\n10,red\n")
    for request in (CurvesRequest(bad), CurvesRequest(uiv=bad)):
        with pytest.raises(ImportFormatError) as caught:
            analyse_curves(QuietJob(), request)
        assert not isinstance(caught.value, CurvesKindError) and "notes.csv" in str(caught.value)
