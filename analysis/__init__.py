"""linpar's analysis library: a loudspeaker driver's parameters from one multitone measurement.

    import analysis
    recording = analysis.read_recording("woofer.wav")      # or analysis.synthesize(driver="paper", ...)
    result = analysis.analyze(recording)                    # keyword options: sd_m2=, effects=, method=
    print(result.report())                                  # result.as_json(): what `linpar analyze --json` prints
    print(analysis.diagnose(recording).report())            # which physics the model lacks, and where
    curves = analysis.import_curves("driver.zma", hx="driver_hx.txt")
    analysis.analyze(curves)                                # other tools' curves, fitted the same way

docs/library.md walks through an example. Each name below is imported on first use (analysis.lazy_exports):
`import analysis` costs nothing, and the command line loads only what a command uses.
"""
from __future__ import annotations

from analysis.lazy_exports import lazy_exports

# Where each public name lives (a submodule of this package).
_HOME = {
    "AnalysisResult": "pipeline",
    "ChannelNoise": "synthesis",
    "CurveAnalysis": "curves.fitting",
    "DiagnosisResult": "diagnosis.result",
    "ImportedCurves": "curves.imported",
    "LinparError": "errors",
    "Model": "model.composed",
    "Recording": "recording.format",
    "TYPICAL_NOISE": "synthesis",
    "analyze": "api",
    "diagnose": "api",
    "import_curves": "curves.imported",
    "load_driver": "drivers",
    "parse_effects": "effects",
    "read_recording": "recording.format",
    "synthesize": "api",
    "write_recording": "recording.format",
}

__all__ = sorted(_HOME)

__getattr__, __dir__ = lazy_exports(__name__, _HOME)
