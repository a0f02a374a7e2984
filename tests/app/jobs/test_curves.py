"""The GUI's Open curves… job reads and fits curves as `linpar analyze --impedance` does (both through
analysis.curves.imported.import_curves): the same lines, the same numbers."""
import json

import numpy as np
import pytest

from analysis.effects import parse_effects
from analysis.model.composed import Model
from app.cli import main
from app.jobs.curves import CurvesRequest, analyse_curves
from tests.builders import PAPER

# A linearly spaced export (1 Hz steps, as many analyzers write): the CLI thins it to 100 lines per decade.
FREQS = np.arange(5.0, 5001.0, 1.0)


class _Job:
    """What the job's work function uses of app.jobs.book.Job."""

    def say(self, text: str) -> None:
        pass

    def check(self) -> None:
        pass


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
    gui = analyse_curves(_Job(), CurvesRequest(linear_files / "z.txt", linear_files / "hx.txt", True))
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
