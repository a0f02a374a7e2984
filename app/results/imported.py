"""What the Results page says and draws besides for imported curves (File > Open curves…): the files and bands
fitted instead of a recording's settings, the exporting tool's fitted curve over linpar's, and how far apart the
two fits are (analysis.curves.reference, the numbers `linpar analyze --impedance` prints)."""
from __future__ import annotations

import html

from analysis.curves.reference import compare_with_reference, comparison_words

REFERENCE_NAME = "the export's fit"
CHANNEL_WORDS = {"impedance": "Z", "displacement": "Hx"}


def is_imported(result) -> bool:
    """True for an analysis.curves.fitting.CurveAnalysis (no spectra: curves read from another tool's files)."""
    return not hasattr(result, "spectra")


def source_html(result) -> str:
    """The files, the band each channel was fitted over, and the comparison with the export's own fit."""
    names = " + ".join(f"<b>{html.escape(path.name)}</b>" for path in result.files) or "<b>imported curves</b>"
    magnitude_only = set(result.validity.imported.magnitude_only if result.validity.imported else ())
    bands = ", ".join(f"{CHANNEL_WORDS.get(name, name)} {lo:.3g}–{hi:.4g} Hz"
                      + (" (magnitude only)" if name in magnitude_only else "")
                      for name, (lo, hi) in result.ranges.items())
    lines = [f"{names} &nbsp;·&nbsp; imported curves, fitted: {html.escape(bands)}"]
    for name, c in comparison(result).items():
        words = comparison_words(name, c)
        lines.append(html.escape(words[0].upper() + words[1:], quote=False))
    return "<br>".join(lines)


def comparison(result) -> dict:
    """compare_with_reference's numbers for the channels whose file carried the tool's fitted curve."""
    references = {name: tf for name, tf in result.references.items() if tf is not None}
    return compare_with_reference(result.fit, references) if references else {}


def draw_references(result, plots: dict) -> None:
    """The tool's fitted |Z| and |Hx| on the Results page's plots (by channel name), over linpar's fitted band."""
    for name, plot in plots.items():
        reference = result.references.get(name)
        channel = result.fit.channels.get(name)
        if reference is None or channel is None:
            continue
        inside = (reference.freqs >= channel.freqs.min()) & (reference.freqs <= channel.freqs.max())
        plot.set_reference(reference.freqs[inside], abs(reference.value[inside]), REFERENCE_NAME)
