"""The archive: `linpar archive list` over 1,000 stored measurements, and the index rebuild.

The 1,000 measurements are light-weight: one short synthetic recording
(3 channels, 3 periods of 1,024 samples at 8 kHz) analysed once, stored 1,000 times
under different drivers, serials and operators: what is timed is the
archive, not the analysis.
"""
from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

from bench.common import Row, at_most, median_time

N_MEASUREMENTS = 1000


def small_recording():
    from analysis.drivers import load_driver
    from analysis.multitone import design_multitone
    from analysis.synthesis import ChannelNoise, synthesize_recording
    driver = load_driver("paper")
    # 8 kHz: 1,024 samples a period still resolve the resonance (7.8 Hz lines).
    mt = design_multitone(8000, 1024, 8.0, 3000.0, rms=1.0)
    return synthesize_recording(driver.model(), driver.parameters, mt.waveform, mt.excited_bins, 8000, 3, 0,
                                ChannelNoise(1e-4, 1e-4, 1e-8), seed=1, driver={"name": "paper", "sd_m2": 0.0133})


def fill(root: Path, n: int = N_MEASUREMENTS) -> float:
    """Store n measurements; return the seconds it took."""
    from analysis.archive import Archive
    from analysis.archive.results import results_document
    from analysis.pipeline import analyze_recording
    from analysis.recording.format import write_recording
    rec = small_recording()
    path = root.parent / "bench-recording"
    write_recording(path, rec)
    doc = results_document(analyze_recording(rec), rec)
    archive = Archive(root)
    t0 = time.perf_counter()
    for i in range(n):
        archive.store(path, doc, {"driver": f"woofer-{i % 7}", "serial": f"SN{i:05d}",
                                  "operator": ("ana", "ben", "cem")[i % 3], "station": f"QA{i % 2}"})
    return time.perf_counter() - t0


def run(workdir: Path) -> list[Row]:
    root = workdir / "archive"
    t_fill = fill(root)
    rows = [Row(f"store {N_MEASUREMENTS} light-weight measurements", t_fill, "s", "", None)]

    env = {**os.environ, "LINPAR_ARCHIVE": str(root)}
    cmd = [sys.executable, "-m", "app.cli", "archive", "list"]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env).stdout
    assert f"{N_MEASUREMENTS} measurement(s)" in out, out[-200:]
    t_list = median_time(lambda: subprocess.run(cmd, check=True, capture_output=True, env=env), repeats=7)
    rows.append(at_most(f"'linpar archive list', {N_MEASUREMENTS} measurements (whole process)", t_list, "s", 0.2))

    from analysis.archive import Archive
    archive = Archive(root)
    t_list_in = median_time(lambda: archive.list(), repeats=7)
    rows.append(Row("  Archive.list() in process", t_list_in, "s", "", None))

    t_rebuild = median_time(lambda: archive.rebuild(), repeats=3)
    rows.append(at_most(f"rebuild the index from {N_MEASUREMENTS} folders", t_rebuild, "s", 5.0))

    (root / "index.sqlite").write_bytes(b"\x00garbage" * 100)
    t0 = time.perf_counter()
    n = len(Archive(root).list())
    t_recover = time.perf_counter() - t0
    assert n == N_MEASUREMENTS, n
    rows.append(at_most("list after the database was overwritten with garbage (detect + rebuild)", t_recover, "s", 5.0))
    return rows


if __name__ == "__main__":   # pragma: no cover
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        for r in run(Path(tmp)):
            print(f"{r.name:<75}{r.value:>9.3f} {r.unit} {r.target} {'' if r.ok is None else ('ok' if r.ok else 'NO')}")
