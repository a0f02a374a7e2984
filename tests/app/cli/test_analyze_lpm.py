"""`linpar analyze --impedance Z.txt --hx HX.txt --json` on Klippel LPM-like exports of realistic drivers (issue 29):
RE, fs, Qts, Qes, Qms, Bl, Mms and Cms within 5 % of the truth with default options, each within 2 of its
reported std (noise and model parts)."""
import json

import pytest

from app.cli import main
from tests.lpm_exports import DRIVERS, EIGHT, truth, write_exports


@pytest.fixture(scope="module")
def analysed(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lpm")
    cache = {}

    def run(name):
        if name not in cache:
            z, hx = write_exports(folder, name)
            cache[name] = main(["analyze", "--impedance", str(z), "--hx", str(hx), "--json"])
        return cache[name]
    return run


@pytest.mark.parametrize("name", sorted(DRIVERS))
def test_the_eight_parameters_within_5_percent_and_their_std_covers_the_truth(analysed, capsys, name):
    code = analysed(name)
    doc = json.loads(capsys.readouterr().out)
    assert code == 0
    assert doc["model"]["method"] == "alternating"
    truth_ = truth(DRIVERS[name])
    for key in EIGHT:
        p = doc["parameters"][key]
        assert p["value"] == pytest.approx(truth_[key], rel=0.05), key
        assert abs(p["value"] - truth_[key]) <= 2 * p["std"], (key, p)
        assert p["std_model"] > 0 and p["std_noise"] > 0, key       # both parts named
        assert p["std"] < 0.1 * abs(p["value"]), key                 # and not so wide that it says nothing
    # The export's own fitted curves (LPM's "Fitted" columns) beside linpar's.
    assert set(doc["reference_fit"]) == {"impedance", "displacement"}


def test_the_text_says_the_exports_own_fit_beside_linpars_before_the_notes(tmp_path, capsys):
    z, hx = write_exports(tmp_path, "woofer")
    assert main(["analyze", "--impedance", str(z), "--hx", str(hx)]) == 0
    lines = capsys.readouterr().out.splitlines()
    note = next(i for i, line in enumerate(lines) if line.startswith("note: "))
    said = [line.split(",")[0] for line in lines[note + 1:note + 3]]
    assert said == ["the export's own fit of impedance", "the export's own fit of displacement"]
    assert lines[note + 3].startswith("  ")          # then the notes on the curves
