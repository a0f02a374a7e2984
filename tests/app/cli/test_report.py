"""`linpar report` and `linpar export` given a file that is no recording: one line that says what it is and what to
do, not the archive's "is not a measurement id"."""
import pytest

from analysis.recording.format import write_recording
from app.cli import main
from tests.builders import TYPICAL_NOISE, recording


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("command, output", [("report", "--pdf"), ("export", "--csv")])
def test_a_curve_of_another_tool_is_named_for_what_it_is_with_where_its_report_comes_from(capsys, tmp_path,
                                                                                          command, output):
    curve = tmp_path / "driver.zma"
    curve.write_text("10 7.1 25\n20 9.5 40\n45 29 0\n")
    code, out, err = run(capsys, command, curve, output, tmp_path / "out")
    assert code == 2 and "not a measurement id" not in err
    assert "a file, not a recording" in err and "linpar analyze --impedance" in err and "Open curves" in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("kept", [".wav", ".json"])
def test_half_a_recording_names_the_file_that_is_missing(capsys, tmp_path, kept):
    wav, sidecar = write_recording(tmp_path / "rec", recording(noise=TYPICAL_NOISE, n_periods=3))
    (sidecar if kept == ".wav" else wav).unlink()
    code, out, err = run(capsys, "report", tmp_path / f"rec{kept}", "--pdf", tmp_path / "out.pdf")
    missing = sidecar if kept == ".wav" else wav
    assert code == 2 and f"{missing} is not there" in err and "keep the two files together" in err
