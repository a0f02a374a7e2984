"""The analog-output scale, and the layer rule: instruments.laser stays free
of Qt, the GUI and the analysis (but for the two stdlib-only leaves every layer
shares: the error base analysis.errors and the plausible ranges analysis.bounds)."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from instruments.laser import AnalogLaserScale
from tests.pace import paced


def test_analog_scale_through_two_calibration_points():
    scale = AnalogLaserScale.from_two_points(-5.0, 0.0, 5.0, 0.010)  # +-5 V over 10 mm
    assert scale.m_per_volt == pytest.approx(0.001)
    assert scale.to_metres(np.array([-5.0, 0.0, 5.0])) == pytest.approx([0.0, 0.005, 0.010])
    with pytest.raises(ValueError):
        AnalogLaserScale.from_two_points(1.0, 0.0, 1.0, 0.01)


def test_instruments_laser_imports_no_qt_no_app_no_analysis():
    code = ("import sys, instruments.laser\n"
            # analysis/__init__ names the library's calls lazily (analysis.lazy_exports), importing none of them
            "shared = {'analysis', 'analysis.lazy_exports', 'analysis.errors', 'analysis.bounds'}\n"
            "bad = sorted(m for m in sys.modules if m.split('.')[0] in {'PySide6', 'pyqtgraph', 'app', 'analysis'}"
            " and m not in shared)\n"
            "print(bad); sys.exit(1 if bad else 0)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=paced(60),
                          cwd=Path(__file__).resolve().parents[3])
    assert done.returncode == 0, done.stdout + done.stderr
