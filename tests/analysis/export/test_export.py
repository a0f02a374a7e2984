"""Exports: CSV and JSON parameters, .zma/.frd curves that read back through analysis.importers."""
import csv
import io
import json

import numpy as np
import pytest

from analysis.archive.results import StoredResult, results_document
from analysis.export import ExportError, export_bytes, write_exports
from analysis.importers import read_curve
from analysis.importers.table import read_table
from analysis.pipeline import analyze_recording
from tests.builders import TYPICAL_NOISE, recording


@pytest.fixture(scope="module")
def stored():
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=5)
    return StoredResult.from_json(json.loads(json.dumps(results_document(analyze_recording(rec), rec))))


@pytest.fixture(scope="module")
def z_only():
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=6, displacement=False)
    return StoredResult.from_json(results_document(analyze_recording(rec), rec))


def test_measured_zma_reads_back_equal_through_the_importer(tmp_path, stored):
    path = tmp_path / "z.zma"
    write_exports(stored, {"zma": path})
    curve = read_curve(path, "impedance")
    z = stored.curves["impedance"]
    np.testing.assert_array_equal(curve.transfer.freqs, z.freqs)
    np.testing.assert_allclose(np.abs(curve.transfer.value), np.abs(z.measured), rtol=1e-15)
    np.testing.assert_allclose(curve.transfer.value, z.measured, rtol=1e-14)
    assert curve.transfer.has_phase
    assert any("degrees" in note and "header" in note for note in curve.notes)


def test_model_zma_is_the_model_on_a_dense_grid_over_the_measured_band(tmp_path, stored):
    path = tmp_path / "m.zma"
    write_exports(stored, {"zma_model": path})
    t = read_curve(path, "impedance").transfer
    band = stored.curves["impedance"].freqs
    assert t.freqs[0] == pytest.approx(band.min()) and t.freqs[-1] == pytest.approx(band.max())
    assert len(t.freqs) > 250
    np.testing.assert_allclose(t.value, stored.model_curve("impedance", t.freqs), rtol=1e-14)
    assert np.abs(t.value).max() == pytest.approx(np.abs(stored.curves["impedance"].measured).max(), rel=0.02)


def test_frd_is_the_predicted_spl_with_phase(tmp_path, stored):
    from analysis.spl import predicted_spl
    path = tmp_path / "s.frd"
    write_exports(stored, {"frd": path, "frd_model": tmp_path / "sm.frd"})
    table = read_table(path)
    assert table.header == ("Freq(Hz)", "SPL(dB)", "Phase(deg)")
    hx = stored.curves["displacement"]
    np.testing.assert_array_equal(table.values[:, 0], hx.freqs)
    np.testing.assert_allclose(table.values[:, 1], predicted_spl(hx.freqs, hx.measured, stored.sd_m2), rtol=1e-15)
    assert np.all(np.abs(table.values[:, 2]) <= 180)
    model = read_table(tmp_path / "sm.frd").values
    # The paper driver: about 94 dB at 2.83 V in the piston band.
    assert model[:, 1].max() == pytest.approx(stored.parameters["SPL_2.83V_1m"].value, abs=1.0)


def test_frd_needs_hx_and_sd(z_only):
    with pytest.raises(ExportError, match="displacement"):
        export_bytes("frd", z_only)


def csv_rows(data: bytes) -> list[dict]:
    """The rows of a CSV export, its '#' comment lines skipped as any reader of it would."""
    return list(csv.DictReader(line for line in io.StringIO(data.decode()) if not line.startswith("#")))


def test_parameters_csv_and_json(stored):
    rows = csv_rows(export_bytes("csv", stored))
    by_name = {r["parameter"]: r for r in rows}
    assert list(by_name) == list(stored.parameters)
    mms = by_name["Mms"]
    assert (mms["unit"], mms["display_unit"]) == ("kg", "g")
    assert float(mms["value"]) == stored.parameters["Mms"].value
    assert float(mms["display_value"]) == pytest.approx(1e3 * float(mms["value"]))
    assert float(mms["std"]) > 0
    doc = json.loads(export_bytes("json", stored, {"driver": "d", "serial": "s"}))
    assert doc["format"] == "linpar-parameters/1" and doc["driver"] == {"driver": "d", "serial": "s"}
    assert doc["parameters"]["fs"]["value"] == stored.parameters["fs"].value
    assert set(doc["model"]["chi2_red"]) == {"impedance", "displacement"}


def test_missing_parameters_are_empty_with_a_reason(z_only):
    rows = {r["parameter"]: r for r in csv_rows(export_bytes("csv", z_only))}
    assert rows["Bl"]["value"] == "" and "displacement" in rows["Bl"]["note"]


def test_one_failing_export_writes_no_file(tmp_path, z_only):
    with pytest.raises(ExportError):
        write_exports(z_only, {"csv": tmp_path / "p.csv", "frd": tmp_path / "s.frd"})
    assert list(tmp_path.iterdir()) == []


def test_the_parameters_csv_carries_the_traceability_header(stored):
    header = {"driver": "W6", "serial": "SN-7", "measured_at": "2026-01-02T03:04:05Z", "operator": "A. Tester",
              "station": "bench-2", "template": "woofer", "software": "linpar 9.9"}
    text = export_bytes("csv", stored, header).decode()
    comments = [line for line in text.splitlines() if line.startswith("#")]
    assert text.startswith("# linpar parameters") and len(comments) == 2 + len(header)
    for value in header.values():
        assert sum(value in line for line in comments) == 1
    assert comments[-1].startswith("# exported by linpar")
    first_row = text.splitlines()[len(comments)]
    assert first_row == "parameter,value,std,unit,display_value,display_std,display_unit,note,std_noise,std_model"
