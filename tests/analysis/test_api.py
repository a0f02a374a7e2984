"""The library's front door (analysis.api, through the `analysis` namespace): what it gives is what the CLI gives.

`import analysis` loads nothing until a name is used; analyze, diagnose and import_curves take paths, recordings
or curves with keyword-only options; synthesize makes the recording it is told to; results say themselves as
the CLI prints them (the CLI only prints result.report() / result.as_json()).
"""
from __future__ import annotations

import json

import numpy as np
import pytest

import analysis
from analysis.json_finite import dumps
from analysis.recording.format import write_recording
from app.cli.boundary import main as cli
from tests.fresh_import import loaded_by_import


def test_importing_analysis_loads_only_its_table_of_names():
    assert loaded_by_import("analysis", "analysis.") == ["analysis.lazy_exports"]


def test_every_public_name_is_its_home_modules_own():
    import importlib
    for name in analysis.__all__:
        home = importlib.import_module(f"analysis.{analysis._HOME[name]}")
        assert getattr(analysis, name) is getattr(home, name)
    with pytest.raises(AttributeError, match="no attribute 'analyse'"):
        analysis.analyse        # noqa: B018


def test_options_are_keyword_only():
    rec = analysis.synthesize(n_periods=2, period_samples=4096)
    with pytest.raises(TypeError):
        analysis.analyze(rec, 0.0133)           # noqa: the point: Sd must be named
    with pytest.raises(TypeError):
        analysis.synthesize("paper")


@pytest.fixture(scope="module")
def noisy(tmp_path_factory):
    """A recording of the paper's driver, with a realistic noise, written to a file too."""
    rec = analysis.synthesize(driver="paper", noise=analysis.TYPICAL_NOISE, n_periods=4, seed=7)
    path = tmp_path_factory.mktemp("api") / "paper"
    write_recording(path, rec)
    return rec, path


def test_synthesize_makes_what_it_is_told(noisy):
    rec, _ = noisy
    assert rec.sample_rate == 48000 and rec.period_samples == 16384 and rec.n_periods == 4
    assert rec.driver["sd_m2"] == pytest.approx(0.0133)
    # The voltage is the multitone asked for: 1 V RMS, up to the noise.
    assert np.sqrt(np.mean(rec.signal("voltage") ** 2)) == pytest.approx(1.0, rel=0.01)
    with pytest.raises(analysis.LinparError, match="L3, R3"):
        analysis.synthesize(effects="lr3,creep-log")          # the paper's driver has no second branch


def test_a_path_and_a_recording_give_the_cli_s_json_and_text(noisy, capsys):
    rec, path = noisy
    from_path = analysis.analyze(path)
    from_memory = analysis.analyze(rec)
    assert from_path.parameters["Bl"].value == pytest.approx(from_memory.parameters["Bl"].value, rel=1e-6)
    assert cli(["analyze", str(path), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == json.loads(dumps(from_path.as_json()))
    assert cli(["analyze", str(path)]) == 0
    assert capsys.readouterr().out == from_path.report() + "\n"


def test_a_driver_s_parameters_come_back_within_their_uncertainty(noisy):
    rec, _ = noisy
    result = analysis.analyze(rec)
    truth = analysis.load_driver("paper").parameters
    for name in ("RE", "Bl", "CMES", "LCES", "RES"):
        p = result.parameters[name]
        assert abs(p.value - truth[name]) <= 3 * p.std, name


def test_imported_curves_are_analysed_and_diagnosed_as_the_cli_does(tmp_path, capsys):
    # Z of the paper's driver as a .zma text (frequency, magnitude, phase in degrees), with 0.2 % scatter.
    model = analysis.load_driver("paper").model(with_displacement=False)
    f = np.geomspace(10, 10000, 300)
    z = model.impedance(2j * np.pi * f, analysis.load_driver("paper").parameters)
    z *= 1 + 0.002 * np.random.default_rng(3).standard_normal(f.size)
    zma = tmp_path / "paper.zma"
    zma.write_text("".join(f"{a:.6g} {abs(b):.6g} {np.degrees(np.angle(b)):.6g}\n" for a, b in zip(f, z)))
    curves = analysis.import_curves(zma)
    result = analysis.analyze(curves)
    assert result.parameters["RE"].value == pytest.approx(3.02, rel=0.01)
    assert cli(["analyze", "--impedance", str(zma)]) == 0
    assert capsys.readouterr().out == result.report() + "\n"
    found = analysis.diagnose(curves, start="lr2", parallel=False)
    assert cli(["diagnose", "--impedance", str(zma), "--from", "lr2", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["verdict"] == found.verdict == found.as_json()["verdict"]
    assert found.report().startswith("verdict: ")


def test_curves_given_the_wrong_way_are_one_clear_error(tmp_path):
    with pytest.raises(analysis.LinparError, match="Hx alone cannot be fitted"):
        analysis.import_curves(hx=tmp_path / "hx.txt")
    with pytest.raises(analysis.LinparError, match="uiv carries both"):
        analysis.import_curves(tmp_path / "z.zma", uiv=tmp_path / "u.csv")
    with pytest.raises(analysis.LinparError, match="not a phase unit"):
        analysis.import_curves(tmp_path / "z.zma", phase="grad")
