"""The example report of the README: docs/example-report.pdf and docs/example-report.html.

    .venv/bin/python tools/example_report.py [OUTDIR]

The paper's driver (resources/drivers/paper.json: lr2 and creep-log) synthesized
on the project multitone with realistic noise (seed 1), analysed, and judged
against resources/limits/example.json. The same inputs give the same bytes:
the PDF has no creation date and the SVG ids are salted with a constant. To
look at the pages: pdftoppm -png -r 60 docs/example-report.pdf /tmp/example.
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from analysis.archive.results import StoredResult, results_document  # noqa: E402
from analysis.drivers import load_driver  # noqa: E402
from analysis.limits import load_limits  # noqa: E402
from analysis.multitone import design_multitone  # noqa: E402
from analysis.pipeline import analyze_recording  # noqa: E402
from analysis.recording.format import read_recording, write_recording  # noqa: E402
from analysis.report import build_report, write_report  # noqa: E402
from analysis.synthesis import ChannelNoise, synthesize_recording  # noqa: E402

LIMITS = ROOT / "resources" / "limits" / "example.json"
HEADER = {"driver": "Paper driver (synthetic)", "serial": "SYN-0001", "measured_at": "2025-01-15T09:30:00Z",
          "operator": "example", "station": "virtual rig",
          "source": "tools/example_report.py: resources/drivers/paper.json synthesized, seed 1"}
CALIBRATION = {"note": "synthetic recording: the signals are exact physical values (V, A, m); no sound-card or "
                       "laser calibration applies"}


def main(out_dir: Path) -> list[Path]:
    driver = load_driver("paper")
    mt = design_multitone(48000, 16384, 5.0, 10000.0, rms=1.0)
    synthetic = synthesize_recording(driver.model(with_displacement=True), driver.parameters, mt.waveform,
                                     mt.excited_bins, mt.sample_rate, 8, 1, ChannelNoise(1e-4, 1e-4, 1e-8), seed=1,
                                     driver={"name": "synthetic", "sd_m2": driver.sd_m2})
    with tempfile.TemporaryDirectory() as tmp:      # through the file format, as a measurement would go
        write_recording(Path(tmp) / "example", synthetic)
        recording = read_recording(Path(tmp) / "example")
    stored = StoredResult.from_json(results_document(analyze_recording(recording), recording))
    content = build_report(stored, HEADER, None, CALIBRATION, load_limits(LIMITS))
    out_dir.mkdir(parents=True, exist_ok=True)
    return write_report(content, pdf=out_dir / "example-report.pdf", html=out_dir / "example-report.html")


if __name__ == "__main__":
    for path in main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs"):
        print(f"written: {path}")
