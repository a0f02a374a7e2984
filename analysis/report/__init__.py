"""Reports of one measurement, as HTML (self-contained) and PDF.

    content = build_report(stored_result, header, settings, calibration, limits)
              (or report_for_measurement / report_for_recording; limits: analysis.limits.Limits or None)
    write_report(content, pdf="r.pdf", html="r.html")
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from analysis.archive.atomic import write_atomic

if TYPE_CHECKING:
    from analysis.report.content import ReportContent


def build_report(*args, **kwargs) -> ReportContent:
    """analysis.report.content.build_report, loaded on first use: it pulls in the fit (scipy), and
    analysis.report.numbers, which the limits' parser uses, must not (`linpar qa stats` starts in 0.4 s less)."""
    from analysis.report.content import build_report as _build
    return _build(*args, **kwargs)


def render_html(content: ReportContent) -> str:
    from analysis.report.html import render_html as _render
    return _render(content)


def render_pdf(content: ReportContent) -> bytes:
    from analysis.report.pdf import render_pdf as _render
    return _render(content)


def report_for_measurement(measurement, limits=None) -> ReportContent:
    """The report of an archived measurement (analysis.archive.Measurement), from what is stored.

    limits: an analysis.limits.Limits, or None for a report without QA limits.
    """
    record = measurement.record
    header = {k: record.get(k) for k in ("driver", "serial", "measured_at", "operator", "station", "id")}
    return build_report(measurement.result(), header, measurement.load_json("settings"),
                        measurement.load_json("calibration"), limits)


def report_for_recording(path, sd_m2=None, effects=None, header=None, limits=None) -> ReportContent:
    """Analyse a recording now and report it (the same content an archived copy would give)."""
    from analysis.archive.results import stored_from_recording
    stored, head, calibration = stored_from_recording(path, sd_m2, effects)
    head.update({k: v for k, v in (header or {}).items() if v})
    return build_report(stored, head, None, calibration, limits)


def write_report(content: ReportContent, pdf: str | Path | None = None, html: str | Path | None = None) -> list[Path]:
    written = []
    if pdf is not None:
        written.append(write_atomic(pdf, render_pdf(content)))
    if html is not None:
        written.append(write_atomic(html, render_html(content)))
    return written


__all__ = ["build_report", "render_html", "render_pdf", "report_for_measurement",
           "report_for_recording", "write_report"]
