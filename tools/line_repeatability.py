"""How repeatable the line's short template is beside the full one: N repeats of each on the in-process rig.

    .venv/bin/python tools/line_repeatability.py [N]        (default 10)

The paper driver (resources/drivers/paper.json) on the in-process rig (instruments/rig/in_process.py: the
simulated sound card with the rig's calibration, amplifier and noise, a 65,536-tap FIR, the laser on its analog
input) with a line's noise (LINE_NOISE), measured N times with the "woofer" template and N times with "woofer-line", each repeat with the rig's
noise drawn afresh (its seed). Printed per template: the sound's duration per unit (settling and averaged
periods), the analysis' CPU time, and for Re, fs, Qts, Bl and Mms the mean, the spread between repeats (1 σ,
also in % of the mean), the mean σ the fit reported, and the mean's distance from the driver's truth. Not
real time (the rig runs as fast as it can): the duration is the sound's, which a line waits for.
"""
from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from analysis.derived import derived_from_values  # noqa: E402
from analysis.drivers import load_driver  # noqa: E402
from instruments.measurement import MeasurementPlan, run_measurement  # noqa: E402
from instruments.rig.engine import RigNoise  # noqa: E402
from instruments.rig.in_process import InProcessRig  # noqa: E402
from instruments.simulation.linear_driver import LinearBlockDriver  # noqa: E402

NAMES = (("RE", "Re", "Ω", 1.0), ("fs", "fs", "Hz", 1.0), ("Qts", "Qts", "", 1.0), ("Bl", "Bl", "T·m", 1.0),
         ("Mms", "Mms", "g", 1e3))
SAMPLE_RATE = 48000
# A line's noise, not the rig's -105 dB of full scale (which leaves a spread of 1e-7 between repeats): the
# voltage input 80 dB under the amplifier's 10 V, the current 80 dB under 1 A, a laser with 1 µm rms of noise.
LINE_NOISE = RigNoise(voltage=1e-3, current=1e-4, displacement=1e-6)


def repeats(template: str, n: int, folder: Path) -> tuple[dict[str, list[tuple[float, float]]], float, float]:
    """{name: [(value, reported σ)]}, the sound's duration per unit (s), the mean analysis CPU time (s)."""
    paper = load_driver("paper")
    plan = MeasurementPlan.from_template(template, driver={"name": paper.name, "sd_m2": paper.sd_m2})
    found: dict[str, list[tuple[float, float]]] = {name: [] for name, *_ in NAMES}
    cpu = []
    for seed in range(n):
        driver = LinearBlockDriver(paper.model(with_displacement=True), dict(paper.parameters), SAMPLE_RATE)
        rig = InProcessRig(driver, "analog", seed=100 + seed, realtime=False, noise=LINE_NOISE)
        try:
            started = time.process_time()
            outcome = run_measurement(plan, rig.audio, None, folder, name=f"{template}-{seed}")
            cpu.append(time.process_time() - started)
        finally:
            rig.close()
        for name, *_ in NAMES:
            p = outcome.result.parameters[name]
            found[name].append((p.value, p.std))
    return found, plan.duration_s(SAMPLE_RATE), statistics.mean(cpu)


def table(template: str, found, duration: float, cpu: float, truth: dict) -> list[str]:
    lines = [f"{template}: {duration:.2f} s of sound a unit, {cpu:.2f} s CPU of measuring and analysing "
             f"(mean of {len(found['RE'])})",
             f"  {'':4} {'mean':>10} {'σ between':>11} {'σ %':>7} {'σ reported':>11} {'mean - truth':>13}"]
    for name, shown, unit, scale in NAMES:
        values = [v for v, _ in found[name]]
        mean, spread = statistics.mean(values), statistics.stdev(values)
        reported = statistics.mean(s for _, s in found[name] if s is not None)
        lines.append(f"  {shown:4} {mean * scale:10.4g} {spread * scale:11.2g} {100 * spread / abs(mean):6.3f}% "
                     f"{reported * scale:11.2g} {100 * (mean - truth[name]) / truth[name]:+12.3f}%  {unit}")
    return lines


def main(n: int) -> None:
    paper = load_driver("paper")
    truth = {**paper.parameters, **derived_from_values(paper.parameters)}
    with tempfile.TemporaryDirectory() as tmp:
        for template in ("woofer", "woofer-line"):
            found, duration, cpu = repeats(template, n, Path(tmp))
            print("\n".join(table(template, found, duration, cpu, truth)), flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10)
