"""`linpar measure --plan large-signal` end to end on the JACK rig's nonlinear model (`linpar rig start --model
nonlinear`), with its serial laser behind a USB serial link 8 ms late with 2 ms of jitter (`--fault
latency=0.008,jitter=0.002`): the steps, the summary, and the identification of what was recorded.

The rig's chain reads 2 A at the current input's full scale, which the paper-like demo driver passes near 5 V
(~2 mm): the plan is asked for 1.5 mm.
"""
from __future__ import annotations

import json
import os
import shutil

import pytest

from tests.rig_xruns import measure_until_no_xrun

pytestmark = [pytest.mark.rig, pytest.mark.slow, pytest.mark.timeout(480)]     # up to three plans
LINK = "latency=0.008,jitter=0.002"       # a USB serial adapter's packets, far beyond the +-1 ms delay search


@pytest.fixture(scope="module")
def plan_on_the_rig(virtual_rig, tmp_path_factory):
    """One plan on the rig's nonlinear model (30 s; again when the host did not keep up, tests/rig_xruns.py): its
    exit code, JSON document, stderr (with the rig's status when the plan failed) and output folder."""
    if shutil.which("jackd") is None:
        pytest.skip("jackd is not installed")
    from instruments.audio import portaudio
    from instruments.rig.manager import rig_status, start_rig, stop_rig
    tmp_path = tmp_path_factory.mktemp("large-signal-rig")
    name, runtime = f"linpar-ls-{os.getpid()}", tmp_path / "rigs"
    start_rig(name, driver="demo-large-signal", faults=[LINK], runtime_dir=runtime, seed=3, model="nonlinear")
    try:
        code, out, err, folder = measure_until_no_xrun(
            lambda out_folder: ["measure", "--plan", "large-signal", "--out", str(out_folder), "--name", "ls",
                                "--rig-name", name, "--runtime-dir", str(runtime), "--max-excursion", "1.5",
                                "--step", "2", "--json"], tmp_path)
        if code != 0:
            err += f"the rig's status: {json.dumps(rig_status(name, runtime))}\n"
    finally:
        portaudio.release()
        stop_rig(name, runtime)
        portaudio.use_jack_server(virtual_rig.state.jack_server)  # back to the session's rig
    return code, out, err, folder


def test_the_plan_runs_on_the_nonlinear_rig_and_its_steps_are_identified(plan_on_the_rig):
    code, out, err, folder = plan_on_the_rig
    assert code == 0, err
    doc = json.loads(out)
    assert doc["plan"]["stopped_by"] == "excursion", doc["plan"]["message"]
    summary = json.loads((folder / "ls.large-signal.json").read_text())
    # A step measured again (its displacement did not repeat: a busy host) is kept but not usable.
    peaks = [s["measures"]["peak_displacement_m"] for s in summary["steps"] if s["usable"]]
    assert len(peaks) >= 3 and all(b > a for a, b in zip(peaks, peaks[1:])) and peaks[-1] >= 0.98 * 1.5e-3
    assert all((folder / s["recording"]).is_file() for s in summary["steps"])
    assert "step 1 at 0.5 V" in err
    curves = doc["large_signal"]["curves"]
    assert set(curves) >= {"Bl", "Kms", "Le"}


def test_bl0_and_kms0_on_the_jack_rig_come_within_1_percent(plan_on_the_rig):
    code, out, err, _ = plan_on_the_rig
    assert code == 0, err
    curves = json.loads(out)["large_signal"]["curves"]
    bl0, kms0 = curves["Bl"]["coefficients"][0], curves["Kms"]["coefficients"][0]
    assert bl0 == pytest.approx(5.23, rel=0.01)
    assert kms0 == pytest.approx(5.23**2 / 11.75e-3, rel=0.01)
    for recording in json.loads(out)["large_signal"]["validity"]["recordings"]:
        assert recording["laser_delay_found"] and not recording["laser_delay_at_limit"]
        # Its 1-sigma: below 5 us in 14 plans on a quiet machine, 7.1 us in one at load 6 (a busy host places
        # the stream a little less well, and the sigma says so). The bound catches a delay not pinned down
        # (a tenth of the laser's 250 us sample period); the delay found against the emulation's truth is
        # tested in-process (tests/instruments/measurement/test_large_signal_plan.py, within 20 us), and the
        # curves it leads to just below.
        assert 0 < recording["laser_delay_std_s"] < 20e-6
    # Bl(x) / Bl(0) = 1 - 0.03 x - 0.01 x^2 (x in mm): its slope at rest, -0.03 per mm
    assert curves["Bl"]["coefficients"][1] / bl0 == pytest.approx(-30.0, rel=0.15)
