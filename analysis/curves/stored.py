"""Imported curves' analysis as a results document (analysis.archive.results), for the report and the exports.

The document of a recording's analysis, with what imported curves have instead of a recording's settings (the
band each channel was fitted over) and what they have besides: each channel's fitted curve of the tool that
exported them (a Klippel export's "Fitted" column, |value| on the export's own lines) under "reference_curves",
and how far it lies from the measured curve and from linpar's fit (analysis.curves.reference) under
"reference_fit", so that a report can overlay the tool's fit and say how far apart the two fits are.
"""
from __future__ import annotations

import numpy as np

from analysis.archive.results import results_document
from analysis.curves.reference import compare_with_reference


def curve_results_document(result) -> dict:
    """The linpar-results/1 document of an analysis.curves.fitting.CurveAnalysis (its model part estimated first)."""
    from analysis.fit.model_uncertainty import model_uncertainty
    result = model_uncertainty(result)
    doc = results_document(result)
    doc["settings"] = {f"{name}_band_hz": [float(lo), float(hi)] for name, (lo, hi) in result.ranges.items()}
    references = {name: tf for name, tf in result.references.items() if tf is not None}
    if references:
        doc["reference_curves"] = {name: {"unit": tf.unit, "freqs_hz": [float(f) for f in tf.freqs],
                                          "magnitude": [float(v) for v in np.abs(tf.value)]}
                                   for name, tf in references.items()}
        doc["reference_fit"] = compare_with_reference(result.fit, references)
    return doc


def curve_header(result) -> dict:
    """The report's header of imported curves: the files read, by name."""
    return {"source": " + ".join(path.name for path in result.files)} if result.files else {}
