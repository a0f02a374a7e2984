"""The production line's template: under 3 s of sound a unit, and on the in-process rig (with a line's noise,
not as fast as real time) it finds the paper driver as the full woofer template does."""
from __future__ import annotations

import pytest

from analysis.derived import derived_from_values
from analysis.drivers import load_driver
from instruments.measurement import MeasurementPlan, run_measurement
from instruments.measurement.plan import TEMPLATES
from instruments.rig.engine import RigNoise
from instruments.rig.in_process import InProcessRig
from instruments.simulation.linear_driver import LinearBlockDriver

PAPER = load_driver("paper")
TRUTH = {**PAPER.parameters, **derived_from_values(PAPER.parameters)}
LINE_NOISE = RigNoise(voltage=1e-3, current=1e-4, displacement=1e-6)


def test_the_line_template_takes_under_3_s_of_sound_and_the_full_one_does_not():
    line = MeasurementPlan.from_template("woofer-line")
    assert line.duration_s(48000) <= 3.0
    assert line.settle * line.period_samples >= 65536            # the virtual rig's FIR has settled
    assert MeasurementPlan.from_template("woofer").duration_s(48000) > 10.0
    assert "docs/production.md" in TEMPLATES["woofer-line"].description


@pytest.mark.parametrize("seed", [1, 2])
def test_the_line_template_finds_the_driver_on_the_rig(tmp_path, seed):
    driver = LinearBlockDriver(PAPER.model(with_displacement=True), dict(PAPER.parameters), 48000)
    rig = InProcessRig(driver, "analog", seed=seed, realtime=False, noise=LINE_NOISE)
    try:
        plan = MeasurementPlan.from_template("woofer-line", driver={"name": PAPER.name, "sd_m2": PAPER.sd_m2})
        outcome = run_measurement(plan, rig.audio, None, tmp_path, name="unit")
    finally:
        rig.close()
    assert outcome.ended_by == "complete" and outcome.periods == 4
    for name in ("RE", "fs", "Qts", "Bl", "Mms"):
        p = outcome.result.parameters[name]
        # Within 5 reported sigmas of the truth (and the sigma itself small: 0.001-0.005 % on this rig).
        assert abs(p.value - TRUTH[name]) <= 5 * p.std, (name, p.value, TRUTH[name], p.std)
        assert p.std < 1e-3 * abs(TRUTH[name]), (name, p.std)
