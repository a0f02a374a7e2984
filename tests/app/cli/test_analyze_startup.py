"""`linpar analyze REC --json` imports what it uses: its start-up is most of its time (bench/analysis_bench.py's
startup rows), and every library it loads without calling is paid on every run."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

import analysis
from analysis.recording.format import write_recording
from app.cli.boundary import main
from tests.fresh_import import REPO
from tests.pace import paced

# Loaded by other commands, never called by the analysis of a recording: the imported curves' fitting
# (scipy.ndimage), the export formats (the parser offers them to `linpar export` only), the limits (--limits
# only), the cubic spline (validity, only when the voltage carries off its lines: not on a clean recording),
# the statistics, the plots, Qt, and lmfit (no longer used). The other commands' parsers (app/cli/boundary.py
# builds the one named) and what they import (the devices, the measurement plans); importlib.metadata (read only
# when a package's metadata names linpar.effects) and the effect files' reader (only when there are files); the
# level check (the plausibility check needs its excursion limit only); a pool's concurrent.futures; the
# uncertainties package (analysis.derived propagates by central differences; the added-mass method uses it).
# The coil's heating (only when the current drifts), the capture's checks (only when the sidecar has a "capture")
# and the simulator (analysis.synthesis: TYPICAL_NOISE lives there): each made dataclasses at every start. The
# catalogue's effects beyond the default model's inductance and creep (analysis/effects/catalogue.py imports an
# effect's module when it is first asked for). Imported curves' validity (analysis.validity.imported_curves).
NOT_LOADED = ("analysis.heating", "analysis.validity.capture", "analysis.synthesis",
              "analysis.validity.imported_curves",
              "analysis.effects.enclosure", "analysis.effects.breakup", "analysis.effects.channels",
              "analysis.effects.forcefactor", "analysis.effects.mechanical", "analysis.effects.creep_at_fs",
              "analysis.curves.", "analysis.export", "analysis.limits", "scipy.ndimage", "scipy.interpolate",
              "scipy.stats", "matplotlib", "PySide6", "pyqtgraph", "lmfit",
              "app.cli.added_mass", "app.cli.archive", "app.cli.devices", "app.cli.diagnose", "app.cli.gui",
              "app.cli.large_signal", "app.cli.levels", "app.cli.measure", "app.cli.qa", "app.cli.recover",
              "app.cli.report", "app.cli.rig", "app.cli.stats", "instruments",
              "importlib.metadata", "analysis.effects.user", "analysis.effects.formula", "tomllib",
              "analysis.level_check", "concurrent.futures", "uncertainties")

# Packages whose compiled routines a fit calls, loaded from their files (analysis.fit.minpack): importing the
# packages themselves took 0.4 s.
PACKAGES_NOT_IMPORTED = ("scipy.optimize", "scipy.linalg")

RUN_AND_LIST = ("import contextlib, io, sys\n"
                "from app.cli.boundary import main\n"
                "out = io.StringIO()\n"
                "with contextlib.redirect_stdout(out):\n"
                "    code = main(['analyze', sys.argv[1], '--json'])\n"
                "print(code)\n"
                "print(','.join(sorted(sys.modules)))\n"
                "print(out.getvalue())\n")


def test_analyze_of_a_recording_loads_no_module_it_does_not_call(tmp_path):
    path = tmp_path / "clean"
    write_recording(path, analysis.synthesize(noise=analysis.TYPICAL_NOISE))
    out = subprocess.run([sys.executable, "-c", RUN_AND_LIST, str(path)], cwd=REPO, capture_output=True, text=True,
                         timeout=paced(300))
    assert out.returncode == 0, out.stderr
    code, modules, doc = out.stdout.split("\n", 2)
    assert code == "0" and json.loads(doc)["parameters"]["Bl"]["value"] > 0      # it did analyse
    loaded = [m for m in modules.split(",") if m.startswith(NOT_LOADED) or m.split(".")[0] in NOT_LOADED]
    assert loaded == []
    assert [m for m in modules.split(",") if m in PACKAGES_NOT_IMPORTED] == []


def test_export_still_offers_every_format_of_the_registry(capsys):
    from app.cli.report import export_options
    with pytest.raises(SystemExit) as help_shown:
        main(["export", "--help"])
    assert help_shown.value.code == 0
    shown = " ".join(capsys.readouterr().out.split())      # argparse wraps at the terminal's width
    for kind, what in export_options():
        assert f"--{kind.replace('_', '-')} FILE" in shown and what in shown


BLAS_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
THREADS_AFTER_NUMPY = ("import os, sys\n"
                       "import app.cli, numpy\n"
                       "print(os.environ['OPENBLAS_NUM_THREADS'], len(os.listdir('/proc/self/task')))\n")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="counts the process's threads in /proc")
def test_the_command_runs_one_blas_thread_unless_the_user_chose_another_number():
    """app/cli/__init__.py: set before numpy is imported, so that no BLAS thread spins beside the command's own."""
    bare = {k: v for k, v in os.environ.items() if k not in BLAS_VARIABLES}
    ours = subprocess.run([sys.executable, "-c", THREADS_AFTER_NUMPY], cwd=REPO, env=bare, capture_output=True,
                          text=True, timeout=paced(60))
    assert ours.returncode == 0, ours.stderr
    assert ours.stdout.split() == ["1", "1"]            # the variable, and the process's one thread
    chosen = subprocess.run([sys.executable, "-c", THREADS_AFTER_NUMPY], cwd=REPO,
                            env={**bare, "OPENBLAS_NUM_THREADS": "3"}, capture_output=True, text=True,
                            timeout=paced(60))
    assert chosen.returncode == 0, chosen.stderr
    assert chosen.stdout.split()[0] == "3"
    # OpenBLAS reads its own variable before OMP_NUM_THREADS: a user's OMP_NUM_THREADS alone must not be overridden.
    omp = subprocess.run([sys.executable, "-c", "import os, app.cli\nprint(os.environ.get('OPENBLAS_NUM_THREADS'))"],
                         cwd=REPO, env={**bare, "OMP_NUM_THREADS": "2"}, capture_output=True, text=True,
                         timeout=paced(60))
    assert omp.returncode == 0, omp.stderr
    assert omp.stdout.split() == ["None"]
